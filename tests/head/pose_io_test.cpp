// Head-pose loaders: BVH (channel order from the file, head relative to the
// torso) and marker sets (rotation recovered per frame by SVD).

#include "animrt/controllers/head/pose_io.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "animrt/core/error.hpp"
#include "head_test_util.hpp"

namespace animrt::head {
namespace {

// Our axes: x forward, y left, z up. BVH: x left, y up, z forward.
Eigen::Matrix3d our_axis_rotation(char bvh_axis, double deg) {
  const double a = deg * std::numbers::pi / 180.0;
  const Eigen::Vector3d axis = bvh_axis == 'X'   ? Eigen::Vector3d::UnitY()
                               : bvh_axis == 'Y' ? Eigen::Vector3d::UnitZ()
                                                 : Eigen::Vector3d::UnitX();
  return Eigen::AngleAxisd(a, axis).toRotationMatrix();
}

void expect_same_rotation(const Euler& got, const Eigen::Matrix3d& want) {
  EXPECT_LT((euler_to_matrix(got) - want).norm(), 1e-6)
      << "got yaw " << got.yaw << " pitch " << got.pitch << " roll " << got.roll;
}

// Hips (root, 6 channels) -> Spine -> Neck -> Head, the head's rotation
// channels in `head_order` (e.g. "YXZ").
std::string bvh_text(const std::string& head_order,
                     const std::vector<std::vector<double>>& frames) {
  std::string rot;
  for (char c : head_order) rot += std::string(" ") + c + "rotation";
  std::string s =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n"
      "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
      "  JOINT Spine\n  {\n    OFFSET 0 10 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "    JOINT Neck\n    {\n      OFFSET 0 30 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "      JOINT Head\n      {\n        OFFSET 0 10 0\n        CHANNELS 3" +
      rot +
      "\n        End Site\n        {\n          OFFSET 0 10 0\n        }\n      }\n    }\n  }\n}\n"
      "MOTION\nFrames: " +
      std::to_string(frames.size()) + "\nFrame Time: 0.01\n";
  for (const auto& f : frames) {
    for (double v : f) s += std::to_string(v) + " ";
    s += "\n";
  }
  return s;
}

std::string write_file(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(Bvh, RotationChannelsAreAppliedInTheFilesOrder) {
  const std::string dir = test::temp_dir("bvh_order");
  // Only the head turns: a = 20, b = -15, c = 10 on the head's first, second
  // and third channel.
  const std::vector<std::vector<double>> frames = {
      {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 20, -15, 10},
  };
  for (const std::string order : {"YXZ", "ZXY", "XYZ"}) {
    const PoseTrack t = load_bvh(write_file(dir, order + ".bvh", bvh_text(order, frames)));
    ASSERT_EQ(t.size(), 1u);
    const Eigen::Matrix3d want = our_axis_rotation(order[0], 20) *
                                 our_axis_rotation(order[1], -15) * our_axis_rotation(order[2], 10);
    SCOPED_TRACE(order);
    expect_same_rotation(t.poses[0], want);
  }
  // Y (up), X (left), Z (forward) is our yaw, pitch, roll exactly.
  const PoseTrack yxz = load_bvh(dir + "/YXZ.bvh");
  EXPECT_NEAR(yxz.poses[0].yaw, 20, 1e-6);
  EXPECT_NEAR(yxz.poses[0].pitch, -15, 1e-6);
  EXPECT_NEAR(yxz.poses[0].roll, 10, 1e-6);
  // The other orders give different angles for the same numbers.
  const PoseTrack zxy = load_bvh(dir + "/ZXY.bvh");
  EXPECT_GT(std::abs(zxy.poses[0].yaw - 20) + std::abs(zxy.poses[0].roll - 10), 0.5);
  std::filesystem::remove_all(dir);
}

TEST(Bvh, HeadIsRelativeToTheTorso) {
  const std::string dir = test::temp_dir("bvh_torso");
  // Frame 0: only the root and the spine move (the whole body turns and
  // bends): the head does not move relative to the spine.
  // Frame 1: the neck turns 10 deg and the head 5 deg more about the up axis.
  const std::vector<std::vector<double>> frames = {
      {5, 1, 2, 0, 0, 30, 0, 20, 0, 0, 0, 0, 0, 0, 0},
      {5, 1, 2, 0, 0, 30, 0, 20, 0, 0, 0, 10, 5, 0, 0},
  };
  const std::string path = write_file(dir, "a.bvh", bvh_text("YXZ", frames));
  BvhOptions spine;
  spine.torso_joint = "Spine";
  const PoseTrack rel = load_bvh(path, spine);
  ASSERT_EQ(rel.size(), 2u);
  EXPECT_NEAR(rel.times[1], 0.01, 1e-12);
  expect_same_rotation(rel.poses[0], Eigen::Matrix3d::Identity());
  EXPECT_NEAR(rel.poses[1].yaw, 15, 1e-6);
  EXPECT_NEAR(rel.poses[1].pitch, 0, 1e-6);
  // Relative to the root (the default) the spine's 20 deg bend about BVH X
  // counts, the root's 30 deg turn does not.
  const PoseTrack root = load_bvh(path);
  expect_same_rotation(root.poses[0], our_axis_rotation('X', 20));
  expect_same_rotation(root.poses[1], our_axis_rotation('X', 20) * our_axis_rotation('Y', 15));

  BvhOptions missing;
  missing.head_joint = "Skull";
  try {
    load_bvh(path, missing);
    FAIL() << "loaded a head joint that does not exist";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, path);
    EXPECT_NE(std::string(e.what()).find("Skull"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(Bvh, BadMotionValueNamesFileAndLine) {
  const std::string dir = test::temp_dir("bvh_bad");
  std::string text = bvh_text("YXZ", {{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 3}});
  text.replace(text.rfind("3.000000"), 8, "x");
  const std::string path = write_file(dir, "bad.bvh", text);
  try {
    load_bvh(path);
    FAIL() << "loaded a frame with a non-number";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, path);
    EXPECT_EQ(e.where().line, 29);  // the frame's line
    EXPECT_NE(std::string(e.what()).find("expected a number"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(Markers, SvdRecoversRotationsOfAMovingMarkerSet) {
  const std::string dir = test::temp_dir("markers");
  // Five markers on a head (metres, our axes), the nose among them.
  const std::vector<std::string> names = {"nose", "forehead", "left_ear", "right_ear", "chin"};
  Eigen::MatrixX3d ref(5, 3);
  ref << 0.10, 0.0, 0.0, 0.08, 0.0, 0.08, 0.0, 0.07, 0.0, 0.0, -0.07, 0.0, 0.07, 0.0, -0.08;
  const std::vector<Euler> truth = {{0, 0, 0},   {10, 0, 0},   {0, 15, 0},
                                    {0, 0, -12}, {25, -10, 5}, {-30, 20, 8}};
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.0002);  // 0.2 mm
  std::string csv = "time_s";
  for (const auto& n : names) csv += "," + n + "_x," + n + "_y," + n + "_z";
  csv += "\n";
  for (std::size_t f = 0; f < truth.size(); ++f) {
    // The head rotates about its centre and the body carries it around.
    const Eigen::Matrix3d r = euler_to_matrix(truth[f]);
    const Eigen::RowVector3d shift(0.01 * static_cast<double>(f), -0.02, 1.5);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3f", 0.1 * static_cast<double>(f));
    csv += buf;
    for (Eigen::Index m = 0; m < ref.rows(); ++m) {
      const Eigen::RowVector3d p = (r * ref.row(m).transpose()).transpose() + shift;
      for (int k = 0; k < 3; ++k) {
        std::snprintf(buf, sizeof buf, ",%.6f", p(k) + noise(rng));
        csv += buf;
      }
    }
    csv += "\n";
  }
  const PoseTrack t = load_marker_csv(write_file(dir, "a.markers.csv", csv));
  ASSERT_EQ(t.size(), truth.size());
  for (std::size_t f = 0; f < truth.size(); ++f) {
    SCOPED_TRACE(f);
    EXPECT_NEAR(t.times[f], 0.1 * static_cast<double>(f), 1e-9);
    EXPECT_NEAR(t.poses[f].yaw, truth[f].yaw, 0.5);
    EXPECT_NEAR(t.poses[f].pitch, truth[f].pitch, 0.5);
    EXPECT_NEAR(t.poses[f].roll, truth[f].roll, 0.5);
  }
  // Another reference frame: the angles are relative to that frame's pose.
  const PoseTrack from1 = load_marker_csv(dir + "/a.markers.csv", 1);
  expect_same_rotation(from1.poses[1], Eigen::Matrix3d::Identity());
  EXPECT_LT((euler_to_matrix(from1.poses[2]) -
             euler_to_matrix(truth[2]) * euler_to_matrix(truth[1]).transpose())
                .norm(),
            0.02);
  // load_pose_file picks the marker loader by the file name.
  EXPECT_NEAR(load_pose_file(dir + "/a.markers.csv").poses[4].yaw, 25, 0.5);
  std::filesystem::remove_all(dir);
}

TEST(Markers, FewerThanThreeMarkersIsAnError) {
  const std::string dir = test::temp_dir("markers_bad");
  const std::string path =
      write_file(dir, "b.markers.csv", "time_s,a_x,a_y,a_z,b_x,b_y,b_z\n0,1,0,0,0,1,0\n");
  try {
    load_marker_csv(path);
    FAIL() << "loaded two markers";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, path);
    EXPECT_NE(std::string(e.what()).find("at least 3 markers"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace animrt::head
