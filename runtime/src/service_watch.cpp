#include "animrt/runtime/service_watch.hpp"

namespace animrt {

std::vector<std::string> ServiceWatch::look(const RunHeartbeat& heartbeat) {
  std::vector<std::string> out;
  const std::uint64_t cycles = heartbeat.cycles();
  const RunHeartbeat::Stage stage = heartbeat.stage();
  const bool finishing =
      stage == RunHeartbeat::Stage::stop_ramp || stage == RunHeartbeat::Stage::ended;
  // Ready once the motion has played: a run stopped during its start ramp
  // never was.
  if (!ready_ && heartbeat.moved()) {
    ready_ = true;
    out.emplace_back("READY=1");
  }
  // Once the actuators were released the process only writes its summary
  // and exits; it is fed until then, however long that takes under load.
  const bool alive = cycles != last_cycles_ && stage != RunHeartbeat::Stage::ended;
  if (watchdog_ && (alive || heartbeat.safe())) {
    out.emplace_back("WATCHDOG=1");
  }
  last_cycles_ = cycles;
  if (!stopping_ && finishing) {
    stopping_ = true;
    out.emplace_back("STOPPING=1");
  }
  return out;
}

}  // namespace animrt
