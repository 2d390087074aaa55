#pragma once
// Natural cubic splines, used to fill F0 through unvoiced gaps.

#include <span>
#include <vector>

namespace animrt::head {

class NaturalCubicSpline {
 public:
  // Knots must have strictly increasing x; at least one knot. With one knot
  // the spline is constant, with two it is a line.
  NaturalCubicSpline(std::vector<double> x, std::vector<double> y);
  // Inside the knots: the spline. Outside: the nearest end value (held, so a
  // long leading or trailing gap never runs off along the end slope).
  double operator()(double x) const;

 private:
  std::vector<double> x_, y_, m_;  // m_: second derivatives at the knots
};

// Replaces values where `known[i]` is false by a natural cubic spline through
// the known ones (x = frame index), then clamps the filled values to
// [lo, hi]. Returns the input unchanged when nothing is known.
std::vector<double> fill_gaps_spline(std::span<const double> values, std::span<const bool> known,
                                     double lo, double hi);

}  // namespace animrt::head
