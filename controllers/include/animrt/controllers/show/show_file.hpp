#pragma once
// Keyframe shows: per joint, keys (time, value) with an interpolation per
// segment, a loop flag and an optional audio track with its start offset.
//
//   name: hello
//   loop: true
//   duration_s: 4          # default: the last key's time
//   audio: {file: hello.wav, offset_s: 0.25}
//   joints:
//     jaw:
//       interpolation: cubic        # default of this joint's segments
//       keys:
//         - [0.0, 0]                # [time_s, value]
//         - [0.3, 14]
//         - {t: 0.6, value: 2, interpolation: step}   # segment from this key on
//
// Interpolation of the segment that starts at a key: step (hold the key's
// value), linear, or cubic: a Hermite cubic whose slope at each key is the
// slope between its neighbours (zero at the ends of a non-looping show), so
// velocity is continuous across consecutive cubic segments. A looping show
// wraps from its last key to its first at duration_s.
//
// Values are in the unit of the robot joint they drive: degrees for a
// revolute joint, metres for a prismatic one. A track may state its unit
// (`unit: deg` or `unit: m`); a unit that contradicts the joint's type is an
// error, so a show written for another robot is not silently misread.
//
// Learned in-betweens: tracks with `interpolation: learned` are completed
// between their keys by a joint-space sequence model (animrt seq train on
// joint-angle CSVs) when the show is bound to the robot, never in the cycle:
//
//   learned: {model: gait_joints.seqnn, frame_s: 0.04}
//   joints:
//     lf_hip: {interpolation: learned, keys: [[0, 10], [0.4, -8], [0.8, 10]]}
//
// The learned tracks must be exactly the model's joints and share their key
// times, each gap a whole number of frame_s. The model's frames are then
// played as keys with cubic interpolation.

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/controllers/motion_source.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {

enum class Interpolation { step, linear, cubic, learned };

// Sample rates a show's sound track may have.
inline constexpr int kMinShowAudioRate = 4000;
inline constexpr int kMaxShowAudioRate = 384000;

struct ShowKey {
  double t = 0.0;      // s
  double value = 0.0;  // as written: degrees or metres (SI once bound to a joint)
  Interpolation interpolation = Interpolation::cubic;  // of the segment from this key
  Location where;
};

enum class ShowUnit { from_joint, deg, m };

struct ShowTrack {
  std::string joint;
  std::vector<ShowKey> keys;  // strictly increasing t, at least one
  ShowUnit unit = ShowUnit::from_joint;
  Location unit_where;
  Location where;
};

struct ShowAudio {
  std::string file;       // resolved against the show file's folder
  double offset_s = 0.0;  // show time at which the audio starts
  int sample_rate = 0;    // Hz, read from the file on load
  int channels = 0;
  double length_s = 0.0;
};

// The joint-space model that completes the learned tracks.
struct ShowLearned {
  std::string model_file;  // resolved against the show file's folder
  std::shared_ptr<const seqnet::ModelFile> model;
  double frame_s = 0.0;             // the model's frame period
  std::vector<std::string> joints;  // the model's joints, in its input order
  Location where;                   // of the `learned` section
};

struct ShowFile {
  std::string file;
  std::string name;
  bool loop = false;
  double duration_s = 0.0;
  bool has_audio = false;
  ShowAudio audio;
  std::vector<ShowTrack> tracks;
  bool has_learned = false;
  ShowLearned learned;
};

// Loads and validates a show file (InputError with file, line, column, key).
ShowFile load_show_file(const std::string& path);

// Binds a show to the robot's joints, converting its values to SI by each
// joint's type (an unknown joint, a unit that contradicts the joint's type,
// or a key outside the joint's limits, is an InputError at the key), and
// computes the learned in-betweens.
// sample() is allocation-free.
std::unique_ptr<MotionSource> make_show_source(const ShowFile& show,
                                               std::span<const JointSpec> joints);
std::unique_ptr<MotionSource> load_show_source(const std::string& path,
                                               std::span<const JointSpec> joints);

// Layers: each source in order writes the joints it drives, so a later layer
// overrides an earlier one on the joints they share (e.g. a show for eyes and
// jaw on top of a gait or head motion for the neck).
std::unique_ptr<MotionSource> make_layered_source(
    std::vector<std::unique_ptr<MotionSource>> layers);

}  // namespace animrt
