#include "animrt/sim/simulated_bus.hpp"
