#pragma once
// Turns a densely sampled joint curve (a recording at the loop rate) into the
// few keys that reproduce it: the Ramer-Douglas-Peucker simplification with
// the error measured as a show plays it, the value at the same time under
// linear interpolation between the kept keys. Every sample lies within
// `tolerance` of the linear curve through the kept keys.

#include <cstddef>
#include <span>
#include <vector>

namespace animrt::show {

// Indices of the samples kept as keys, increasing; the first and the last
// sample are always kept. `times` strictly increasing, as many as `values`;
// `tolerance` >= 0 (0 keeps every sample that is not on a straight line).
// Throws std::invalid_argument otherwise.
std::vector<std::size_t> reduce_keys(std::span<const double> times, std::span<const double> values,
                                     double tolerance);

}  // namespace animrt::show
