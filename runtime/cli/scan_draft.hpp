#pragma once
// The robot file `animrt scan --write-robot` drafts from what it found.

#include <string>

#include "animrt/bridge/commission/found_device.hpp"

namespace animrt::cli {

// Writes the draft (and the hold-still show it names, beside it) through
// a temporary file and a rename, so a failed write leaves nothing half
// written. Returns the number of joints. Throws std::runtime_error naming
// the file on failure.
int write_robot_draft(const std::string& path, const std::string& port,
                      const commission::ScanResult& found);

}  // namespace animrt::cli
