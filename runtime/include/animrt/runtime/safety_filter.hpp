#pragma once
// The safety filter lives in core (animrt/core/safety_filter.hpp) so that
// the fitness walk plays a gait through the same limits as the loop.
#include "animrt/core/safety_filter.hpp"
