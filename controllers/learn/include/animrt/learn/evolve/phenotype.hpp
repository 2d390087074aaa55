#pragma once
// From phenotype text to a gait file. A phenotype holds one curve expression
// per curve of the seed gait, in the seed gait's order, separated by ';'.
// The evolved gait is the seed gait with its curves replaced, so timing,
// limbs and the joint mapping come from the seed.

#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"

namespace animrt::evolve {

struct PhenotypeGait {
  bool valid = false;
  GaitFile gait;
  std::string error;  // why it is invalid
};

// `held` (empty, or one entry per curve): a non-empty entry replaces that
// curve (a joint held still while it is not free to move).
PhenotypeGait make_phenotype_gait(const GaitFile& seed, const std::string& phenotype,
                                  const std::vector<std::string>& held = {});

// The mean of each seed curve over a stride, as a constant expression: where
// a joint rests while it is not free to move.
std::vector<std::string> curve_means(const GaitFile& seed);

}  // namespace animrt::evolve
