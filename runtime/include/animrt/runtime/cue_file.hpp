#pragma once
// A cue file: what a figure in service plays (configs/cues/, docs/show_control.md).
//
//   idle: rest                      # the cue played at the start and between cues
//   crossfade_s: 1.0                # default crossfade into every cue
//   transition: {interpolation: learned, model: neck.model, frame_s: 0.04}
//                                   # default way into every cue (crossfade if left out)
//   artnet: {universe: 0, channel: 1}   # a DMX channel's value (a cue's dmx) asks for it
//   sacn: {universe: 1, channel: 1,     # the same over sACN (E1.31)
//          joints: {neck_pan: {channel: 2, fine: 3, range: [-45, 45]}}, hold_s: 2}
//   ltc: {fps: 25, freewheel_s: 1}      # cues with a `timecode` start chase LTC
//   cues:
//     rest:  {play: {gait: ../shows/neck_idle_gait.yaml}}
//     hello: {play: {show: ../shows/hello.yaml}, crossfade_s: 0.5,
//             timecode: "00:01:00:00", midi: {note: 60, channel: 1}}
//     look:  {play: [{pose: {neck_pan: 40}, duration_s: 2}, {show: ../shows/hello.yaml}],
//             then: rest}
//
// Every file a cue names is loaded and checked against the robot before
// anything moves; a bad cue file is one InputError naming its file, line
// and key.

#include <string>
#include <vector>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/controllers/cues/dmx_joints.hpp"
#include "animrt/runtime/ltc_chase.hpp"
#include "animrt/runtime/midi_input.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt {

// A DMX input (Art-Net or sACN): a universe, the channel whose value selects
// a cue (0: none), and the channels that drive joints.
struct DmxSection {
  bool present = false;
  int universe = 0;
  int channel = 0;
  std::vector<DmxJoint> joints;
  double hold_s = 2.0;  // a lost stream's joints hold this long, then ease back
};

struct LoadedCues {
  std::vector<Cue> cues;
  int idle = 0;
  // Art-Net: the DMX value (1-255) that asks for each cue, 0 for none, and
  // the channel (1-512, 0: no Art-Net) of the universe that carries it.
  std::vector<int> dmx_values;
  int artnet_universe = 0;
  int artnet_channel = 0;
  // What the cues' motions are warned of (a learned model never measured
  // better than interpolation), one line each, naming the cue file's line.
  std::vector<std::string> warnings;
  DmxSection artnet;  // the same, and its joints
  DmxSection sacn;
  // LTC timecode: cues bound to a start, the frame rate, how long a dropout
  // freewheels.
  bool ltc = false;
  double ltc_fps = 25.0;
  double ltc_freewheel_s = 1.0;
  std::vector<TimecodeCue> timecode_cues;
  // MIDI: the notes and programs that ask for cues.
  std::vector<MidiBinding> midi;
};

LoadedCues load_cues(const std::string& path, const RobotConfig& robot);

// The index of the cue called `name`, or -1.
int find_cue(const std::vector<Cue>& cues, const std::string& name);

}  // namespace animrt
