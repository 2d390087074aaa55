#include "serve_triggers.hpp"

#include <iostream>
#include <stdexcept>

namespace animrt::cli {

void add_trigger_options(CLI::App* cmd, TriggerArgs& args) {
  cmd->add_option("--ltc", args.ltc,
                  "LTC timecode input: alsa:DEVICE (capture), or a sound file read in real time");
  cmd->add_option("--midi", args.midi,
                  "MIDI input: a raw MIDI byte stream (rawmidi device, FIFO, pty), or "
                  "seq: / seq:CLIENT:PORT for the ALSA sequencer");
}

ServeTriggers::ServeTriggers(const TriggerArgs& args, const LoadedCues& loaded,
                             CueRequests& requests) {
  auto ask = [&requests](int cue) { requests.cue(cue); };
  if (!args.ltc.empty()) {
    if (loaded.timecode_cues.empty()) {
      throw std::invalid_argument("--ltc: the cue file binds no cue to a timecode start");
    }
    // A cue is asked for at the time into it that the timecode is at.
    auto at = [&requests](int cue, double at_s) { requests.cue(cue, at_s); };
    ltc_ = std::make_unique<LtcReceiver>(args.ltc, loaded.ltc_fps, loaded.ltc_freewheel_s,
                                         loaded.timecode_cues, at);
    std::cout << "ltc: reading " << args.ltc << " at " << loaded.ltc_fps << " fps\n" << std::flush;
  }
  if (!args.midi.empty()) {
    if (loaded.midi.empty())
      throw std::invalid_argument("--midi: the cue file binds no cue to MIDI");
    midi_ = std::make_unique<MidiReceiver>(args.midi, loaded.midi, ask);
    std::cout << "midi: reading " << midi_->where() << '\n' << std::flush;
  }
}

void ServeTriggers::report(std::ostream& out) const {
  if (ltc_) {
    out << "ltc: " << ltc_->frames() << " frames, " << ltc_->jumps() << " jumps (re-synced), "
        << ltc_->dropouts() << " dropouts (freewheeled), " << ltc_->losses() << " lost, "
        << ltc_->malformed() << " malformed, " << ltc_->cues_asked() << " cues asked\n";
  }
  if (midi_) {
    out << "midi: " << midi_->messages() << " messages, " << midi_->triggers() << " triggers, "
        << midi_->unbound() << " unbound, " << midi_->malformed() << " malformed, "
        << midi_->unknown_port() << " from unknown ports\n";
  }
}

}  // namespace animrt::cli
