// The USB serial adapter's latency timer, read from a fake sysfs tree.

#include "animrt/bridge/dynamixel/latency_timer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace animrt {
namespace {

namespace fs = std::filesystem;

struct FakeSysfs : ::testing::Test {
  FakeSysfs()
      : root(fs::temp_directory_path() /
             ("animrt_sysfs_" + std::to_string(::getpid()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(root);
  }
  ~FakeSysfs() override { fs::remove_all(root); }
  void set(const std::string& tty, const std::string& value) {
    const fs::path dir = root / "bus/usb-serial/devices" / tty;
    fs::create_directories(dir);
    std::ofstream(dir / "latency_timer") << value;
  }
  fs::path root;
};

TEST_F(FakeSysfs, DefaultSixteenMillisecondsIsWarnedAboutWithTheFix) {
  set("ttyUSB7", "16\n");
  EXPECT_EQ(read_latency_timer("/dev/ttyUSB7", root), 16);
  const std::string w = latency_timer_warning("/dev/ttyUSB7", root);
  EXPECT_NE(w.find("/dev/ttyUSB7 (ttyUSB7)"), std::string::npos) << w;
  EXPECT_NE(w.find("latency timer is 16 ms"), std::string::npos) << w;
  EXPECT_NE(w.find("echo 1 | sudo tee /sys/bus/usb-serial/devices/ttyUSB7/latency_timer"),
            std::string::npos)
      << w;
}

TEST_F(FakeSysfs, OneMillisecondIsFine) {
  set("ttyUSB0", "1\n");
  EXPECT_EQ(read_latency_timer("/dev/ttyUSB0", root), 1);
  EXPECT_EQ(latency_timer_warning("/dev/ttyUSB0", root), "");
}

TEST_F(FakeSysfs, OtherPortsAndMissingFilesSayNothing) {
  set("ttyUSB0", "16\n");
  EXPECT_FALSE(read_latency_timer("/dev/pts/3", root));
  EXPECT_FALSE(read_latency_timer("/dev/ttyS1", root));
  EXPECT_FALSE(read_latency_timer("/dev/ttyUSB1", root));  // no such adapter in the tree
  EXPECT_EQ(latency_timer_warning("/dev/ttyUSB1", root), "");
  set("ttyUSB2", "garbage");
  EXPECT_FALSE(read_latency_timer("/dev/ttyUSB2", root));
}

TEST_F(FakeSysfs, ALinkToTheAdapterIsFollowed) {
  // /dev/serial/by-id/... links to ../../ttyUSBn.
  set("ttyUSB3", "16\n");
  fs::create_directories(root / "dev");
  std::ofstream(root / "dev/ttyUSB3");
  fs::create_directories(root / "dev/serial/by-id");
  fs::create_symlink("../../ttyUSB3", root / "dev/serial/by-id/usb-FTDI_U2D2-if00-port0");
  EXPECT_EQ(read_latency_timer((root / "dev/serial/by-id/usb-FTDI_U2D2-if00-port0").string(), root),
            16);
}

}  // namespace
}  // namespace animrt
