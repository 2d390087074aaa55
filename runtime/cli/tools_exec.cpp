// Handing a tool's command to animrt-tools (see tools_exec.hpp).

#include "tools_exec.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>

#include "subcommand.hpp"

namespace animrt::cli {
namespace {

char** g_argv = nullptr;

// animrt-tools in the folder of the running animrt (/usr/bin in the
// packages, bin/ in the build tree).
std::string tools_path() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const auto dir = ec ? std::filesystem::path(".") : self.parent_path();
  return (dir / "animrt-tools").string();
}

}  // namespace

void remember_argv(char** argv) { g_argv = argv; }
char** remembered_argv() { return g_argv; }

int exec_tools(char** argv, const std::string& command_name) {
  const std::string tools = tools_path();
  std::cout.flush();
  std::cerr.flush();
  ::execv(tools.c_str(), argv);
  const int error = errno;
  const std::string command = !command_name.empty() ? command_name
                              : argv[1] != nullptr  ? argv[1]
                                                    : "";
  if (error == ENOENT) {
    std::cerr << "error: `animrt " << command
              << "` is one of the offline tools, which are not installed here (" << tools
              << "): install the animrt-tools package\n";
  } else {
    std::cerr << "error: cannot run " << tools << ": " << std::strerror(error) << '\n';
  }
  return kExitUsage;
}

}  // namespace animrt::cli
