#pragma once
// CLI::Range for floating-point options, refusing NaN as well: CLI11's
// check compares the value with its bounds, and every comparison with NaN
// is false, so "--duration nan" passed it (a serve then ran until stopped).

#include <CLI/CLI.hpp>
#include <cmath>
#include <limits>
#include <string>

namespace animrt::cli {

class FiniteRange : public CLI::Range {
 public:
  FiniteRange(double min, double max, const std::string& name = {}) : CLI::Range(min, max, name) {
    func_ = [in_range = func_](std::string& input) {
      double value = 0.0;
      if (CLI::detail::lexical_cast(input, value) && std::isnan(value)) {
        return "Value " + input + " is not a number";
      }
      return in_range(input);
    };
  }
};

// CLI::PositiveNumber and CLI::NonNegativeNumber, refusing NaN.
inline const FiniteRange kPositiveNumber(std::numeric_limits<double>::min(),
                                         std::numeric_limits<double>::max(), "POSITIVE");
inline const FiniteRange kNonNegativeNumber(0.0, std::numeric_limits<double>::max(), "NONNEGATIVE");

}  // namespace animrt::cli
