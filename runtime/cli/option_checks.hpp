#pragma once
// Option checks CLI11's own miss: numbers, seeds, output paths.

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <string>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::cli {

// CLI::Range for floating-point options, refusing NaN as well: CLI11's check
// compares the value with its bounds, and every comparison with NaN is
// false, so "--duration nan" passed it (a serve then ran until stopped).
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

// run's and serve's --duration: a finite number of seconds, 0 (until
// stopped) up to a year, far past any show. The message quotes the argument
// as given, not CLI11's conversion of it.
class RunDurationValidator : public CLI::Validator {
 public:
  static constexpr double kMaxS = 365.0 * 24 * 3600;
  RunDurationValidator() : CLI::Validator("SECONDS") {
    func_ = [](std::string& text) -> std::string {
      double value = 0.0;
      const char* end = text.data() + text.size();
      const auto [stop, error] = std::from_chars(text.data(), end, value);
      const std::string expected = "expected seconds from 0 (until stopped) to " +
                                   std::to_string(static_cast<long long>(kMaxS)) + ", found " +
                                   quote(text);
      if (error != std::errc() || stop != end || text.empty()) return expected;
      if (!std::isfinite(value) || value < 0.0 || value > kMaxS) return expected;
      return {};
    };
  }
};
inline const RunDurationValidator kRunDuration;

// Seeds: the integers a scene or run file's seed takes, 0 to 2^63 - 1. An
// unsigned option alone reads "-1" as 2^64 - 1, and CLI::Range over int64
// let 2^63 through.
class SeedValidator : public CLI::Validator {
 public:
  SeedValidator() : CLI::Validator("SEED") {
    func_ = [](std::string& input) -> std::string {
      std::int64_t value = 0;
      const char* end = input.data() + input.size();
      const auto [stop, error] = std::from_chars(input.data(), end, value);
      if (error != std::errc() || stop != end || value < 0) {
        return "Value " + input + " is not a seed (an integer from 0 to " +
               std::to_string(std::numeric_limits<std::int64_t>::max()) + ")";
      }
      return {};
    };
  }
};
inline const SeedValidator kSeed;

// A whole number, all of the argument: CLI11 reads an empty argument as 0
// for an integer option (`servo ... set-id ""` gave a servo id 0).
class IntegerValidator : public CLI::Validator {
 public:
  // No name of its own: the option's type already reads INT in --help.
  IntegerValidator() : CLI::Validator("") {
    func_ = [](std::string& input) -> std::string {
      long long value = 0;
      const char* end = input.data() + input.size();
      const auto [stop, error] = std::from_chars(input.data(), end, value);
      if (input.empty() || error != std::errc() || stop != end)
        return "Value " + quote(input) + " is not a whole number";
      return {};
    };
  }
};
inline const IntegerValidator kInteger;

// Output paths, checked when the command line is read: a file that cannot
// be written is found before the work (a search, a training, a run), not
// after it. kOutputFile wants its folder to exist; kOutputFolder is a folder
// written into (made when missing).
class OutputPathValidator : public CLI::Validator {
 public:
  enum class Kind { file, folder };
  explicit OutputPathValidator(Kind kind) : CLI::Validator(kind == Kind::folder ? "DIR" : "FILE") {
    func_ = [kind](std::string& input) -> std::string {
      const std::string problem =
          kind == Kind::folder ? output_folder_problem(input) : output_file_problem(input);
      return problem.empty() ? problem : input + ": " + problem;
    };
  }
};
inline const OutputPathValidator kOutputFile(OutputPathValidator::Kind::file);
inline const OutputPathValidator kOutputFolder(OutputPathValidator::Kind::folder);

// The same check where an output's kind is known only after parsing (a file,
// or with another option or model a folder): false, with the message CLI11
// would print, when `path` will not do.
inline bool output_option_ok(const std::string& option, std::string path,
                             const OutputPathValidator& check) {
  const std::string problem = check(path);
  if (!problem.empty()) std::cerr << option << ": " << problem << '\n';
  return problem.empty();
}

}  // namespace animrt::cli
