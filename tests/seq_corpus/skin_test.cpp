// The skin: marching tetrahedra give closed, consistently oriented surfaces;
// the model's skin is one genus-0 closed manifold with about the requested
// vertex count; skinning at the bind pose gives the rest mesh back, and
// walked frames carry each leg's vertices with their bodies.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "animrt/controllers/gait/froude.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/learn/seq_corpus/body_field.hpp"
#include "animrt/learn/seq_corpus/generator.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"
#include "support/files.hpp"

namespace {

using animrt::kSourceRoot;

using namespace animrt::sim;
using namespace animrt::learn::seq_corpus;

TEST(MarchingTetrahedra, SphereIsClosedOrientedAndHasItsVolume) {
  const double r = 0.5, step = 0.05;
  const auto sphere = [r](const Eigen::Vector3d& p) { return p.norm() - r; };
  const Eigen::AlignedBox3d box(Eigen::Vector3d::Constant(-0.63), Eigen::Vector3d::Constant(0.61));
  const TriangleMesh mesh = marching_tetrahedra(sphere, box, step);
  const MeshReport rep = check_mesh(mesh, 1e-6 * step * step);
  EXPECT_TRUE(rep.closed_manifold());
  EXPECT_EQ(rep.components, 1);
  EXPECT_EQ(rep.degenerate, 0);
  EXPECT_EQ(rep.euler(), 2);
  const double volume = 4.0 / 3.0 * M_PI * r * r * r;
  EXPECT_NEAR(enclosed_volume(mesh), volume, 0.03 * volume);
  for (Eigen::Index v = 0; v < mesh.vertices.cols(); ++v)
    EXPECT_NEAR(mesh.vertices.col(v).norm(), r, 0.2 * step);
}

TEST(MarchingTetrahedra, TwoBallsAreTwoComponentsAndTheLargerIsKept) {
  const auto balls = [](const Eigen::Vector3d& p) {
    return std::min((p - Eigen::Vector3d(-0.5, 0, 0)).norm() - 0.3,
                    (p - Eigen::Vector3d(0.5, 0, 0)).norm() - 0.2);
  };
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-1, -0.5, -0.5), Eigen::Vector3d(1, 0.5, 0.5));
  const TriangleMesh both = marching_tetrahedra(balls, box, 0.05);
  EXPECT_EQ(check_mesh(both, 0.0).components, 2);
  const TriangleMesh big = largest_component(both);
  const MeshReport rep = check_mesh(big, 0.0);
  EXPECT_EQ(rep.components, 1);
  EXPECT_TRUE(rep.closed_manifold());
  EXPECT_LT(big.vertices.row(0).maxCoeff(), -0.1);  // the ball at x = -0.5
}

TEST(MeshCheck, FindsHolesAndFlippedTriangles) {
  TriangleMesh tet;
  tet.vertices.resize(3, 4);
  tet.vertices << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  MeshReport rep = check_mesh(tet, 1e-9);
  EXPECT_TRUE(rep.closed_manifold());
  EXPECT_EQ(rep.euler(), 2);
  EXPECT_NEAR(enclosed_volume(tet), 1.0 / 6.0, 1e-12);
  TriangleMesh flipped = tet;
  std::swap(flipped.triangles[1][1], flipped.triangles[1][2]);
  EXPECT_GT(check_mesh(flipped, 1e-9).misoriented_edges, 0);
  TriangleMesh open = tet;
  open.triangles.pop_back();
  EXPECT_EQ(check_mesh(open, 1e-9).boundary_edges, 3);
  TriangleMesh flat = tet;
  flat.vertices.col(3) = Eigen::Vector3d(0.5, 0, 0);  // on the edge 0-1
  flat.triangles = {{0, 1, 3}};
  EXPECT_EQ(check_mesh(flat, 1e-9).degenerate, 1);
}

struct ModelSkin {
  MujocoModel model;
  Skin skin;
};

const ModelSkin& quadruped_skin() {
  static const ModelSkin s = [] {
    ModelSkin out{load_mujoco_model(kSourceRoot + "/configs/models/quadruped.xml"), {}};
    out.skin = bind_pose_skin(out.model, 400);
    return out;
  }();
  return s;
}

const ModelSkin& horse_skin() {
  static const ModelSkin s = [] {
    ModelSkin out{load_mujoco_model(kSourceRoot + "/configs/models/horse.xml"), {}};
    out.skin = bind_pose_skin(out.model, 1500);
    return out;
  }();
  return s;
}

void expect_good_skin(const ModelSkin& s, int requested) {
  const Skin& skin = s.skin;
  const double h = skin.grid_step_m;
  const MeshReport rep = check_mesh(skin.rest, 1e-4 * h * h);
  EXPECT_EQ(rep.components, 1);
  EXPECT_TRUE(rep.closed_manifold())
      << rep.boundary_edges << " boundary, " << rep.nonmanifold_edges << " non-manifold edges, "
      << rep.misoriented_edges << " misoriented, " << rep.nonmanifold_vertices
      << " non-manifold vertices";
  EXPECT_EQ(rep.euler(), 2);  // genus 0
  EXPECT_EQ(rep.degenerate, 0) << "smallest area " << rep.min_area / (h * h) << " h^2";
  EXPECT_GT(enclosed_volume(skin.rest), 0.0);  // faces point out
  EXPECT_NEAR(rep.vertices, requested, 0.05 * requested);
  // Every body with geoms is in the skin: some vertices move mainly with it.
  const mjModel* m = s.model.model.get();
  std::vector<int> dominant(static_cast<std::size_t>(m->nbody), 0);
  for (int v = 0; v < rep.vertices; ++v)
    ++dominant[static_cast<std::size_t>(dominant_body(skin, v))];
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body_geomnum[b] == 0) continue;
    EXPECT_GT(dominant[static_cast<std::size_t>(b)], 0) << mj_id2name(m, mjOBJ_BODY, b);
  }
  for (const auto& w : skin.weights) EXPECT_NEAR(w[0] + w[1] + w[2], 1.0, 1e-12);
}

TEST(Skin, QuadrupedIsOneClosedGenusZeroManifold) { expect_good_skin(quadruped_skin(), 400); }
TEST(Skin, HorseIsOneClosedGenusZeroManifold) { expect_good_skin(horse_skin(), 1500); }

TEST(Skin, VertexCountFollowsTheRequest) {
  const MujocoModel& model = quadruped_skin().model;
  const Skin small = bind_pose_skin(model, 200);
  const Skin large = bind_pose_skin(model, 2000);
  EXPECT_NEAR(small.rest.vertices.cols(), 200, 20);
  EXPECT_NEAR(large.rest.vertices.cols(), 2000, 200);
  const auto mean_edge = [](const TriangleMesh& mesh) {
    double sum = 0.0;
    for (const auto& t : mesh.triangles)
      for (int c = 0; c < 3; ++c)
        sum += (mesh.vertices.col(t[static_cast<std::size_t>(c)]) -
                mesh.vertices.col(t[static_cast<std::size_t>((c + 1) % 3)]))
                   .norm();
    return sum / (3.0 * static_cast<double>(mesh.triangles.size()));
  };
  EXPECT_LT(mean_edge(large.rest), 0.5 * mean_edge(small.rest));
  // Both enclose about the same body.
  EXPECT_NEAR(enclosed_volume(small.rest), enclosed_volume(large.rest),
              0.15 * enclosed_volume(large.rest));
}

TEST(Skin, BindPoseGivesTheRestMeshBack) {
  for (const ModelSkin* s : {&quadruped_skin(), &horse_skin()}) {
    MujocoData d = make_mujoco_data(s->model);
    const std::vector<double> zero(s->model.actuated_joints.size(), 0.0);
    place_standing(s->model, d.get(), zero.data());
    animrt::seqnet::Positions posed;
    pose_skin(s->skin, d.get(), posed);
    ASSERT_EQ(posed.cols(), s->skin.rest.vertices.cols());
    EXPECT_LE((posed - s->skin.rest.vertices).cwiseAbs().maxCoeff(), 1e-12);
  }
}

// Posed vertices bound mostly to one body follow that body rigidly.
TEST(Skin, WalkedFramesCarryFootVerticesWithTheirFeet) {
  const ModelSkin& s = quadruped_skin();
  const mjModel* m = s.model.model.get();
  const WalkConfig config{kSourceRoot + "/configs/gaits/walk.yaml", 0.054, 3, 0.0};
  WalkOptions options;
  options.frames = 12;
  const WalkRecord walk = walk_sequence(s.model, s.skin, config, options);
  ASSERT_EQ(walk.mesh.frame_count(), 12);
  ASSERT_FALSE(walk.fell);
  EXPECT_GT(walk.torso.back()[0] - walk.torso.front()[0], 0.005);  // it walked forward
  // The bodies as they were at each frame, from the recorded state.
  MujocoData d = make_mujoco_data(s.model);
  const int n = static_cast<int>(s.skin.rest.vertices.cols());
  int checked = 0;
  double moved = 0.0;
  for (int f = 0; f < walk.mesh.frame_count(); f += 5) {
    std::copy(walk.qpos[static_cast<std::size_t>(f)].begin(),
              walk.qpos[static_cast<std::size_t>(f)].end(), d->qpos);
    mj_kinematics(m, d.get());
    for (int v = 0; v < n; ++v) {
      const int b = dominant_body(s.skin, v);
      const std::string name = mj_id2name(m, mjOBJ_BODY, b);
      if (name.find("foot_link") == std::string::npos) continue;
      if (*std::max_element(s.skin.weights[static_cast<std::size_t>(v)].begin(),
                            s.skin.weights[static_cast<std::size_t>(v)].end()) < 0.9)
        continue;
      const Eigen::Matrix3d r_now =
          Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->xmat + 9 * b);
      const Eigen::Vector3d p_now(d->xpos + 3 * b);
      const auto bb = static_cast<std::size_t>(b);
      const Eigen::Vector3d rigid = r_now * s.skin.bind_rot[bb].transpose() *
                                        (s.skin.rest.vertices.col(v) - s.skin.bind_pos[bb]) +
                                    p_now;
      const Eigen::Vector3d posed = walk.mesh.frames[static_cast<std::size_t>(f)].col(v);
      EXPECT_LE((posed - rigid).norm(), 0.004) << name << " vertex " << v << " frame " << f;
      moved = std::max(moved, (posed - s.skin.rest.vertices.col(v)).norm());
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
  EXPECT_GT(moved, 0.02);  // far more than the tolerance: the feet did move
}

TEST(Walk, SameSeedSameFramesOtherSeedOtherFrames) {
  const ModelSkin& s = quadruped_skin();
  WalkOptions options;
  options.frames = 6;
  const WalkConfig a{kSourceRoot + "/configs/gaits/quadruped_evolved.yaml", 0.06, 7, 0.0};
  WalkConfig b = a;
  b.seed = 8;
  const WalkRecord a1 = walk_sequence(s.model, s.skin, a, options);
  const WalkRecord a2 = walk_sequence(s.model, s.skin, a, options);
  const WalkRecord b1 = walk_sequence(s.model, s.skin, b, options);
  ASSERT_EQ(a1.mesh.frame_count(), 6);
  ASSERT_EQ(a2.mesh.frame_count(), 6);
  ASSERT_EQ(b1.mesh.frame_count(), 6);
  double diff_seed = 0.0;
  for (int f = 0; f < 6; ++f) {
    const auto fi = static_cast<std::size_t>(f);
    EXPECT_EQ(a1.mesh.frames[fi], a2.mesh.frames[fi]) << "frame " << f;
    EXPECT_EQ(a1.joints[fi], a2.joints[fi]);
    diff_seed =
        std::max(diff_seed, (a1.mesh.frames[fi] - b1.mesh.frames[fi]).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(diff_seed, 1e-3);
  EXPECT_NE(a1.timing.start_phase, b1.timing.start_phase);
  EXPECT_NEAR(a1.timing.froude, 0.06, 0.06 * 0.021);
  EXPECT_EQ(a1.time_s[1] - a1.time_s[0], 1.0 / options.fps);
}

// Wraps a gait and keeps the steering commands it is given.
class SteerRecorder final : public animrt::MotionSource {
 public:
  SteerRecorder(std::unique_ptr<animrt::MotionSource> inner,
                std::vector<animrt::MotionCommand>* seen)
      : inner_(std::move(inner)), seen_(seen) {}
  std::span<const int> driven_joints() const override { return inner_->driven_joints(); }
  void sample(double t, std::span<double> targets) const override { inner_->sample(t, targets); }
  void steer(const animrt::MotionCommand& c) override { seen_->push_back(c); }

 private:
  std::unique_ptr<animrt::MotionSource> inner_;
  std::vector<animrt::MotionCommand>* seen_;
};

TEST(Walk, TheTurnRateGoesToTheGaitThroughSteer) {
  const ModelSkin& s = quadruped_skin();
  std::vector<animrt::MotionCommand> seen;
  WalkOptions options;
  options.frames = 2;
  options.make_source = [&seen](const animrt::GaitFile& g, std::span<const animrt::JointSpec> j) {
    return std::make_unique<SteerRecorder>(animrt::make_gait_source(g, j), &seen);
  };
  const WalkConfig c{kSourceRoot + "/configs/gaits/walk.yaml", 0.05, 1, -0.25};
  const WalkRecord walk = walk_sequence(s.model, s.skin, c, options);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].turn_rad_s, -0.25);
  EXPECT_NEAR(seen[0].speed_m_s, animrt::froude_velocity(walk.timing.froude, 0.18), 1e-12);
}

// walk.yaml walks Froude 0.053 to 0.056 when steered, and a command below
// that stops a steered gait; the corpus asks it for 0.04 (and the quadruped
// stood still in those clips): its walks below the range must walk.
TEST(Walk, AFroudeNumberBelowTheGaitsSteeringRangeStillWalks) {
  const ModelSkin& s = quadruped_skin();
  WalkOptions options;
  options.frames = 101;  // 4 s
  for (double fr : {0.03, 0.04}) {
    const WalkConfig c{kSourceRoot + "/configs/gaits/walk.yaml", fr, 1, 0.0};
    const WalkRecord walk = walk_sequence(s.model, s.skin, c, options);
    ASSERT_FALSE(walk.fell) << fr;
    const double commanded = animrt::froude_velocity(walk.timing.froude, 0.18);
    EXPECT_GT(walk.speed_m_s, 0.5 * commanded) << "Froude " << fr;
  }
}

TEST(Walk, RejectsAFrameRateOffThePhysicsSteps) {
  const ModelSkin& s = quadruped_skin();
  WalkOptions options;
  options.fps = 30.0;  // 16.67 steps of 2 ms
  const WalkConfig c{kSourceRoot + "/configs/gaits/walk.yaml", 0.054, 1, 0.0};
  EXPECT_THROW(walk_sequence(s.model, s.skin, c, options), std::invalid_argument);
}

TEST(Schedule, EveryGaitFroudeTurnAndSeed) {
  CorpusOptions o = model_preset("quadruped", kSourceRoot + "/configs");
  o.turns = {0.0, 0.3};
  o.seeds = 2;
  o.first_seed = 5;
  const auto schedule = corpus_schedule(o);
  ASSERT_EQ(schedule.size(), 2u * 3u * 2u * 2u);
  EXPECT_EQ(schedule[1].seed, 6u);
  EXPECT_EQ(schedule[2].turn_rad_s, 0.3);
  std::set<std::string> names;
  for (const auto& c : schedule) names.insert(sequence_name(c));
  EXPECT_EQ(names.size(), schedule.size());
  EXPECT_THROW(model_preset("cat", "configs"), std::invalid_argument);
}

}  // namespace

namespace {

// The generated corpus goes through the deformation features and back like
// the real clips: every walked frame within 0.2 % mean and 1 % max of the
// bounding-box diagonal, up to a translation.
TEST(Skin, WalkedFramesComeBackFromTheirFeatures) {
  const ModelSkin& s = quadruped_skin();
  const WalkConfig config{kSourceRoot + "/configs/gaits/walk.yaml", 0.054, 5, 0.0};
  WalkOptions options;
  options.frames = 10;
  const WalkRecord walk = walk_sequence(s.model, s.skin, config, options);
  ASSERT_EQ(walk.mesh.frame_count(), 10);
  const animrt::seqnet::SequenceFeatures features = animrt::seqnet::compute_features(walk.mesh);
  const animrt::seqnet::Reconstructor solver(features.rest, features.triangles);
  double worst_mean = 0.0;
  for (int f = 0; f < walk.mesh.frame_count(); ++f) {
    const animrt::seqnet::Positions got = solver.solve(features.raw(f));
    const animrt::seqnet::FrameError e = animrt::seqnet::error_up_to_translation(
        walk.mesh.frames[static_cast<std::size_t>(f)], got, solver.neighbourhood());
    EXPECT_LT(e.mean, 0.002) << "frame " << f;
    EXPECT_LT(e.max, 0.01) << "frame " << f;
    worst_mean = std::max(worst_mean, e.mean);
  }
  // The walk moved the skin: the round trip is not of a still mesh.
  const animrt::seqnet::FrameError moved = animrt::seqnet::error_up_to_translation(
      walk.mesh.frames.front(), walk.mesh.frames.back(), solver.neighbourhood());
  EXPECT_GT(moved.max, 0.01);
  EXPECT_LT(worst_mean, moved.mean);
}

}  // namespace
