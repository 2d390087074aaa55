#include "port_check.hpp"

#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace animrt::cli {
namespace {

namespace fs = std::filesystem;

bool holds(const fs::path& fd_dir, const std::string& target, bool* ptmx) {
  std::error_code ec;
  bool found = false;
  for (const auto& entry : fs::directory_iterator(fd_dir, ec)) {
    const fs::path link = fs::read_symlink(entry.path(), ec);
    if (ec) continue;
    if (link == target) found = true;
    if (link == "/dev/ptmx" || link == "/dev/pts/ptmx") *ptmx = true;
  }
  return found;
}

}  // namespace

std::string port_busy(const std::string& port) {
  char resolved[PATH_MAX];
  if (::realpath(port.c_str(), resolved) == nullptr) return "";
  const std::string device(resolved);
  const std::string self = std::to_string(::getpid());
  std::error_code ec;
  for (const auto& proc : fs::directory_iterator("/proc", ec)) {
    const std::string pid = proc.path().filename();
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos || pid == self) {
      continue;
    }
    bool ptmx = false;
    if (!holds(proc.path() / "fd", device, &ptmx) || ptmx) continue;
    std::string name;
    std::ifstream comm(proc.path() / "comm");
    std::getline(comm, name);
    return "busy: open in process " + pid + " (" + name + ")";
  }
  return "";
}

}  // namespace animrt::cli
