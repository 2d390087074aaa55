// Hostile inputs for the sequence network's file readers other than meshes:
// feature files, model files and joint-angle CSVs each refuse a FIFO (without
// blocking), a device and a gzip bomb, and name the file.

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/joint_csv.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/core/error.hpp"
#include "seq_test_util.hpp"
#include "support/hostile_files.hpp"

namespace animrt::seqnet {
namespace {

namespace fs = std::filesystem;

std::string refusal_of(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

struct HostileReader {
  const char* name;
  const char* extension;
  std::function<void(const std::string&)> read;
};

const HostileReader kHostileReaders[] = {
    {"feature file", ".feat", [](const std::string& p) { (void)read_feature_file(p); }},
    {"model file", ".seqnn", [](const std::string& p) { (void)read_model_file(p); }},
    {"joint CSV", ".csv", [](const std::string& p) { (void)read_joint_csv(p); }},
};

TEST(SeqInputs, FifoDeviceAndGzipBombAreRefusedByName) {
  const std::string dir = seqtest::temp_path("hostile_seq_inputs");
  fs::remove_all(dir);
  fs::create_directories(dir);
  animrt::test::write_gzip_bomb(dir + "/bomb.gz", std::uint64_t{80} << 20);
  for (const HostileReader& r : kHostileReaders) {
    SCOPED_TRACE(r.name);
    const animrt::test::UnblockedFifo fifo(dir + "/pipe" + r.extension);
    EXPECT_EQ(refusal_of([&] { r.read(fifo.path()); }),
              fifo.path() + ": is not a regular file (FIFO)");
    EXPECT_EQ(fifo.times_opened(), 0);
    const std::string zero = dir + "/zero" + r.extension;
    fs::create_symlink("/dev/zero", zero);
    EXPECT_EQ(refusal_of([&] { r.read(zero); }),
              zero + ": is not a regular file (character device)");
  }
  // The binary formats read gzip transparently; a CSV is plain text.
  for (const HostileReader& r : {kHostileReaders[0], kHostileReaders[1]}) {
    SCOPED_TRACE(r.name);
    const std::string bomb = dir + "/bomb" + r.extension;
    fs::copy_file(dir + "/bomb.gz", bomb);
    EXPECT_EQ(refusal_of([&] { r.read(bomb); }),
              bomb + ": gzip data inflates to more than the 64 MiB limit");
  }
}

TEST(SeqInputs, JointCsvQuotesALongCellShort) {
  const std::string path = seqtest::temp_path("long_cell.csv");
  seqtest::write_text(path, "time_s,neck\n0," + std::string(60u << 20, '9') + "x\n");
  const std::string e = refusal_of([&] { (void)read_joint_csv(path); });
  EXPECT_LT(e.size(), path.size() + 200) << e.substr(0, 300);
  EXPECT_EQ(e.rfind(path + ":2:3: neck: \"999", 0), 0u) << e.substr(0, 300);
}

}  // namespace
}  // namespace animrt::seqnet
