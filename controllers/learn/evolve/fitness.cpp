// Scoring a walk against Froude predictions (see fitness.hpp).

#include "animrt/learn/evolve/fitness.hpp"

#include <algorithm>
#include <cmath>

#include "animrt/controllers/gait/froude.hpp"

namespace animrt::evolve {

double duty_factor_target(double froude) {
  const double x = froude * froude;  // v^2 / (g h), Alexander and Jayes' argument
  return std::clamp(0.75 - 0.5 * x, 0.35, 0.75);
}

GaitTargets froude_targets(double froude, double hip_height_m) {
  GaitTargets t;
  t.speed = froude_velocity(froude, hip_height_m);
  t.stride_length = froude_stride_length(froude, hip_height_m);
  t.stride_frequency = froude_stride_frequency(froude, hip_height_m);
  t.duty_factor = duty_factor_target(froude);
  return t;
}

double score(const GaitMeasures& m, const GaitTargets& t, const FitnessWeights& w, double mass_kg) {
  if (m.fell) return kWorstFitness;
  const auto rel = [](double value, double target) {
    return std::min(std::fabs(value - target) / target, 10.0);  // one term cannot swamp the rest
  };
  const double errors = w.distance * rel(m.speed, t.speed) +
                        w.duty_factor * rel(m.duty_factor, t.duty_factor) +
                        w.stride_length * rel(m.stride_length, t.stride_length);
  const double cot = m.energy_per_cycle / (mass_kg * kStandardGravity * t.stride_length);
  const double s = 100.0 * errors + 10.0 * w.energy * cot;
  return std::isfinite(s) ? std::min(s, kWorstFitness) : kWorstFitness;
}

const FitnessWeights& weights_at(const std::vector<WeightStage>& stages, int generation) {
  static const FitnessWeights kDefault{};
  const FitnessWeights* w = &kDefault;
  for (const auto& s : stages) {
    if (s.from_generation <= generation) w = &s.weights;
  }
  return *w;
}

}  // namespace animrt::evolve
