#pragma once
// MIDI triggers: a note on or a program change selects a cue. Two inputs:
// - a raw MIDI byte stream (a rawmidi device node such as /dev/snd/midiC1D0,
//   a serial MIDI interface, a FIFO or a pty), parsed here: running status,
//   real-time bytes interleaved anywhere, SysEx and system common messages
//   skipped; data bytes without a status are counted as malformed;
// - an ALSA sequencer client ("seq:" or "seq:CLIENT:PORT" to connect from a
//   source), whose port other programs (aconnect, aseqsend) connect to.
// Both read on a thread of their own (never the cycle's).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace animrt {

struct MidiBinding {
  int cue = 0;
  bool program = false;  // a program change; else a note on
  int number = 0;        // note or program, 0-127
  int channel = 0;       // 1-16, 0: any
};

struct MidiMessage {
  int status = 0;  // 0x80-0xef: the kind in the high nibble, the channel (0-15) in the low
  int data1 = 0;
  int data2 = 0;
};

class MidiParser {
 public:
  // True when `byte` completes a channel message, written to `out`.
  bool feed(std::uint8_t byte, MidiMessage& out);
  std::uint64_t malformed() const { return malformed_; }  // data bytes without a status
  std::uint64_t sysex() const { return sysex_; }          // SysEx messages skipped

 private:
  int status_ = 0;  // the running status, 0: none
  int needed_ = 0;  // data bytes the message takes
  int have_ = 0;
  int data_[2] = {0, 0};
  bool in_sysex_ = false;
  int common_left_ = 0;  // data bytes of a system common message still to skip
  std::uint64_t malformed_ = 0, sysex_ = 0;
};

// The cue a message asks for, or -1 (a note on with velocity 0 is a note off).
int midi_cue(const MidiMessage& message, const std::vector<MidiBinding>& bindings);

class MidiReceiver {
 public:
  using Handler = std::function<void(int cue)>;

  // `input`: a path to a MIDI byte stream, or "seq:" / "seq:CLIENT:PORT" for
  // the ALSA sequencer. Throws DeviceError when it cannot be opened.
  MidiReceiver(const std::string& input, std::vector<MidiBinding> bindings, Handler handler);
  ~MidiReceiver();
  MidiReceiver(const MidiReceiver&) = delete;
  MidiReceiver& operator=(const MidiReceiver&) = delete;

  std::uint64_t messages() const { return messages_.load(); }
  std::uint64_t triggers() const { return triggers_.load(); }
  std::uint64_t malformed() const { return malformed_.load(); }
  std::uint64_t unbound() const { return unbound_.load(); }            // messages no cue answers
  std::uint64_t unknown_port() const { return unknown_port_.load(); }  // sequencer only
  std::string where() const { return where_; }

 private:
  struct Sequencer;
  void read_stream();
  void read_sequencer();
  void take(const MidiMessage& message);

  std::vector<MidiBinding> bindings_;
  Handler handler_;
  int fd_ = -1;
  std::unique_ptr<Sequencer> seq_;
  std::string where_;
  std::atomic<bool> running_{true};
  std::atomic<std::uint64_t> messages_{0}, triggers_{0}, malformed_{0}, unbound_{0},
      unknown_port_{0};
  std::thread thread_;
};

}  // namespace animrt
