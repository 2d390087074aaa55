#pragma once
// A file written once at the end of a command's work (run's and serve's
// --summary-json, herd's summary and top view, head table's --out): opened
// before the work starts (before anything moves; a path that cannot be
// written is found then, not after a long run) and emptied only when it is
// written, every failure (a full disk, /dev/full, a close that fails) kept
// with its errno. A file it created and never wrote is removed again.

#include <stdexcept>
#include <string>

namespace animrt::cli {

struct OutputFile {
  int fd = -1;
  int error = 0;
  OutputFile() = default;
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();
  bool is_open() const { return fd >= 0; }
  bool open(const std::string& path);
  bool write(const std::string& text);  // and close

 private:
  std::string created_;  // the path, while a file this made is unwritten
};

// How every command says an output file failed: "--svg: cannot write
// PATH: No space left on device" (without the reason when `error` is 0).
std::runtime_error cannot_write(const std::string& option, const std::string& path, int error);

// run's and serve's --summary-json (none when `path` is empty): false, with
// the error logged, when it cannot be opened.
bool open_summary_json(OutputFile& file, const std::string& path);
// Writes `json` to run's or serve's --summary-json if one is open; when it
// cannot be written, prints the RECORD LOST line and turns a clean exit
// `code` into kExitRecordLost. Returns the exit code.
int write_summary_json(OutputFile& file, const std::string& path, const std::string& json,
                       int code);

}  // namespace animrt::cli
