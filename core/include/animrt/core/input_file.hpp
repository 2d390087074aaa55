#pragma once
// Opening input files safely: only regular files under a size limit are read,
// so a directory, a FIFO (which would block) or a device such as /dev/zero
// (which never ends) gets its own clear message instead of a hang, a huge
// allocation or a misleading "file is empty".

#include <cstdint>
#include <string>
#include <vector>

#include "animrt/core/error.hpp"

namespace animrt {

// What input_file_problem says of a path where nothing is.
inline constexpr const char* kFileMissing = "does not exist";

// Text inputs: BNF, model, CSV files (YAML files have a smaller limit,
// kMaxYamlFileBytes in yaml_doc.hpp).
inline constexpr std::uintmax_t kMaxInputFileBytes = std::uintmax_t{64} << 20;  // 64 MiB
// Inputs that may be larger (WAV sound tracks, MJCF models). A sound file is
// decoded whole into floats, up to 4x its size in memory.
inline constexpr std::uintmax_t kMaxMediaFileBytes = std::uintmax_t{256} << 20;  // 256 MiB

// What a gzip-compressed input may inflate to. Checked while inflating, so a
// small file that would inflate to gigabytes stops at this limit.
inline constexpr std::uintmax_t kMaxInflatedBytes = std::uintmax_t{64} << 20;  // 64 MiB

// What is wrong with `path` as an input file, or "" when it is a readable
// regular file of at most `max_bytes`: "does not exist", "is a directory",
// "is not a regular file (FIFO)", "is 80 MiB, more than the 64 MiB limit", ...
// Never opens the file (so a FIFO cannot block).
std::string input_file_problem(const std::string& path,
                               std::uintmax_t max_bytes = kMaxInputFileBytes);

// Throws InputError "PATH: PROBLEM" when something other than a regular
// file is at `path` (a device, a FIFO, a folder): a file written beside it
// and renamed over it, as outputs are saved, would replace it (as root, a
// /dev/zero given as an output became a file). Nothing there is fine.
void check_replaceable_file(const std::string& path);

// Writes all `size` bytes at `data` to `fd`, again after EINTR and after a
// short write. Returns 0, or the errno of the write that failed (EIO for one
// that wrote nothing); `written`, when given, gets the bytes written.
int write_all(int fd, const void* data, std::size_t size, std::size_t* written = nullptr);

// What keeps a command from writing a file at `path`, or "": a folder there,
// or no folder to hold it. Asked before the work, so a bad path is not found
// after a long run.
std::string output_file_problem(const std::string& path);

// What keeps a command from writing into a folder at `path` (making it when
// it is missing), or "": a file there, or a file where one of its parents
// should be.
std::string output_folder_problem(const std::string& path);

// Throws InputError "PATH: PROBLEM" when input_file_problem finds one.
void check_input_file(const std::string& path, std::uintmax_t max_bytes = kMaxInputFileBytes);

// The whole file, after the checks above (made again on the open descriptor,
// so a file swapped between check and open is caught too). Throws InputError.
std::string read_input_file(const std::string& path, std::uintmax_t max_bytes = kMaxInputFileBytes);

// The whole file as bytes, read as read_input_file does; a file that starts
// with the gzip magic is inflated (several members in a row as one stream),
// and refused as soon as its inflated bytes pass `max_inflated`.
std::vector<std::uint8_t> read_input_bytes(const std::string& path,
                                           std::uintmax_t max_bytes = kMaxInputFileBytes,
                                           std::uintmax_t max_inflated = kMaxInflatedBytes);

// Counts read from a binary header, checked before anything is sized from
// them: throws InputError "PATH: KEY: WHAT (COUNT x ITEM bytes) is larger
// than the file (AVAILABLE bytes)" unless count * item fits.
void check_header_count(const std::string& path, const std::string& key, const std::string& what,
                        std::uint64_t count, std::uint64_t item_bytes, std::uint64_t available);

}  // namespace animrt
