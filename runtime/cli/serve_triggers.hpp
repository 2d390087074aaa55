#pragma once
// `animrt serve`'s timecode and MIDI triggers: LTC from an audio input chased
// by the cues bound to timecode starts, and MIDI notes and program changes
// (docs/show_control.md).

#include <CLI/CLI.hpp>
#include <memory>
#include <ostream>
#include <string>

#include "animrt/controllers/cues/cue_requests.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/ltc_receiver.hpp"
#include "animrt/runtime/midi_input.hpp"

namespace animrt::cli {

struct TriggerArgs {
  std::string ltc;   // a sound file played at real time, or alsa:DEVICE; empty: none
  std::string midi;  // a MIDI byte stream's path, or seq:[CLIENT:PORT]; empty: none
};

void add_trigger_options(CLI::App* cmd, TriggerArgs& args);

class ServeTriggers {
 public:
  // Opens the inputs asked for; a cue file without timecode cues or MIDI
  // bindings for an input given is a usage error (thrown as std::invalid_argument).
  ServeTriggers(const TriggerArgs& args, const LoadedCues& loaded, CueRequests& requests);
  void report(std::ostream& out) const;
  // The motion has started (from the cycle: only sets a flag): a timecode
  // file starts playing.
  void begin() {
    if (ltc_) ltc_->begin();
  }

 private:
  std::unique_ptr<LtcReceiver> ltc_;
  std::unique_ptr<MidiReceiver> midi_;
};

}  // namespace animrt::cli
