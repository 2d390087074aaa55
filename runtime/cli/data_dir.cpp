// Finding the shipped data (see data_dir.hpp).

#include "data_dir.hpp"

#include <filesystem>
#include <system_error>

namespace animrt::cli {

std::string data_dir() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path bin = self.parent_path();
    if (fs::equivalent(bin, ANIMRT_BUILD_BIN, ec)) return ANIMRT_SOURCE_DATA;
    // A relocated install: PREFIX/bin/animrt beside PREFIX/share/animrt.
    const fs::path beside = bin.parent_path() / "share" / "animrt";
    if (fs::is_directory(beside, ec)) return beside.string();
  }
  return ANIMRT_INSTALLED_DATA;
}

}  // namespace animrt::cli
