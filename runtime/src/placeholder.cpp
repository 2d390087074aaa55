#include "animrt/runtime/robot_config.hpp"
