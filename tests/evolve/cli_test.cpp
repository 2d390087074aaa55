// `animrt evolve` end to end: serial, threaded and MPI runs of the same seed
// write the same gait and statistics, and the gait plays on the runtime.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "support/files.hpp"

namespace {

using animrt::kSourceRoot;

namespace fs = std::filesystem;
const std::string kAnimrt = std::string(ANIMRT_BINARY_DIR) + "/bin/animrt";

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The CSV without its timing columns (seconds, evals/s differ run to run).
std::string csv_without_timing(const std::string& path) {
  std::istringstream in(read(path));
  std::string line, out;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) cells.push_back(c);
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (i != 7 && i != 8) out += cells[i] + ",";
    }
    out += "\n";
  }
  return out;
}

int sh(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class EvolveCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("animrt_evolve_cli_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    std::ofstream run(dir_ / "run.yaml");
    run << "name: tiny\n"
        << "grammar: " << kSourceRoot << "/configs/grammars/quadruped_concatenating.bnf\n"
        << "model: " << kSourceRoot << "/configs/models/quadruped.xml\n"
        << "seed_gait: " << kSourceRoot << "/configs/gaits/quadruped_seed.yaml\n"
        << "search: {seed: 5, population: 6, generations: 1, elites: 1, max_depth: 5}\n"
        << "walk: {settle_s: 0.1, warmup_cycles: 1, measure_cycles: 1}\n";
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  int evolve(const std::string& out, const std::string& extra, const std::string& prefix = "") {
    return sh(prefix + kAnimrt + " evolve " + path("run.yaml") + " --out " + path(out) + " " +
              extra + " --quiet > " + path(out + ".log") + " 2>&1");
  }
  fs::path dir_;
};

TEST_F(EvolveCli, ThreadsAndMpiGiveTheSerialResultAndTheGaitPlays) {
  ASSERT_EQ(evolve("serial.yaml", "--threads 1"), 0) << read(path("serial.yaml.log"));
  ASSERT_EQ(evolve("threads.yaml", "--threads 2"), 0) << read(path("threads.yaml.log"));
  EXPECT_EQ(read(path("serial.yaml")), read(path("threads.yaml")));
  EXPECT_EQ(csv_without_timing(path("serial.csv")), csv_without_timing(path("threads.csv")));
  EXPECT_NE(read(path("serial.svg")).find("<svg"), std::string::npos);
  // Header + generations 0 and 1.
  const std::string csv = read(path("serial.csv"));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);

  // The evolved gait on the runtime's quadruped.
  std::string robot = read(kSourceRoot + "/configs/robots/quadruped.yaml");
  const std::string from = "file: ../gaits/walk.yaml";
  ASSERT_NE(robot.find(from), std::string::npos);
  robot.replace(robot.find(from), from.size(), "file: " + path("serial.yaml"));
  const std::string model = "model: ../models/quadruped.xml";  // relative: the copy's is absolute
  ASSERT_NE(robot.find(model), std::string::npos);
  robot.replace(robot.find(model), model.size(),
                "model: " + kSourceRoot + "/configs/models/quadruped.xml");
  std::ofstream(path("robot.yaml")) << robot;
  EXPECT_EQ(sh(kAnimrt + " validate " + path("robot.yaml") + " > /dev/null"), 0);
  EXPECT_EQ(sh(kAnimrt + " run " + path("robot.yaml") +
               " --lockstep --no-realtime --duration 0.5 > " + path("run.log") + " 2>&1"),
            0)
      << read(path("run.log"));

  ASSERT_EQ(sh("command -v mpirun > /dev/null 2>&1"), 0)
      << "mpirun not found (scripts/install-deps.sh installs Open MPI)";
  // Leak checking would flag Open MPI's own allocations under ASan.
  const std::string mpirun =
      "ASAN_OPTIONS=detect_leaks=0 OMPI_MCA_plm_rsh_agent=false mpirun --allow-run-as-root "
      "--oversubscribe -np 2 ";
  ASSERT_EQ(evolve("mpi.yaml", "--threads 1 --mpi", mpirun), 0) << read(path("mpi.yaml.log"));
  EXPECT_EQ(read(path("serial.yaml")), read(path("mpi.yaml")));
  EXPECT_EQ(csv_without_timing(path("serial.csv")), csv_without_timing(path("mpi.csv")));
}

// The CSV's column `column` on its data rows.
std::vector<std::string> csv_column(const std::string& path, std::size_t column) {
  std::istringstream in(read(path));
  std::string line;
  std::vector<std::string> out;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::string cell;
    for (std::size_t i = 0; i <= column && std::getline(ls, cell, ','); ++i) {
    }
    out.push_back(cell);
  }
  return out;
}

TEST_F(EvolveCli, AParetoRunWritesPlayableGaitsAndMpiGivesTheSameFront) {
  ASSERT_EQ(evolve("front", "--pareto --threads 1"), 0) << read(path("front.log"));
  const auto files = csv_column(path("front/front.csv"), 8);
  ASSERT_FALSE(files.empty()) << read(path("front.log"));
  EXPECT_NE(read(path("front/front.svg")).find("<circle"), std::string::npos);
  EXPECT_EQ(csv_column(path("front/history.csv"), 0), (std::vector<std::string>{"0", "1"}));

  // The first member walks on the model what the front says it walked.
  const auto speeds = csv_column(path("front/front.csv"), 4);
  ASSERT_EQ(
      sh(kAnimrt + " gait measure " + path("front/" + files[0]) + " --physics " + kSourceRoot +
         "/configs/models/quadruped.xml --starts 1 --perturb-deg 0 --settle 0.1 "
         "--warmup-cycles 1 --measure-cycles 1 > " +
         path("measure.log") + " 2>&1"),
      0)
      << read(path("measure.log"));
  char expected[32];
  std::snprintf(expected, sizeof expected, "%.3f", std::stod(speeds[0]));
  EXPECT_NE(read(path("measure.log")).find(std::string("speed ") + expected), std::string::npos)
      << "front.csv speed " << speeds[0] << "\n"
      << read(path("measure.log"));

  const std::string mpirun =
      "ASAN_OPTIONS=detect_leaks=0 OMPI_MCA_plm_rsh_agent=false mpirun --allow-run-as-root "
      "--oversubscribe -np 2 ";
  ASSERT_EQ(evolve("front_mpi", "--pareto --threads 1 --mpi", mpirun), 0)
      << read(path("front_mpi.log"));
  EXPECT_EQ(read(path("front/front.csv")), read(path("front_mpi/front.csv")));
  for (const auto& f : files) {
    EXPECT_EQ(read(path("front/" + f)), read(path("front_mpi/" + f))) << f;
  }
}

TEST_F(EvolveCli, BadRunFileExitsTwoWithOneClearLine) {
  std::ofstream(path("bad.yaml")) << "name: x\ngrammar: g.bnf\nmodel: m.xml\nseed_gait: s.yaml\n"
                                     "search: {population: lots}\n";
  EXPECT_EQ(sh(kAnimrt + " evolve " + path("bad.yaml") + " --out " + path("o.yaml") + " 2> " +
               path("err.txt")),
            2);
  EXPECT_EQ(read(path("err.txt")),
            "error: " + path("bad.yaml") +
                ":5:22: search.population: expected an integer, found \"lots\"\n");
}

}  // namespace
