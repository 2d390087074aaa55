#pragma once
// Opening input files safely: only regular files under a size limit are read,
// so a directory, a FIFO (which would block) or a device such as /dev/zero
// (which never ends) gets its own clear message instead of a hang, a huge
// allocation or a misleading "file is empty".

#include <cstdint>
#include <string>

#include "animrt/core/error.hpp"

namespace animrt {

// What input_file_problem says of a path where nothing is.
inline constexpr const char* kFileMissing = "does not exist";

// Text inputs: YAML, BNF, model files.
inline constexpr std::uintmax_t kMaxInputFileBytes = std::uintmax_t{64} << 20;  // 64 MiB
// Inputs that may be larger (WAV sound tracks, MJCF models). A sound file is
// decoded whole into floats, up to 4x its size in memory.
inline constexpr std::uintmax_t kMaxMediaFileBytes = std::uintmax_t{256} << 20;  // 256 MiB

// What is wrong with `path` as an input file, or "" when it is a readable
// regular file of at most `max_bytes`: "does not exist", "is a directory",
// "is not a regular file (FIFO)", "is 80 MiB, more than the 64 MiB limit", ...
// Never opens the file (so a FIFO cannot block).
std::string input_file_problem(const std::string& path,
                               std::uintmax_t max_bytes = kMaxInputFileBytes);

// Throws InputError "PATH: PROBLEM" when input_file_problem finds one.
void check_input_file(const std::string& path, std::uintmax_t max_bytes = kMaxInputFileBytes);

// The whole file, after the checks above (made again on the open descriptor,
// so a file swapped between check and open is caught too). Throws InputError.
std::string read_input_file(const std::string& path, std::uintmax_t max_bytes = kMaxInputFileBytes);

}  // namespace animrt
