#pragma once
// The error a gait file's text gets, or "no error".

#include <string>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/core/error.hpp"

namespace animrt {

inline std::string gait_file_error(const std::string& text) {
  try {
    (void)parse_gait_file(text, "g.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace animrt
