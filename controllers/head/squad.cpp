// slerp and SQUAD on unit quaternions.

#include "animrt/controllers/head/squad.hpp"

#include <algorithm>
#include <cmath>

namespace animrt::head {
namespace {

// Logarithm of a unit quaternion: (0, theta * axis).
Eigen::Quaterniond qlog(const Eigen::Quaterniond& q) {
  const double vn = q.vec().norm();
  const double theta = std::atan2(vn, q.w());
  const Eigen::Vector3d v =
      vn > 1e-12 ? Eigen::Vector3d(q.vec() * (theta / vn)) : Eigen::Vector3d(q.vec());
  return Eigen::Quaterniond(0.0, v.x(), v.y(), v.z());
}

Eigen::Quaterniond qexp(const Eigen::Quaterniond& q) {
  const double theta = q.vec().norm();
  const double s = theta > 1e-12 ? std::sin(theta) / theta : 1.0;
  const Eigen::Vector3d v = q.vec() * s;
  return Eigen::Quaterniond(std::cos(theta), v.x(), v.y(), v.z());
}

}  // namespace

Eigen::Quaterniond slerp(const Eigen::Quaterniond& q1, const Eigen::Quaterniond& q2_in, double mu) {
  Eigen::Quaterniond q2 = q2_in;
  double c = q1.dot(q2);
  if (c < 0) {
    q2.coeffs() = -q2.coeffs();
    c = -c;
  }
  c = std::min(c, 1.0);
  const double theta = std::acos(c);
  Eigen::Quaterniond out;
  if (theta < 1e-9) {
    out.coeffs() = (1 - mu) * q1.coeffs() + mu * q2.coeffs();
  } else {
    const double s = std::sin(theta);
    out.coeffs() =
        (std::sin((1 - mu) * theta) / s) * q1.coeffs() + (std::sin(mu * theta) / s) * q2.coeffs();
  }
  return out.normalized();
}

void make_signs_consistent(std::vector<Eigen::Quaterniond>& keys) {
  for (std::size_t i = 1; i < keys.size(); ++i) {
    if (keys[i - 1].dot(keys[i]) < 0) keys[i].coeffs() = -keys[i].coeffs();
  }
}

Eigen::Quaterniond squad_inner(const Eigen::Quaterniond& prev, const Eigen::Quaterniond& q,
                               const Eigen::Quaterniond& next) {
  const Eigen::Quaterniond inv = q.conjugate();
  const Eigen::Quaterniond a = qlog(inv * next);
  const Eigen::Quaterniond b = qlog(inv * prev);
  Eigen::Quaterniond sum;
  sum.coeffs() = -(a.coeffs() + b.coeffs()) / 4.0;
  return (q * qexp(sum)).normalized();
}

// Inner slerps without the shortest-arc flip: the control points belong to
// the same sign-consistent chain and flipping one would bend the curve.
static Eigen::Quaterniond slerp_noflip(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b,
                                       double mu) {
  const double c = std::clamp(a.dot(b), -1.0, 1.0);
  const double theta = std::acos(c);
  Eigen::Quaterniond out;
  if (std::abs(theta) < 1e-9) {
    out.coeffs() = (1 - mu) * a.coeffs() + mu * b.coeffs();
  } else {
    const double s = std::sin(theta);
    out.coeffs() =
        (std::sin((1 - mu) * theta) / s) * a.coeffs() + (std::sin(mu * theta) / s) * b.coeffs();
  }
  return out.normalized();
}

Eigen::Quaterniond squad(const Eigen::Quaterniond& q1, const Eigen::Quaterniond& s1,
                         const Eigen::Quaterniond& s2, const Eigen::Quaterniond& q2, double h) {
  return slerp_noflip(slerp_noflip(q1, q2, h), slerp_noflip(s1, s2, h), 2.0 * h * (1.0 - h));
}

SquadCurve::SquadCurve(std::vector<Eigen::Quaterniond> keys) : keys_(std::move(keys)) {
  for (auto& k : keys_) k.normalize();
  make_signs_consistent(keys_);
  inner_.resize(keys_.size());
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    const auto& prev = keys_[i == 0 ? 0 : i - 1];
    const auto& next = keys_[std::min(i + 1, keys_.size() - 1)];
    inner_[i] = squad_inner(prev, keys_[i], next);
  }
}

Eigen::Quaterniond SquadCurve::operator()(double u) const {
  if (keys_.empty()) return Eigen::Quaterniond::Identity();
  const double last = static_cast<double>(keys_.size() - 1);
  u = std::clamp(u, 0.0, last);
  std::size_t i = static_cast<std::size_t>(std::floor(u));
  if (i >= keys_.size() - 1) return keys_.back();
  const double h = u - static_cast<double>(i);
  return squad(keys_[i], inner_[i], inner_[i + 1], keys_[i + 1], h);
}

}  // namespace animrt::head
