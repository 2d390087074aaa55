#pragma once
// --summary-json's file (run and serve): opened before anything moves (a
// summary that cannot be written is found then), written once at the end,
// every failure (a full disk, /dev/full, a close that fails) kept with its
// errno.

#include <string>

namespace animrt::cli {

struct SummaryFile {
  int fd = -1;
  int error = 0;
  SummaryFile() = default;
  SummaryFile(const SummaryFile&) = delete;
  SummaryFile& operator=(const SummaryFile&) = delete;
  ~SummaryFile();
  bool is_open() const { return fd >= 0; }
  bool open(const std::string& path);
  bool write(const std::string& text);  // and close
};

}  // namespace animrt::cli
