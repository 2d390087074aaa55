#pragma once
// One error for every bus that cannot be brought up (a port that does not
// open, devices that do not answer), so that a figure with several
// unplugged adapters is fixed in one go rather than one run at a time.

#include <fmt/format.h>

#include <string>
#include <vector>

namespace animrt {

inline std::string bus_failures(const std::vector<std::string>& failed, std::size_t buses) {
  if (failed.size() == 1) return failed.front();
  std::string message = fmt::format("{} of {} buses cannot be brought up:", failed.size(), buses);
  for (const std::string& line : failed) message += "\n  " + line;
  return message;
}

}  // namespace animrt
