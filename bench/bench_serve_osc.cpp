// Trigger-to-motion latency of `animrt serve` over OSC: the simulated
// animatronic figure serves its shipped cues in real time; a sender thread
// sends /cue/NAME over UDP on loopback at random phases of the cycle, and
// the time from sendto() to the first bus write of the cycle that began
// the cue (the neck bus's Sync Write) is measured. Run as the machine is and
// with a thread spinning at ordinary priority (added load).
// Each case ends early if a fault ends the run (its summary is printed);
// the devices' silence watchdog is 1 s here, as the machine is shared.
//
//   bench_serve_osc [triggers-per-case]

#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "animrt/runtime/osc_receiver.hpp"
#include "serve_bench_setup.hpp"

namespace {

using namespace animrt;
using namespace animrt::serve_bench;

std::vector<std::uint8_t> osc_cue(const std::string& name) {
  std::vector<std::uint8_t> out;
  for (const std::string& s : {"/cue/" + name, std::string(",")}) {
    out.insert(out.end(), s.begin(), s.end());
    do out.push_back(0);
    while (out.size() % 4 != 0);
  }
  return out;
}

void run_case(bool load, int triggers) {
  ServedFigure served;
  // The cue names are the receiver's own: its thread outlives the player.
  std::vector<std::string> cues;
  for (const Cue& cue : served.player().cues()) cues.push_back(cue.name);
  OscReceiver osc("127.0.0.1", 0, [&requests = served.requests(), cues](const OscMessage& m) {
    const auto found = std::find(cues.begin(), cues.end(), m.address.substr(5));
    if (found != cues.end()) requests.cue(static_cast<int>(found - cues.begin()));
    return found != cues.end();
  });
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(osc.port()));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const std::vector<std::uint8_t> packets[2] = {osc_cue("look_left"), osc_cue("hello")};
  const CaseResult result = served.run(
      [&](int i) {
        const std::vector<std::uint8_t>& p = packets[i % 2];
        ::sendto(fd, p.data(), p.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
      },
      triggers, load);
  ::close(fd);
  print_case(load ? "added load (a spinning thread)" : "no added load", 34, "OSC send", result);
}

}  // namespace

int main(int argc, char** argv) {
  const int triggers = argc > 1 ? std::atoi(argv[1]) : 200;
  run_case(false, triggers);
  run_case(true, triggers);
  return 0;
}
