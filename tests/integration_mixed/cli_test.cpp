// The CLI on the mixed figure: `animrt validate` of a layered config,
// `animrt run ... --backend sim --lockstep` and the endpoint lines of
// `animrt sim`.

#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "support/files.hpp"

extern char** environ;

namespace {

using animrt::kConfigsDir;

const std::string kAnimrt = std::string(ANIMRT_BINARY_DIR) + "/bin/animrt";
const std::string kFigure = kConfigsDir + "/robots/animatronic.yaml";

std::string run(const std::string& command, int* status) {
  std::string out;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return "popen failed";
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  *status = ::pclose(p);
  return out;
}

TEST(MixedCli, ValidateNamesEveryLayerFile) {
  int status = -1;
  const std::string out = run(kAnimrt + " validate " + kFigure, &status);
  EXPECT_EQ(WEXITSTATUS(status), 0) << out;
  const std::string robots = kConfigsDir + "/robots/";
  // Then the buses that animrt cannot guard itself: the Maestro's timeout
  // is a board setting, the Modbus map names no watchdog register.
  EXPECT_EQ(out, kFigure + ": ok (6 joints, 3 buses, 6 devices, layers [gait " + robots +
                     "../shows/neck_idle_gait.yaml, show " + robots +
                     "../shows/hello.yaml])\nbus face (maestro): the Maestro takes its serial "
                     "timeout only from its settings: set Serial Settings > Timeout to 0.10 s in "
                     "the Maestro Control Center, and each channel's On startup or error to Off "
                     "or Go to (what the servo does when the host dies)\nbus torso (modbus-tcp): "
                     "no device-side guard (a register map names no watchdog register; set the "
                     "drive's own communication timeout with its vendor tool): if the host dies, "
                     "the drives hold their last target\n");
}

// The figure with every bus timeout at 100 ms: a lockstep run judges
// silence in simulated time, so the shipped few-millisecond timeouts would
// let a loaded machine's scheduling delays fault a healthy device.
std::string patient_figure() {
  std::ifstream in(kFigure);
  std::stringstream text;
  text << in.rdbuf();
  std::string out;
  std::string line;
  while (std::getline(text, line)) {
    if (auto at = line.find("timeout_ms: "); at != std::string::npos) {
      line = line.substr(0, at) + "timeout_ms: 100";
    }
    // Every bus timeout must be below the watchdog.
    if (auto at = line.find("watchdog_timeout_s: "); at != std::string::npos) {
      line = line.substr(0, at) + "watchdog_timeout_s: 0.5";
    }
    for (const std::string folder : {"../shows/", "../modbus/"}) {
      if (auto at = line.find(folder); at != std::string::npos) {
        line.replace(at, folder.size(), kConfigsDir + "/" + folder.substr(3));
      }
    }
    out += line + "\n";
  }
  const std::string path = ::testing::TempDir() + "/animatronic_patient.yaml";
  std::ofstream(path) << out;
  return path;
}

TEST(MixedCli, RunsTheAnimatronicFigureOnTheSimBackend) {
  int status = -1;
  const std::string out = run(
      kAnimrt + " run " + patient_figure() + " --backend sim --lockstep --no-audio --duration 0.5",
      &status);
  EXPECT_EQ(WEXITSTATUS(status), 0) << out;
  EXPECT_NE(out.find("simulated devices: modbus-tcp torso 127.0.0.1:"), std::string::npos) << out;
  EXPECT_NE(out.find("simulated devices: serial face /dev/pts/"), std::string::npos) << out;
  EXPECT_NE(out.find("ended by duration"), std::string::npos) << out;
  EXPECT_NE(out.find("bus torso: cycle time"), std::string::npos) << out;
}

// `animrt sim` serves until a signal: its output is read until every bus has
// printed its line (however long start-up takes), then it is interrupted.
TEST(MixedCli, SimPrintsOneLinePerBus) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  std::string path = kAnimrt, sub = "sim", config = kFigure;
  char* argv[] = {path.data(), sub.data(), config.data(), nullptr};
  pid_t pid = -1;
  ASSERT_EQ(::posix_spawn(&pid, kAnimrt.c_str(), &actions, nullptr, argv, environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  FILE* in = ::fdopen(fds[0], "r");
  ASSERT_NE(in, nullptr);
  std::string out;
  char buf[512];
  int lines = 0;
  while (lines < 3 && std::fgets(buf, sizeof buf, in)) {
    out += buf;
    ++lines;
  }
  ::kill(pid, SIGINT);
  int status = -1;
  ::waitpid(pid, &status, 0);
  std::fclose(in);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_NE(out.find("serial neck /dev/pts/"), std::string::npos) << out;
  EXPECT_NE(out.find("serial face /dev/pts/"), std::string::npos) << out;
  EXPECT_NE(out.find("modbus-tcp torso 127.0.0.1:"), std::string::npos) << out;
}

}  // namespace
