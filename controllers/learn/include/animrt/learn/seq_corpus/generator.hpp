#pragma once
// A generated corpus of mesh animation sequences with known motion, for the
// mesh-sequence learner (controllers/seqnet). It generates data and knows
// nothing of the learner: a MuJoCo model walks a gait (at a Froude number,
// with a seed's small noise on its timing, told a turn rate), and a skin
// around the model's bodies (skin.hpp) is posed at every frame. Beside each
// mesh sequence go the joint angles and the torso's pose that made it.
//
// Output folder (docs/seqnet.md, "Generated corpus"):
//   index.yaml          every sequence: gait, Froude number, seed, turn,
//                       frames, vertices, fell, achieved speed and turn
//   rest.obj            the skin at its bind pose
//   skin_weights.csv    vertex, body, weight
//   NAME/frame_0000.obj ... one OBJ per frame, world frame, metres
//   NAME.csv            time_s, one column per actuated joint (rad),
//                       torso_x, torso_y, torso_z (m), torso_yaw (rad)

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/controllers/seqnet/mesh_sequence.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/learn/seq_corpus/skin.hpp"
#include "animrt/sim/mujoco/mujoco_model.hpp"

namespace animrt::learn::seq_corpus {

// The figures walk on the simulator's MuJoCo models.
using sim::load_mujoco_model;
using sim::make_mujoco_data;
using sim::MujocoData;
using sim::MujocoModel;

// One sequence of the schedule.
struct WalkConfig {
  std::string gait_file;
  double froude = 0.0;     // nominal Fr = v / sqrt(g h)
  std::uint64_t seed = 1;  // the timing noise
  // Given to the gait with its speed through MotionSource::steer before the
  // walk starts. Gaits that cannot be steered ignore it and walk straight;
  // the record says what the figure achieved.
  double turn_rad_s = 0.0;
};

// Binds a gait to the model's joints as a motion source (default:
// make_gait_source).
using GaitSourceFactory =
    std::function<std::unique_ptr<MotionSource>(const GaitFile&, std::span<const JointSpec>)>;

struct WalkOptions {
  int frames = 64;
  double fps = 25.0;           // a whole number of physics steps per frame
  double warmup_cycles = 1.0;  // strides walked (the first blends in from standing) before frame 0
  GaitSourceFactory make_source;  // empty: make_gait_source
};

// The seed's noise: a few per cent on the Froude number, where in its stride
// the gait starts, how long the figure settles standing first.
struct WalkTiming {
  double froude = 0.0;       // actual
  double start_phase = 0.0;  // stride cycles, 0..1
  double settle_s = 0.0;
};
WalkTiming draw_timing(const WalkConfig& config);

struct WalkRecord {
  WalkConfig config;
  WalkTiming timing;
  seqnet::MeshSequence mesh;
  std::vector<double> time_s;                // per frame, from frame 0
  std::vector<std::vector<double>> joints;   // per frame, one angle per actuator (rad)
  std::vector<std::array<double, 4>> torso;  // per frame: x, y, z, yaw (unwrapped)
  std::vector<std::vector<double>> qpos;     // per frame, the model's whole qpos
  bool fell = false;                         // the walk stopped at a fall
  double speed_m_s = 0.0;                    // achieved over the frames, on the ground plane
  double turn_rad_s = 0.0;                   // achieved yaw rate
};

// Physics steps between frames; throws std::invalid_argument when the frame
// rate is not a whole number of them (or frames < 1).
long physics_steps_per_frame(const MujocoModel& model, const WalkOptions& options);

// The skin of `model` at its bind pose: every joint at 0 (within its
// range), standing with the lowest foot on the floor.
Skin bind_pose_skin(const MujocoModel& model, int target_vertices);

// Walks one configuration and skins every frame. Deterministic: the same
// arguments give the same numbers. Throws InputError for a gait that does
// not fit the model, std::invalid_argument for options it cannot honour.
WalkRecord walk_sequence(const MujocoModel& model, const Skin& skin, const WalkConfig& config,
                         const WalkOptions& options);

struct CorpusOptions {
  std::string model_file;
  std::vector<std::string> gaits;
  std::vector<double> froude;
  std::vector<double> turns{0.0};
  int seeds = 3;  // seeds first_seed, first_seed + 1, ...
  std::uint64_t first_seed = 1;
  int vertices = 1000;
  WalkOptions walk;
  std::function<void(const std::string&)> log;
};

// Every gait x Froude number x turn x seed, in that nesting.
std::vector<WalkConfig> corpus_schedule(const CorpusOptions& options);

// The corpus a named model gets by default: its model file and gaits under
// `configs_dir`, and Froude numbers around its gaits' own. Names: horse,
// quadruped. Throws std::invalid_argument for another name.
CorpusOptions model_preset(const std::string& name, const std::string& configs_dir);

// Folder and CSV name of a sequence.
std::string sequence_name(const WalkConfig& config);

struct CorpusSummary {
  int sequences = 0;
  int fell = 0;
  long frames = 0;
  int vertices = 0;
  int triangles = 0;
};

// Writes the corpus into `dir` (created if needed).
CorpusSummary generate_corpus(const std::string& dir, const CorpusOptions& options);

void write_joints_csv(const std::string& path, const MujocoModel& model, const WalkRecord& walk);

}  // namespace animrt::learn::seq_corpus
