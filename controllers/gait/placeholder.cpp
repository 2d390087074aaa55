#include "animrt/controllers/motion_source.hpp"
