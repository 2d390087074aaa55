// Natural cubic spline: tridiagonal solve for the knot second derivatives.

#include "animrt/controllers/head/spline.hpp"

#include <algorithm>
#include <stdexcept>

namespace animrt::head {

NaturalCubicSpline::NaturalCubicSpline(std::vector<double> x, std::vector<double> y)
    : x_(std::move(x)), y_(std::move(y)), m_(x_.size(), 0.0) {
  const std::size_t n = x_.size();
  if (n == 0 || y_.size() != n)
    throw std::invalid_argument("spline: need matching, non-empty knots");
  for (std::size_t i = 1; i < n; ++i) {
    if (!(x_[i] > x_[i - 1])) throw std::invalid_argument("spline: x must increase strictly");
  }
  if (n < 3) return;
  // Thomas algorithm on the interior second derivatives (m_0 = m_{n-1} = 0).
  std::vector<double> c(n, 0.0), d(n, 0.0);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double h0 = x_[i] - x_[i - 1];
    const double h1 = x_[i + 1] - x_[i];
    const double a = h0, b = 2.0 * (h0 + h1), cc = h1;
    const double r = 6.0 * ((y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0);
    const double denom = b - a * c[i - 1];
    c[i] = cc / denom;
    d[i] = (r - a * d[i - 1]) / denom;
  }
  for (std::size_t i = n - 2; i >= 1; --i) {
    m_[i] = d[i] - c[i] * m_[i + 1];
  }
}

double NaturalCubicSpline::operator()(double x) const {
  const std::size_t n = x_.size();
  if (x <= x_.front()) return y_.front();
  if (x >= x_.back()) return y_.back();
  const auto it = std::upper_bound(x_.begin(), x_.end(), x);
  const std::size_t i = static_cast<std::size_t>(it - x_.begin()) - 1;
  if (n < 2) return y_.front();
  const double h = x_[i + 1] - x_[i];
  const double a = (x_[i + 1] - x) / h;
  const double b = (x - x_[i]) / h;
  return a * y_[i] + b * y_[i + 1] +
         ((a * a * a - a) * m_[i] + (b * b * b - b) * m_[i + 1]) * h * h / 6.0;
}

std::vector<double> fill_gaps_spline(std::span<const double> values, std::span<const bool> known,
                                     double lo, double hi) {
  std::vector<double> out(values.begin(), values.end());
  std::vector<double> kx, ky;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (known[i]) {
      kx.push_back(static_cast<double>(i));
      ky.push_back(values[i]);
    }
  }
  if (kx.empty()) return out;
  const NaturalCubicSpline spline(std::move(kx), std::move(ky));
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!known[i]) out[i] = std::clamp(spline(static_cast<double>(i)), lo, hi);
  }
  return out;
}

}  // namespace animrt::head
