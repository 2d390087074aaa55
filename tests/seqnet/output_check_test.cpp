// A sequence model whose output is not finite is refused at load, and the
// seq commands never write a non-finite number.

#include "animrt/controllers/seqnet/output_check.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/core/error.hpp"
#include "seqnet/tiny_joint_model.hpp"

namespace animrt::seqnet {
namespace {
namespace output_check_test {

namespace fs = std::filesystem;
const std::string kAnimrt = std::string(ANIMRT_BINARY_DIR) + "/bin/animrt";

class ModelOutput : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / "seqnet_output_check";
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
    return path(name);
  }
  // Runs animrt; returns the exit code, stderr in `err`.
  int animrt(const std::string& args, std::string& err) const {
    const std::string log = path("stderr.txt");
    const int status = std::system((kAnimrt + " " + args + " >/dev/null 2>" + log).c_str());
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    err = ss.str();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
};

TEST_F(ModelOutput, AModelWhoseWeightsOverflowIsRefusedAtLoadNamingTheFile) {
  const std::string model = path("huge.model");
  write_model_file(model, test::tiny_joint_model(3e38F));
  // The file itself is sound: it reads back whole, CRC and all.
  const ModelFile read = read_model_file(model);
  SeqNetInference net(read, model);
  try {
    check_model_output(read, model);
    FAIL() << "a model computing inf was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, model);
    EXPECT_NE(e.message().find("not finite"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_checked_model(model), InputError);

  // Ordinary weights pass.
  write_model_file(path("small.model"), test::tiny_joint_model(0.1F));
  EXPECT_NO_THROW(read_checked_model(path("small.model")));
}

TEST_F(ModelOutput, GenerateAndCompleteRefuseAnOverflowingModelAndWriteNothing) {
  const std::string model = path("huge.model");
  write_model_file(model, test::tiny_joint_model(3e38F));
  write("init.csv", "hip,knee\n0.1,0.2\n");
  write("keys.csv", "hip,knee\n0.1,0.2\n0.3,-0.1\n");
  std::string err;
  int code = animrt("seq generate " + model + " --init " + path("init.csv") + " --frames 4 --out " +
                        path("gen.csv"),
                    err);
  EXPECT_NE(code, 0) << err;
  EXPECT_NE(err.find(model), std::string::npos) << err;
  EXPECT_NE(err.find("not finite"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("gen.csv")));
  code = animrt("seq complete " + model + " --keys " + path("keys.csv") + " --gap 3 --out " +
                    path("done.csv"),
                err);
  EXPECT_NE(code, 0) << err;
  EXPECT_NE(err.find(model), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("done.csv")));
}

// A sound model fed a key far outside its range (finite in the CSV, beyond
// float range once normalised) computed inf: such a key is refused at its
// line before the model runs, and nothing is written.
TEST_F(ModelOutput, GenerateAndCompleteNeverWriteANonFiniteNumber) {
  const std::string model = path("small.model");
  write_model_file(model, test::tiny_joint_model(0.1F));
  write("init.csv", "hip,knee\n1e300,0.2\n");
  write("keys.csv", "hip,knee\n1e300,0.2\n0.3,-0.1\n");
  std::string err;
  int code = animrt("seq generate " + model + " --init " + path("init.csv") + " --frames 4 --out " +
                        path("gen.csv"),
                    err);
  EXPECT_EQ(code, 2) << err;
  EXPECT_NE(err.find(path("init.csv") + ":2: hip: 1e+300 is far outside the range"),
            std::string::npos)
      << err;
  EXPECT_FALSE(fs::exists(path("gen.csv")));
  code = animrt("seq complete " + model + " --keys " + path("keys.csv") + " --gap 3 --out " +
                    path("done.csv"),
                err);
  EXPECT_EQ(code, 2) << err;
  EXPECT_NE(err.find(path("keys.csv") + ":2: hip:"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("done.csv")));

  // The same model from keys in its range writes finite rows.
  write("ok.csv", "hip,knee\n0.1,0.2\n0.3,-0.1\n");
  code = animrt(
      "seq complete " + model + " --keys " + path("ok.csv") + " --gap 3 --out " + path("done.csv"),
      err);
  EXPECT_EQ(code, 0) << err;
  EXPECT_TRUE(fs::exists(path("done.csv")));
}

// The last guard before a file is written: a frame the model computed that
// is not finite is refused, naming the joint and the frame.
TEST_F(ModelOutput, ANonFiniteFrameIsRefusedNamingItsJointAndFrame) {
  FrameMatrix frames(2, 3);
  frames << 0.1, 0.2, 0.3, 0.4, std::numeric_limits<double>::quiet_NaN(), 0.6;
  try {
    require_finite_frames(frames, "m.model", {"hip", "knee"});
    ADD_FAILURE() << "a NaN frame was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "m.model: output: the model computed a non-finite value (nan) for knee at frame 1; "
              "nothing was written");
  }
  frames(1, 1) = 0.5;
  EXPECT_NO_THROW(require_finite_frames(frames, "m.model", {"hip", "knee"}));
}

}  // namespace output_check_test
}  // namespace
}  // namespace animrt::seqnet
