#pragma once
// The evolve run file (configs/evolve/*.yaml, format in docs/evolve.md):
// grammar, model, seed gait, GE parameters, walk and fitness settings.
// Relative paths are resolved against the run file's folder.

#include <cstdint>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_simulator.hpp"
#include "animrt/learn/evolve/fitness.hpp"
#include "animrt/learn/evolve/operators.hpp"

namespace animrt::evolve {

// How a genome becomes a phenotype (mapper.hpp): standard GE reads one codon
// string for the whole derivation; structured reads each top-level
// non-terminal from its own segment.
enum class Mapping { standard, structured };

struct SearchSettings {
  std::uint64_t seed = 1;
  int population = 75;
  int generations = 50;  // after the initial one (generations 0..N are evaluated)
  int elites = 7;
  int tournament = 3;
  double crossover = 0.9;
  double mutation = 0.02;
  int max_wraps = 3;
  Mapping mapping = Mapping::standard;
  Location mapping_where;  // of the `mapping` key, for errors that need the grammar
  // A phenotype walked before in the same freedom stage takes that walk's
  // measures instead of being walked again (population.hpp). Off walks every
  // child: the same run, slower; there to check exactly that.
  bool remember_walks = true;
  InitSettings init;
};

// Curves free to move from a generation on (the paper's Table 3); the other
// curves are held at their seed mean.
struct FreedomStage {
  int from_generation = 0;
  std::vector<std::string> free;  // curve names of the seed gait
  Location where;
};

struct RunConfig {
  std::string file;
  std::string name;
  std::string grammar;  // path
  std::string model;    // path (MJCF)
  std::string
      seed_gait;  // path: timing (froude), limbs, joint mapping, curve names in grammar order
  SearchSettings search;
  WalkSettings walk;
  // Path of a robot file (`robot:`): the walk is played as that figure
  // plays it (its joint limits, loop period and IMU); empty: as the physics
  // alone. The command line applies it (it knows robot files).
  std::string robot;
  std::vector<WeightStage> weights;   // at least one, the first from generation 0
  std::vector<FreedomStage> freedom;  // empty: every curve free all the time
  int threads = 0;                    // 0: all cores
};

RunConfig load_run_config(const std::string& path);
RunConfig parse_run_config(const std::string& text, const std::string& file_name);

}  // namespace animrt::evolve
