// Joint-angle CSVs as people write them: a spreadsheet's byte order mark,
// blanks after commas, a joint whose name starts with torso_.

#include "animrt/controllers/seqnet/joint_csv.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "seq_test_util.hpp"

namespace animrt::seqnet::joint_csv_test {
namespace {

TEST(JointCsv, AByteOrderMarkAndBlanksRoundCellsAreNoPartOfThem) {
  const std::string path = seqtest::temp_path("bom.csv");
  seqtest::write_text(path, "\xEF\xBB\xBFtime_s, neck_pan ,jaw\n0, 0.25 ,-0.5\n0.04,\t0.5,\t1\n");
  const JointCsv csv = read_joint_csv(path);
  EXPECT_EQ(csv.joints, (std::vector<std::string>{"neck_pan", "jaw"}));
  ASSERT_EQ(csv.rows.size(), 2u);
  EXPECT_EQ(csv.rows[0], (std::vector<double>{0.25, -0.5}));
  EXPECT_EQ(csv.rows[1], (std::vector<double>{0.5, 1.0}));
  EXPECT_EQ(csv.lines, (std::vector<int>{2, 3}));
}

// The corpus's body pose columns are no joints; a joint named torso_lean
// (the animatronic's) is one, and was dropped without a word.
TEST(JointCsv, OnlyTheCorpusBodyPoseColumnsAreNoJoints) {
  const std::string path = seqtest::temp_path("torso.csv");
  seqtest::write_text(path,
                      "time_s,hip,torso_lean,torso_x,torso_y,torso_z,torso_yaw\n"
                      "0,0.1,0.2,1,2,3,4\n");
  const JointCsv csv = read_joint_csv(path);
  EXPECT_EQ(csv.joints, (std::vector<std::string>{"hip", "torso_lean"}));
  EXPECT_EQ(csv.rows[0], (std::vector<double>{0.1, 0.2}));
}

}  // namespace
}  // namespace animrt::seqnet::joint_csv_test
