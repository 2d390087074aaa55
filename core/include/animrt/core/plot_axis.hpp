#pragma once
// Axes and labels of the SVG plots animrt writes: ticks at round numbers
// (1, 2 or 5 times a power of ten, the "nice numbers" of Heckbert's
// Graphics Gems label algorithm) and point labels that do not overlap.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace animrt {

struct PlotAxis {
  double lo = 0.0, hi = 1.0, step = 0.25;  // ticks at lo, lo + step, ... hi
  std::vector<double> ticks() const {
    std::vector<double> out;
    for (int k = 0; lo + k * step <= hi + step * 1e-9; ++k) {
      const double v = lo + k * step;
      out.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);  // no -0 or 1e-17
    }
    return out;
  }
};

// A round number (1, 2 or 5 times a power of ten) for `x` > 0: the nearest
// one when `round`, else the smallest one not below it.
inline double nice_number(double x, bool round) {
  const double power = std::pow(10.0, std::floor(std::log10(x)));
  const double f = x / power;
  double nice = 10.0;
  if (round) {
    nice = f < 1.5 ? 1.0 : f < 3.0 ? 2.0 : f < 7.0 ? 5.0 : 10.0;
  } else {
    nice = f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0;
  }
  return nice * power;
}

// An axis from lo to hi (lo <= hi) with about `ticks` round ticks that
// cover both.
inline PlotAxis nice_axis(double lo, double hi, int ticks = 5) {
  if (!(hi > lo)) hi = lo + (lo == 0.0 ? 1.0 : std::abs(lo));
  const double range = nice_number(hi - lo, false);
  const double step = nice_number(range / std::max(1, ticks - 1), true);
  return {std::floor(lo / step) * step, std::ceil(hi / step) * step, step};
}

// A tick's text: as many decimals as the step needs, no more.
inline std::string tick_label(double v, double step) {
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// Places point labels without overlaps: each label is tried right of its
// point, then left, above and below; a label that fits nowhere is left out
// (the point keeps its tooltip).
class LabelPlacer {
 public:
  struct Box {
    double x0, y0, x1, y1;
  };
  // Text anchored at (x, baseline y) of `chars` characters at `size` px;
  // returns false when it cannot be placed. Writes where it goes.
  bool place(double px, double py, std::size_t chars, double size, double& x, double& y) {
    const double w = 0.6 * size * static_cast<double>(chars), h = size;
    const double offsets[4][2] = {{7, 4}, {-7 - w, 4}, {-w / 2, -7}, {-w / 2, 7 + h}};
    for (const auto& o : offsets) {
      const Box b{px + o[0], py + o[1] - h, px + o[0] + w, py + o[1]};
      bool free = true;
      for (const Box& p : placed_) {
        if (b.x0 < p.x1 && p.x0 < b.x1 && b.y0 < p.y1 && p.y0 < b.y1) free = false;
      }
      if (!free) continue;
      placed_.push_back(b);
      x = px + o[0];
      y = py + o[1];
      return true;
    }
    return false;
  }
  // A region labels must not cover (a point's marker).
  void reserve(const Box& box) { placed_.push_back(box); }
  const std::vector<Box>& placed() const { return placed_; }

 private:
  std::vector<Box> placed_;
};

}  // namespace animrt
