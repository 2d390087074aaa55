// The figure's forward kinematics over the MJCF model: bodies and geoms as
// the model has them, poses that follow the robot's joints by name.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "animrt/sim/mujoco/mujoco_figure.hpp"

namespace animrt {
namespace {

const std::string kModel = std::string(ANIMRT_SOURCE_DIR) + "/configs/models/quadruped.xml";
const std::vector<std::string> kJoints{"lf_hip",   "lf_knee",  "lf_ankle", "rf_hip",
                                       "rf_knee",  "rf_ankle", "lh_hip",   "lh_knee",
                                       "lh_ankle", "rh_hip",   "rh_knee",  "rh_ankle"};

int body_index(const FigureKinematics& figure, const std::string& name) {
  const auto& bodies = figure.bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

double distance(const BodyPose& a, const BodyPose& b) {
  return std::hypot(a.pos[0] - b.pos[0], a.pos[1] - b.pos[1], a.pos[2] - b.pos[2]);
}

TEST(Figure, BodiesAndGeomsAreTheModels) {
  sim::MujocoFigure figure(kModel, kJoints, Location{"robot.yaml", 3, 8});
  EXPECT_EQ(figure.matched_joints(), 12u);
  const int torso = body_index(figure, "torso");
  const int thigh = body_index(figure, "lf_thigh");
  ASSERT_GE(torso, 0);
  ASSERT_GE(thigh, 0);
  EXPECT_EQ(figure.bodies()[static_cast<std::size_t>(torso)].parent, -1);
  EXPECT_EQ(figure.bodies()[static_cast<std::size_t>(thigh)].parent, torso);
  const FigureGeom& body = figure.bodies()[static_cast<std::size_t>(torso)].geoms.at(0);
  EXPECT_EQ(body.type, "box");
  EXPECT_EQ(body.size, (std::vector<double>{0.15, 0.08, 0.03}));
}

TEST(Figure, PosesFollowTheJointsByName) {
  sim::MujocoFigure figure(kModel, kJoints, Location{"robot.yaml", 3, 8});
  std::vector<BodyPose> home(figure.bodies().size()), bent(figure.bodies().size());
  std::vector<double> joints(kJoints.size(), 0.0);
  figure.pose(joints, home);
  joints[1] = 0.6;  // lf_knee
  figure.pose(joints, bent);
  const auto at = [&](const std::string& name) {
    return static_cast<std::size_t>(body_index(figure, name));
  };
  EXPECT_NEAR(home[at("torso")].pos[2], 0.18, 1e-9);
  EXPECT_NEAR(distance(home[at("torso")], bent[at("torso")]), 0.0, 1e-12);
  EXPECT_NEAR(distance(home[at("lf_shin")], bent[at("lf_shin")]), 0.0, 1e-12);  // above the knee
  // The foot swings about the knee on a radius of the shin's length.
  const double moved = distance(home[at("lf_foot_link")], bent[at("lf_foot_link")]);
  EXPECT_NEAR(moved, 2.0 * 0.065 * std::sin(0.3), 1e-9);
  EXPECT_NEAR(distance(home[at("rf_foot_link")], bent[at("rf_foot_link")]), 0.0, 1e-12);
  // The knee's rotation shows in the foot link's orientation.
  EXPECT_NEAR(std::abs(bent[at("lf_foot_link")].quat[0]), std::cos(0.3), 1e-9);
}

TEST(Figure, TheHeadTurnsItsSkullAboutTheNeck) {
  const std::string model = std::string(ANIMRT_SOURCE_DIR) + "/configs/models/head.xml";
  sim::MujocoFigure figure(model, {"neck_yaw", "neck_pitch", "neck_roll", "jaw"},
                           Location{"head.yaml", 1, 1});
  EXPECT_EQ(figure.matched_joints(), 4u);
  const auto skull = static_cast<std::size_t>(body_index(figure, "skull"));
  std::vector<BodyPose> poses(figure.bodies().size());
  figure.pose(std::vector<double>{0.5, 0.0, 0.0, 0.0}, poses);
  // Yaw about z: the skull's orientation is a rotation of 0.5 rad about z.
  EXPECT_NEAR(poses[skull].quat[0], std::cos(0.25), 1e-9);
  EXPECT_NEAR(poses[skull].quat[3], std::sin(0.25), 1e-9);
}

TEST(Figure, AModelThatDoesNotLoadOrHasNoneOfTheJointsIsAnErrorAtTheKey) {
  const std::string bad = ::testing::TempDir() + "animrt_figure_bad.xml";
  std::ofstream(bad) << "<mujoco><worldbody><body><geom type='box'/></worldbody></mujoco>\n";
  try {
    sim::MujocoFigure figure(bad, kJoints, Location{"robot.yaml", 3, 8});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(
        std::string(e.what()).rfind("robot.yaml:3:8: model: " + bad + " is not a valid MJCF", 0),
        0u)
        << e.what();
  }
  try {
    sim::MujocoFigure figure(kModel, {"neck_yaw", "jaw"}, Location{"robot.yaml", 3, 8});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "robot.yaml:3:8: model: " + kModel +
                                         " has none of the robot's joints (joints are matched "
                                         "by name)");
  }
}

}  // namespace
}  // namespace animrt
