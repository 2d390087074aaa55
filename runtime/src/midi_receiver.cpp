#include <alsa/asoundlib.h>
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "animrt/core/error.hpp"
#include "animrt/runtime/midi_input.hpp"

namespace animrt {
namespace {

// How often the threads look whether they should end.
constexpr int kMidiPollMs = 100;

}  // namespace

struct MidiReceiver::Sequencer {
  snd_seq_t* seq = nullptr;
  int port = -1;
  int from_client = -1, from_port = -1;  // the source connected from, -1: any
  ~Sequencer() {
    if (seq) snd_seq_close(seq);
  }
};

MidiReceiver::MidiReceiver(const std::string& input, std::vector<MidiBinding> bindings,
                           Handler handler)
    : bindings_(std::move(bindings)), handler_(std::move(handler)) {
  constexpr std::string_view kSeq = "seq:";
  if (input.rfind(kSeq, 0) == 0) {
    seq_ = std::make_unique<Sequencer>();
    int err = snd_seq_open(&seq_->seq, "default", SND_SEQ_OPEN_INPUT, SND_SEQ_NONBLOCK);
    if (err < 0)
      throw DeviceError("MIDI: cannot open the ALSA sequencer: " + std::string(snd_strerror(err)));
    snd_seq_set_client_name(seq_->seq, "animrt");
    seq_->port = snd_seq_create_simple_port(
        seq_->seq, "cues", SND_SEQ_PORT_CAP_WRITE | SND_SEQ_PORT_CAP_SUBS_WRITE,
        SND_SEQ_PORT_TYPE_MIDI_GENERIC | SND_SEQ_PORT_TYPE_APPLICATION);
    if (seq_->port < 0) {
      throw DeviceError("MIDI: cannot create a sequencer port: " +
                        std::string(snd_strerror(seq_->port)));
    }
    const std::string from = input.substr(kSeq.size());
    if (!from.empty()) {
      snd_seq_addr_t addr{};
      err = snd_seq_parse_address(seq_->seq, &addr, from.c_str());
      if (err >= 0) err = snd_seq_connect_from(seq_->seq, seq_->port, addr.client, addr.port);
      if (err < 0) {
        throw DeviceError("MIDI: cannot connect from " + from + ": " + snd_strerror(err));
      }
      seq_->from_client = addr.client;
      seq_->from_port = addr.port;
    }
    where_ = "ALSA sequencer port " + std::to_string(snd_seq_client_id(seq_->seq)) + ':' +
             std::to_string(seq_->port);
    thread_ = std::thread([this] { read_sequencer(); });
    return;
  }
  // O_RDWR: a FIFO opened so never reads end-of-file when its writer goes.
  fd_ = ::open(input.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) fd_ = ::open(input.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw DeviceError("MIDI: cannot open " + input + ": " + std::strerror(errno));
  // A terminal (a serial MIDI interface, a pty) passes bytes as they come,
  // untranslated, only in raw mode.
  termios tio{};
  if (::isatty(fd_) && ::tcgetattr(fd_, &tio) == 0) {
    ::cfmakeraw(&tio);
    ::tcsetattr(fd_, TCSANOW, &tio);
  }
  where_ = input;
  thread_ = std::thread([this] { read_stream(); });
}

MidiReceiver::~MidiReceiver() {
  running_.store(false);
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) ::close(fd_);
}

void MidiReceiver::take(const MidiMessage& message) {
  messages_.fetch_add(1);
  const int kind = message.status & 0xf0;
  if (kind != 0xc0 && !(kind == 0x90 && message.data2 > 0)) return;
  const int cue = midi_cue(message, bindings_);
  if (cue < 0) {
    unbound_.fetch_add(1);
    return;
  }
  triggers_.fetch_add(1);
  handler_(cue);
}

void MidiReceiver::read_stream() {
  MidiParser parser;
  std::vector<std::uint8_t> buffer(4096);
  while (running_.load()) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, kMidiPollMs) <= 0) continue;
    const ssize_t n = ::read(fd_, buffer.data(), buffer.size());
    if (n <= 0) {
      if (n == 0 || (errno != EAGAIN && errno != EINTR)) ::poll(nullptr, 0, kMidiPollMs);
      continue;
    }
    for (ssize_t i = 0; i < n; ++i) {
      MidiMessage message;
      if (parser.feed(buffer[static_cast<std::size_t>(i)], message)) take(message);
    }
    malformed_.store(parser.malformed());
  }
}

// Untested on machines without /dev/snd/seq.
void MidiReceiver::read_sequencer() {
  const int count = snd_seq_poll_descriptors_count(seq_->seq, POLLIN);
  std::vector<pollfd> fds(static_cast<std::size_t>(count));
  snd_seq_poll_descriptors(seq_->seq, fds.data(), static_cast<unsigned>(count), POLLIN);
  while (running_.load()) {
    if (::poll(fds.data(), fds.size(), kMidiPollMs) <= 0) continue;
    snd_seq_event_t* ev = nullptr;
    while (snd_seq_event_input(seq_->seq, &ev) >= 0 && ev != nullptr) {
      if (seq_->from_client >= 0 &&
          (ev->source.client != seq_->from_client || ev->source.port != seq_->from_port)) {
        unknown_port_.fetch_add(1);
        continue;
      }
      if (ev->type == SND_SEQ_EVENT_NOTEON) {
        take({0x90 | (ev->data.note.channel & 0x0f), ev->data.note.note, ev->data.note.velocity});
      } else if (ev->type == SND_SEQ_EVENT_PGMCHANGE) {
        take({0xc0 | (ev->data.control.channel & 0x0f), ev->data.control.value & 0x7f, 0});
      }
      if (snd_seq_event_input_pending(seq_->seq, 0) <= 0) break;
    }
  }
}

}  // namespace animrt
