#pragma once
// The fitness of a walk, lower is better (after Murphy, O'Neill and Carr):
// weighted errors against the dynamic-similarity predictions for the gait's
// Froude number, plus weighted energy. A fall, a flip or an invalid
// phenotype scores kWorstFitness.
//
//   score = 100 * ( w_distance      |v - v*| / v*
//                 + w_duty_factor   |D - D*| / D*
//                 + w_stride_length |L - L*| / L* )
//         +  10 * w_energy * E / (m g L*)
//
// v* = Fr sqrt(g h), L* = 2.3 h Fr^0.6 (Alexander), D* from duty_factor_target;
// E is the energy per stride cycle, so E / (m g L*) is a cost of transport.
// The errors are percentages; the cost of transport is scaled by 10 because
// position-controlled joints spend several times the ideal (a walk of the
// demo quadruped costs about 4.6), and at 100 standing still would beat
// walking.

#include <vector>

#include "animrt/controllers/gait/gait_simulator.hpp"

namespace animrt::evolve {

inline constexpr double kWorstFitness = 10000.0;

struct FitnessWeights {
  double distance = 1.0;
  double duty_factor = 1.0;
  double stride_length = 1.0;
  double energy = 1.0;
};

struct GaitTargets {
  double speed = 0.0;          // m/s
  double stride_length = 0.0;  // m
  double duty_factor = 0.0;
  double stride_frequency = 0.0;  // Hz
};

// Duty factor predicted for a Froude number (Fr = v / sqrt(g h)): a straight
// line through Alexander and Jayes' (1983) walking data, about 0.72 at slow
// walks falling to 0.5 at the walk-trot transition (v^2/(g h) ~ 0.5).
double duty_factor_target(double froude);

GaitTargets froude_targets(double froude, double hip_height_m);

double score(const GaitMeasures& m, const GaitTargets& targets, const FitnessWeights& w,
             double mass_kg);

// Fitness weights that change with the generation (the paper's Table 2).
struct WeightStage {
  int from_generation = 0;
  FitnessWeights weights;
};
// The stage in effect at `generation` (stages sorted by from_generation, the
// first one starting at 0).
const FitnessWeights& weights_at(const std::vector<WeightStage>& stages, int generation);

}  // namespace animrt::evolve
