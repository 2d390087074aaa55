// Trigger-to-motion latency of `animrt serve` per trigger source (Art-Net,
// sACN, MIDI as a raw byte stream through a FIFO): the simulated animatronic
// figure serves its shipped cues in real time; a sender thread sends each
// trigger at a random phase of the cycle, and the time from the send (the
// sendto() or write()) to the first bus write of the cycle that began the
// cue (the neck bus's Sync Write) is measured. OSC: bench_serve_osc.
// Each case ends early if a fault ends the run (its summary is printed);
// the devices' silence watchdog is 1 s here, as the machine is shared.
//
//   bench_serve_triggers [triggers-per-source]

#include <arpa/inet.h>
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "animrt/runtime/artnet_receiver.hpp"
#include "animrt/runtime/midi_input.hpp"
#include "animrt/runtime/sacn_receiver.hpp"
#include "serve_bench_setup.hpp"

namespace {

using namespace animrt;
using namespace animrt::serve_bench;

// The trigger packets, written from the protocols' layouts.
std::vector<std::uint8_t> artdmx(int value) {
  std::vector<std::uint8_t> p = {'A',
                                 'r',
                                 't',
                                 '-',
                                 'N',
                                 'e',
                                 't',
                                 0,
                                 0x00,
                                 0x50,
                                 0,
                                 14,
                                 0,
                                 0,
                                 0,
                                 0,
                                 0,
                                 2,
                                 static_cast<std::uint8_t>(value),
                                 0};
  return p;
}

std::vector<std::uint8_t> e131(int value, int sequence) {
  std::vector<std::uint8_t> p(128, 0);
  auto put16 = [&p](std::size_t at, unsigned v) {
    p[at] = static_cast<std::uint8_t>(v >> 8);
    p[at + 1] = static_cast<std::uint8_t>(v);
  };
  put16(0, 0x0010);
  const char id[] = "ASC-E1.17";
  std::copy(id, id + 9, p.begin() + 4);
  put16(16, 0x7000 | (128 - 16));
  p[21] = 4;
  put16(38, 0x7000 | (128 - 38));
  p[43] = 2;
  p[108] = 100;
  p[111] = static_cast<std::uint8_t>(sequence);
  put16(113, 1);
  put16(115, 0x7000 | (128 - 115));
  p[117] = 2;
  p[118] = 0xa1;
  put16(121, 1);
  put16(123, 3);
  p[126] = static_cast<std::uint8_t>(value);
  return p;
}

enum class Source { artnet, sacn, midi };
const char* source_name(Source s) {
  return s == Source::artnet ? "Art-Net (ArtDmx)"
         : s == Source::sacn ? "sACN (E1.31)"
                             : "MIDI (FIFO)";
}

void run_case(Source source, int triggers) {
  ServedFigure served;
  CueRequests& requests = served.requests();
  const CuePlayer& player = served.player();
  // The receiver and its sender: look_left and hello in turn.
  const std::vector<int> values = served.dmx_values();
  auto select = [&requests, values](int value) {
    for (std::size_t c = 0; c < values.size(); ++c) {
      if (values[c] == value) requests.cue(static_cast<int>(c));
    }
  };
  const int look = find_cue(player.cues(), "look_left"), hello = find_cue(player.cues(), "hello");
  const int dmx[2] = {values[static_cast<std::size_t>(look)],
                      values[static_cast<std::size_t>(hello)]};
  std::unique_ptr<ArtNetReceiver> artnet;
  std::unique_ptr<SacnReceiver> sacn;
  std::unique_ptr<MidiReceiver> midi;
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const std::string fifo = "/tmp/bench_serve_triggers." + std::to_string(::getpid());
  int midi_fd = -1;
  std::function<void(int)> send;
  if (source == Source::artnet) {
    artnet = std::make_unique<ArtNetReceiver>("127.0.0.1", 0, 0, 1, select);
    to.sin_port = htons(static_cast<std::uint16_t>(artnet->port()));
    send = [&](int i) {
      const auto p = artdmx(dmx[i % 2]);
      ::sendto(fd, p.data(), p.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    };
  } else if (source == Source::sacn) {
    sacn = std::make_unique<SacnReceiver>("127.0.0.1", 0, false, 1, 1, select);
    to.sin_port = htons(static_cast<std::uint16_t>(sacn->port()));
    send = [&](int i) {
      const auto p = e131(dmx[i % 2], i);
      ::sendto(fd, p.data(), p.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    };
  } else {
    ::mkfifo(fifo.c_str(), 0600);
    midi = std::make_unique<MidiReceiver>(
        fifo, std::vector<MidiBinding>{{look, false, 60, 0}, {hello, false, 61, 0}},
        [&requests](int cue) { requests.cue(cue); });
    midi_fd = ::open(fifo.c_str(), O_WRONLY);
    send = [&](int i) {
      const std::uint8_t note[3] = {0x90, static_cast<std::uint8_t>(60 + i % 2), 100};
      if (::write(midi_fd, note, 3) != 3) std::perror("MIDI write");
    };
  }
  const CaseResult result = served.run(send, triggers);
  ::close(fd);
  if (midi_fd >= 0) ::close(midi_fd);
  if (midi) ::unlink(fifo.c_str());
  print_case(source_name(source), 20, "send", result);
}

}  // namespace

int main(int argc, char** argv) {
  const int triggers = argc > 1 ? std::atoi(argv[1]) : 200;
  for (Source s : {Source::artnet, Source::sacn, Source::midi}) run_case(s, triggers);
  return 0;
}
