// Finding the shipped data (see data_dir.hpp).

#include "data_dir.hpp"

#include <filesystem>
#include <system_error>

namespace animrt::cli {

namespace {

bool in_build_tree() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return !ec && std::filesystem::equivalent(self.parent_path(), ANIMRT_BUILD_BIN, ec);
}

}  // namespace

std::string data_dir() {
  namespace fs = std::filesystem;
  if (in_build_tree()) return ANIMRT_SOURCE_DATA;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    // A relocated install: PREFIX/bin/animrt beside PREFIX/share/animrt.
    const fs::path beside = self.parent_path().parent_path() / "share" / "animrt";
    if (fs::is_directory(beside, ec)) return beside.string();
  }
  return ANIMRT_INSTALLED_DATA;
}

std::string dashboard_www_dir() {
  if (in_build_tree()) return ANIMRT_DASHBOARD_WWW;
  return (std::filesystem::path(data_dir()) / "www").string();
}

}  // namespace animrt::cli
