// Handing `seq train` over to animrt-seqnet (see
// seq_net_forward.hpp).

#include "seq_net_forward.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "subcommand.hpp"

namespace animrt::cli {
namespace {

// animrt-seqnet in the folder of the running animrt.
std::string tool_path() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const auto dir = ec ? std::filesystem::path(".") : self.parent_path();
  return (dir / "animrt-seqnet").string();
}

void forward(const std::string& command, const std::vector<std::string>& args) {
  const std::string tool = tool_path();
  // argv[0] is the name its usage lines give: the command the user typed.
  std::vector<std::string> words{"animrt seq", command};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::cout.flush();
  ::execv(tool.c_str(), argv.data());
  std::cerr << "error: cannot run " << tool << " (" << std::strerror(errno)
            << "): the sequence network's commands are in that executable, built with animrt "
               "(make build)\n";
  throw CLI::RuntimeError(kExitUsage);
}

void add_forwarder(CLI::App& seq, const std::string& name, const std::string& description) {
  auto* cmd = seq.add_subcommand(name, description + " (animrt-seqnet " + name + " --help)");
  cmd->prefix_command();  // every argument, --help included, goes to animrt-seqnet
  cmd->set_help_flag();
  cmd->callback([cmd, name] { forward(name, cmd->remaining()); });
}

}  // namespace

void add_seq_net_forwarders(CLI::App& seq) {
  add_forwarder(seq, "train",
                "Train the bidirectional sequence network on mesh features or joint CSVs");
}

}  // namespace animrt::cli
