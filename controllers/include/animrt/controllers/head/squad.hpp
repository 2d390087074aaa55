#pragma once
// Spherical interpolation of unit quaternions: slerp and SQUAD (spherical
// cubic), with signs kept consistent along a sequence.

#include <Eigen/Geometry>
#include <span>
#include <vector>

namespace animrt::head {

// Paper Eq. 4: shortest-arc interpolation (flips q2 when q1 . q2 < 0).
Eigen::Quaterniond slerp(const Eigen::Quaterniond& q1, const Eigen::Quaterniond& q2, double mu);

// Flips signs so that every quaternion lies in the hemisphere of its
// predecessor (q and -q are the same rotation; mixing them makes an
// interpolation take the long way round).
void make_signs_consistent(std::vector<Eigen::Quaterniond>& keys);

// SQUAD through keys: between keys i and i+1,
//   squad = slerp(slerp(q_i, q_{i+1}, h), slerp(s_i, s_{i+1}, h), 2h(1-h))
// (the paper's Eq. 5), with inner control points
//   s_i = q_i exp(-(log(q_i^-1 q_{i+1}) + log(q_i^-1 q_{i-1})) / 4)
// (end keys use themselves as missing neighbours). The curve passes through
// every key and has a continuous tangent.
class SquadCurve {
 public:
  explicit SquadCurve(std::vector<Eigen::Quaterniond> keys);  // signs made consistent
  std::size_t size() const { return keys_.size(); }
  // `u` in key units: key i at u = i; clamped to [0, size-1].
  Eigen::Quaterniond operator()(double u) const;
  const std::vector<Eigen::Quaterniond>& keys() const { return keys_; }

 private:
  std::vector<Eigen::Quaterniond> keys_, inner_;
};

// The inner control point for key q with neighbours prev and next (all three
// already sign-consistent).
Eigen::Quaterniond squad_inner(const Eigen::Quaterniond& prev, const Eigen::Quaterniond& q,
                               const Eigen::Quaterniond& next);
// One SQUAD segment.
Eigen::Quaterniond squad(const Eigen::Quaterniond& q1, const Eigen::Quaterniond& s1,
                         const Eigen::Quaterniond& s2, const Eigen::Quaterniond& q2, double h);

}  // namespace animrt::head
