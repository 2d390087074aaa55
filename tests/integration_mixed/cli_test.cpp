// The CLI on the mixed figure: `animrt run ... --backend sim` and the
// endpoint lines of `animrt sim`.

#include <gtest/gtest.h>
#include <signal.h>

#include <cstdio>
#include <string>

namespace {

const std::string kAnimrt = std::string(ANIMRT_BINARY_DIR) + "/bin/animrt";
const std::string kFigure = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml";

std::string run(const std::string& command, int* status) {
  std::string out;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return "popen failed";
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  *status = ::pclose(p);
  return out;
}

TEST(MixedCli, RunsTheAnimatronicFigureOnTheSimBackend) {
  int status = -1;
  const std::string out =
      run(kAnimrt + " run " + kFigure + " --backend sim --lockstep --duration 0.5", &status);
  EXPECT_EQ(WEXITSTATUS(status), 0) << out;
  EXPECT_NE(out.find("simulated devices: modbus-tcp torso 127.0.0.1:"), std::string::npos) << out;
  EXPECT_NE(out.find("simulated devices: serial face /dev/pts/"), std::string::npos) << out;
  EXPECT_NE(out.find("ended by duration"), std::string::npos) << out;
  EXPECT_NE(out.find("bus torso: cycle time"), std::string::npos) << out;
}

TEST(MixedCli, SimPrintsOneLinePerBus) {
  int status = -1;
  // `animrt sim` serves until a signal: stop it after it printed.
  const std::string out = run("timeout -s INT 1 " + kAnimrt + " sim " + kFigure, &status);
  EXPECT_NE(out.find("serial neck /dev/pts/"), std::string::npos) << out;
  EXPECT_NE(out.find("serial face /dev/pts/"), std::string::npos) << out;
  EXPECT_NE(out.find("modbus-tcp torso 127.0.0.1:"), std::string::npos) << out;
}

}  // namespace
