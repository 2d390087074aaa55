#include "animrt/runtime/telemetry.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "animrt/runtime/loop_stats.hpp"

namespace animrt {
namespace {

TEST(TelemetryRing, KeepsOrderAndCountsDropsWhenFull) {
  TelemetryRing ring(2, 4);
  for (int i = 0; i < 6; ++i) {
    std::vector<double> r{double(i), double(-i)};
    EXPECT_EQ(ring.push(r), i < 4);
  }
  EXPECT_EQ(ring.dropped(), 2u);
  std::vector<double> out(2);
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.pop(out));
    EXPECT_EQ(out[0], i);
    EXPECT_EQ(out[1], -i);
  }
  EXPECT_FALSE(ring.pop(out));
}

TEST(TelemetryRing, ProducerAndConsumerThreadsLoseNothing) {
  TelemetryRing ring(3, 64);
  constexpr int kCount = 200000;
  // A full or empty ring sleeps briefly: on a machine busy with other tests
  // both threads may share one core, and a spinning (or merely yielding)
  // one would hold it for whole time slices while the other cannot move
  // (25 s instead of 0.05 s in a parallel CTest run).
  std::thread producer([&] {
    for (int i = 0; i < kCount;) {
      std::vector<double> r{double(i), double(i) * 2, double(i) * 3};
      if (ring.push(r)) {
        ++i;
      } else {
        std::this_thread::sleep_for(std::chrono::microseconds(20));
      }
    }
  });
  std::vector<double> out(3);
  int expected = 0;
  while (expected < kCount) {
    if (ring.pop(out)) {
      ASSERT_EQ(out[0], expected);
      ASSERT_EQ(out[2], expected * 3.0);
      ++expected;
    } else {
      std::this_thread::sleep_for(std::chrono::microseconds(20));
    }
  }
  producer.join();
}

TEST(TelemetryWriter, WritesAHeaderAndOneRowPerRecord) {
  const std::string path = ::testing::TempDir() + "/telemetry_test.csv";
  TelemetryRing ring(5, 16);
  std::vector<std::string> names{"a", "b"};
  {
    TelemetryWriter writer(path, names, ring);
    ring.push(std::vector<double>{0.0, 1.0, 2.0, 3.0, 4.0});
    ring.push(std::vector<double>{0.005, 1.5, 2.5, 3.5, 4.5});
    writer.finish();
    EXPECT_EQ(writer.written(), 2u);
  }
  std::ifstream in(path);
  std::string header, row1, row2;
  std::getline(in, header);
  std::getline(in, row1);
  std::getline(in, row2);
  EXPECT_EQ(header, "time_s,a_cmd_rad,b_cmd_rad,a_meas_rad,b_meas_rad");
  EXPECT_EQ(row1, "0,1,2,3,4");
  EXPECT_EQ(row2, "0.005,1.5,2.5,3.5,4.5");
  std::remove(path.c_str());
}

TEST(TelemetryWriter, CountsRecordsThatCannotBeWrittenAndSaysWhy) {
  TelemetryRing ring(3, 16);
  std::vector<std::string> names{"a"};
  TelemetryWriter writer("/dev/full", names, ring);
  ring.push(std::vector<double>{0.0, 1.0, 2.0});
  ring.push(std::vector<double>{0.005, 1.5, 2.5});
  writer.finish();
  EXPECT_EQ(writer.written(), 0u);
  EXPECT_EQ(writer.lost(), 2u);
  EXPECT_EQ(writer.error(), ENOSPC);
}

TEST(MicrosHistogram, Quantiles) {
  MicrosHistogram h(1000);
  for (int i = 1; i <= 100; ++i) h.add(i * 1e-6);
  EXPECT_DOUBLE_EQ(h.quantile(0.5), 50e-6);
  EXPECT_DOUBLE_EQ(h.quantile(0.99), 99e-6);
  EXPECT_DOUBLE_EQ(h.max(), 100e-6);
  h.add(5.0);  // beyond the last bin: reported through max
  EXPECT_DOUBLE_EQ(h.quantile(1.0), 5.0);
}

}  // namespace
}  // namespace animrt
