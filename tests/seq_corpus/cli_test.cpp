// `animrt seq corpus` end to end on a small corpus: the index lists every
// sequence with its files, the frames and joints agree with it, the same
// seed writes the same bytes, and bad input gets a clear error.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/files.hpp"

namespace {

using animrt::kSourceRoot;

namespace fs = std::filesystem;
const std::string kAnimrt = std::string(ANIMRT_BINARY_DIR) + "/bin/animrt";

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int sh(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class SeqCorpusCli : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / "seq_corpus_cli";
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  int corpus(const std::string& out, const std::string& extra) {
    return sh(kAnimrt + " seq corpus --quiet --model quadruped --configs " + kSourceRoot +
              "/configs --frames 4 --vertices 250 --seeds 2 --froude 0.06 --out " +
              (dir / out).string() + " " + extra + " > " + (dir / (out + ".log")).string() +
              " 2>&1");
  }
};

TEST_F(SeqCorpusCli, WritesIndexFramesAndJointsDeterministically) {
  ASSERT_EQ(corpus("a", ""), 0) << read(dir / "a.log");
  const YAML::Node index = YAML::LoadFile((dir / "a" / "index.yaml").string());
  const int vertices = index["vertices"].as<int>();
  EXPECT_NEAR(vertices, 250, 50);
  const YAML::Node seqs = index["sequences"];
  ASSERT_EQ(seqs.size(), 4u);  // 2 gaits x 1 Froude number x 1 turn x 2 seeds
  for (const auto& s : seqs) {
    EXPECT_EQ(s["froude"].as<double>(), 0.06);
    EXPECT_EQ(s["turn_rad_s"].as<double>(), 0.0);
    EXPECT_EQ(s["vertices"].as<int>(), vertices);
    EXPECT_FALSE(s["fell"].as<bool>());
    const int frames = s["frames"].as<int>();
    EXPECT_EQ(frames, 4);
    int objs = 0;
    for (const auto& e : fs::directory_iterator(dir / "a" / s["folder"].as<std::string>())) {
      ++objs;
      const std::string text = read(e.path());
      int v = 0;
      std::istringstream in(text);
      for (std::string line; std::getline(in, line);) v += line.rfind("v ", 0) == 0;
      EXPECT_EQ(v, vertices) << e.path();
    }
    EXPECT_EQ(objs, frames);
    std::istringstream csv(read(dir / "a" / s["joints_csv"].as<std::string>()));
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header.rfind("time_s,lf_hip,lf_knee,lf_ankle,", 0), 0u) << header;
    EXPECT_NE(header.find(",torso_x,torso_y,torso_z,torso_yaw"), std::string::npos);
    int rows = 0;
    for (std::string line; std::getline(csv, line);) {
      ++rows;
      EXPECT_EQ(std::count(line.begin(), line.end(), ','), 16) << line;  // 12 joints + 4 torso
    }
    EXPECT_EQ(rows, frames);
  }
  EXPECT_NE(seqs[0]["start_phase"].as<double>(), seqs[1]["start_phase"].as<double>());
  EXPECT_TRUE(fs::exists(dir / "a" / "rest.obj"));
  EXPECT_TRUE(fs::exists(dir / "a" / "skin_weights.csv"));

  // The same command again: the same bytes.
  ASSERT_EQ(corpus("b", ""), 0) << read(dir / "b.log");
  for (const auto& e : fs::recursive_directory_iterator(dir / "a")) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir / "a");
    ASSERT_EQ(read(e.path()), read(dir / "b" / rel)) << rel;
  }
  // Another first seed: other motion.
  ASSERT_EQ(corpus("c", "--seed 9"), 0) << read(dir / "c.log");
  const YAML::Node other = YAML::LoadFile((dir / "c" / "index.yaml").string());
  EXPECT_EQ(other["sequences"][0]["seed"].as<int>(), 9);
}

TEST_F(SeqCorpusCli, BadInputIsAClearError) {
  EXPECT_EQ(sh(kAnimrt + " seq corpus --out " + (dir / "x").string() + " --model " +
               (dir / "missing.xml").string() + " --gait g.yaml --froude 0.1 > " +
               (dir / "log").string() + " 2>&1"),
            2);
  EXPECT_NE(read(dir / "log").find("missing.xml"), std::string::npos) << read(dir / "log");
  EXPECT_EQ(sh(kAnimrt + " seq corpus --out " + (dir / "x").string() + " --model " +
               (dir / "m.xml").string() + " > /dev/null 2>&1"),
            1);  // a model of its own needs --gait and --froude
  EXPECT_EQ(sh(kAnimrt + " seq corpus --out " + (dir / "x").string() + " --model cat > " +
               (dir / "log").string() + " 2>&1"),
            1);
  EXPECT_NE(read(dir / "log").find("horse, quadruped"), std::string::npos) << read(dir / "log");
  EXPECT_EQ(
      sh(kAnimrt + " seq corpus --out " + (dir / "y").string() + " --model quadruped --configs " +
         kSourceRoot + "/configs --fps 30 > " + (dir / "log").string() + " 2>&1"),
      1);
  EXPECT_NE(read(dir / "log").find("30"), std::string::npos) << read(dir / "log");
}

}  // namespace
