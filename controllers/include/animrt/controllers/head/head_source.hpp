#pragma once
// The head as a MotionSource: speech (a bundled WAV played as the run's
// clock passes, or live ALSA capture) goes through the streaming synthesizer in blocks; the
// Euler angles drive the neck joints (axis mapping, signs, scale, offsets,
// clamped to the joint limits) and the speech energy opens the jaw.
//
// Timing. The jaw and the head poses take two paths: the jaw follows the
// speech energy (RMS about the mean over jaw.window_s, from the samples
// themselves: a DC offset does not open it), the neck follows the slower
// HMM pipeline of the streaming synthesizer.
//   - A sound file (`audio`) is known ahead: the worker feeds the
//     synthesizer its worst-case latency ahead of the run's clock, so motion
//     time t shows the head pose of audio time t, and the jaw opens with the
//     energy of the samples up to t: it never leads the sound and lags it by
//     less than one cycle. The file's sound (ALSA playback) is not delayed.
//   - Live sound (`capture`, or `live: true` for a file played as if it were
//     captured) cannot be looked ahead: the jaw shows the energy up to the
//     newest block that has arrived, the head the newest final pose (at
//     most the synthesizer's worst case plus one block behind the sound),
//     whatever the motion's time t: a cue that restarts it joins the sound
//     as it is.
// A file's blocks "arrive" on the run's clock (MotionSource::start): in a
// lockstep run on the simulated time, and sample(t) waits for the blocks due
// by then, so the head moves the same however fast the machine runs.
//
// Robot file (motion section), see docs/head.md:
//   motion:
//     type: head
//     model: ../head/model.txt
//     audio: ../head/utterance.wav   # or  capture: default  (ALSA, live; or pipe:PATH)
//     live: false                    # true: play the file as live input (no look-ahead)
//     playback: realtime             # or precomputed (same stream, run at load)
//     repeat: true
//     pause_s: 1.0
//     audio_device: none             # ALSA playback: none, auto or a device name
//     decoder_lag_s: 0.2
//     smoothing: squad               # or causal: live head within ~0.14 s (docs/head.md)
//     axes:
//       yaw:   {joint: neck_yaw, sign: 1, scale: 1.0, offset_deg: 0}
//       pitch: {joint: neck_pitch, sign: 1}
//       roll:  {joint: neck_roll, sign: 1}
//     jaw: {joint: jaw, closed_deg: 0, open_deg: 20, energy_floor: 0.01, energy_full: 0.12,
//           window_s: 0.02}

#include <memory>
#include <optional>
#include <span>
#include <string>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt::head {

struct HeadAxisMap {
  std::string joint;  // empty: axis not driven
  double sign = 1.0, scale = 1.0, offset_deg = 0.0;
  Location where;   // the `joint` key in the robot or cue file
  std::string key;  // its path there
};

struct HeadJawMap {
  std::string joint;  // empty: no jaw
  double closed_deg = 0.0, open_deg = 20.0;
  double energy_floor = 0.01, energy_full = 0.12;  // RMS energy: closed below, fully open above
  double window_s = 0.02;                          // the RMS window, ending at the newest sample
  Location where;                                  // the `joint` key in the robot or cue file
  std::string key;                                 // its path there
};

struct HeadMotionConfig {
  std::string model;     // resolved path
  std::string audio;     // resolved path, or empty with capture
  Location audio_where;  // where the robot or cue file names `audio`, and its key
  std::string audio_key;
  std::string capture;  // live input (audio_input.hpp: ALSA device or pipe:PATH), or empty
  bool live = false;    // play `audio` as if captured live: no look-ahead
  bool precomputed = false;
  bool repeat = true;
  double pause_s = 1.0;
  std::string audio_device = "none";
  double decoder_lag_s = 0.2;
  double max_gap_s = 0.15;
  bool causal = false;  // smoothing: causal (no SQUAD look-ahead), for live sound
  double block_s = 0.01;
  std::optional<double> noise_deg;
  HeadAxisMap yaw, pitch, roll;
  HeadJawMap jaw;
  Location where;
};

// Reads the motion node of a robot file (type: head); paths are resolved
// against the robot file's folder and must exist. InputError on any problem.
HeadMotionConfig parse_head_motion(const YamlNode& motion, const std::string& robot_path);

// The motion's sound file. A problem with it is an InputError at the line
// and key of the robot or cue file that names it, with the problem's text.
Audio load_head_audio(const HeadMotionConfig& config);

// Loads the model and audio (InputError naming the file on any problem) and
// binds the axes to the robot's joints by name.
std::unique_ptr<MotionSource> make_head_source(const HeadMotionConfig& config,
                                               std::span<const JointSpec> joints);

}  // namespace animrt::head
