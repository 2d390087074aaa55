#include "animrt/runtime/run_summary.hpp"

#include <fmt/format.h>

#include <cmath>

#include "animrt/core/joint.hpp"

namespace animrt {
namespace {

std::string ms(double seconds) { return fmt::format("{:.3f} ms", seconds * 1e3); }

nlohmann::json timing_json(const TimingSummary& t) {
  return {{"count", t.count}, {"p50_s", t.p50_s}, {"p99_s", t.p99_s}, {"max_s", t.max_s}};
}

// "3.1 A", or "n/a" for a value never read.
std::string value_or_na(double v, const char* format_unit) {
  return std::isnan(v) ? std::string("n/a") : fmt::format(fmt::runtime(format_unit), v);
}

std::string health_text(const HealthStats& h) {
  if (h.readings == 0) return {};
  return fmt::format(
      "\n      health: temperature {}..{}, peak current {}, min voltage {}{}, warnings {}",
      value_or_na(h.min_temperature_c, "{:.0f} C"), value_or_na(h.max_temperature_c, "{:.0f} C"),
      value_or_na(h.peak_current_a, "{:.2f} A"), value_or_na(h.min_voltage_v, "{:.1f} V"),
      std::isnan(h.peak_torque_nm) ? std::string()
                                   : fmt::format(", peak torque {:.2f} Nm", h.peak_torque_nm),
      h.warnings);
}

nlohmann::json number_or_null(double v) {
  return std::isnan(v) ? nlohmann::json() : nlohmann::json(v);
}

std::string device_line(const DeviceReport& d) {
  const DeviceStatus& st = d.status;
  return fmt::format(
             "  {} id {:<3} {:<14} {:<15} transactions {} timeouts {} crc {} protocol {} hardware "
             "{}{}",
             d.bus, st.device_id, d.joint, st.faulted ? "FAULTED" : to_string(st.health),
             st.transactions, st.timeouts, st.crc_errors, st.protocol_errors, st.hardware_errors,
             st.hardware_error_status
                 ? fmt::format(" (hardware error status 0x{:02x})", st.hardware_error_status)
                 : std::string()) +
         (st.exceptions
              ? fmt::format(" exceptions {} (last code {})", st.exceptions, st.last_error_byte)
              : std::string()) +
         (st.open_loop ? std::string(" [open loop: position is the controller's ramped output]")
                       : std::string()) +
         health_text(d.health);
}

void add_physics(std::string& out, const PhysicsReport& p) {
  auto line = [&out](const std::string& text) { out += text + '\n'; };
  line(fmt::format(
      "physics: {} ({:g} ms steps), {:.2f} s simulated: forward {:.3f} m, sideways {:.3f} m, "
      "falls {}{}",
      p.model, p.timestep_s * 1e3, p.simulated_s, p.forward_m, p.sideways_m, p.falls,
      p.falls > 0 ? fmt::format(" (first at {:.2f} s)", p.first_fall_s) : std::string()));
  line(fmt::format("physics, motion only: forward {:.3f} m in {:.2f} s, average speed {:.3f} m/s",
                   p.motion_forward_m, p.motion_s, p.average_speed_m_s));
  if (p.duty_factor >= 0.0) {
    line(fmt::format("physics, motion only: stride {:.3f} m, duty factor {:.3f}", p.stride_length_m,
                     p.duty_factor));
  }
  if (p.lockstep_waits_timed_out > 0) {
    line(
        fmt::format("physics: a bus kept the others waiting {} time(s); this lockstep run may "
                    "not repeat exactly",
                    p.lockstep_waits_timed_out));
  }
}

void add_telemetry(std::string& out, const RunSummary& s) {
  auto line = [&out](const std::string& text) { out += text + '\n'; };
  if (!s.telemetry_file.empty() && (s.telemetry_lost > 0 || !s.telemetry_error.empty())) {
    line(fmt::format("RECORD LOST telemetry: {} of {} records could not be written to {}: {}",
                     s.telemetry_lost, s.telemetry_records + s.telemetry_lost, s.telemetry_file,
                     s.telemetry_error) +
         fmt::format(" ({} written, {} dropped)", s.telemetry_records, s.telemetry_dropped));
  } else if (!s.telemetry_file.empty()) {
    line(fmt::format("telemetry: {} records to {} ({} dropped)", s.telemetry_records,
                     s.telemetry_file, s.telemetry_dropped));
  }
  if (!s.record_file.empty() && (s.record_lost > 0 || !s.record_error.empty())) {
    line(fmt::format("RECORD LOST recording: {} of {} messages could not be written to {}: {}",
                     s.record_lost, s.record_messages + s.record_lost, s.record_file,
                     s.record_error) +
         fmt::format(" ({} written, {} dropped)", s.record_messages, s.record_dropped));
  } else if (!s.record_file.empty()) {
    line(fmt::format("recording: {} messages to {} ({} dropped)", s.record_messages, s.record_file,
                     s.record_dropped));
  }
}

nlohmann::json device_json(const DeviceReport& d) {
  const DeviceStatus& st = d.status;
  return nlohmann::json{{"bus", d.bus},
                        {"id", st.device_id},
                        {"joint", d.joint},
                        {"health", to_string(st.health)},
                        {"faulted", st.faulted},
                        {"transactions", st.transactions},
                        {"timeouts", st.timeouts},
                        {"crc_errors", st.crc_errors},
                        {"protocol_errors", st.protocol_errors},
                        {"hardware_errors", st.hardware_errors},
                        {"hardware_error_status", st.hardware_error_status},
                        {"exceptions", st.exceptions},
                        {"open_loop", st.open_loop},
                        {"readings",
                         {{"count", d.health.readings},
                          {"min_temperature_c", number_or_null(d.health.min_temperature_c)},
                          {"max_temperature_c", number_or_null(d.health.max_temperature_c)},
                          {"peak_current_a", number_or_null(d.health.peak_current_a)},
                          {"min_voltage_v", number_or_null(d.health.min_voltage_v)},
                          {"peak_torque_nm", number_or_null(d.health.peak_torque_nm)},
                          {"warnings", d.health.warnings}}}};
}

nlohmann::json physics_json(const PhysicsReport& p) {
  return nlohmann::json{{"model", p.model},
                        {"timestep_s", p.timestep_s},
                        {"simulated_s", p.simulated_s},
                        {"forward_m", p.forward_m},
                        {"sideways_m", p.sideways_m},
                        {"motion_s", p.motion_s},
                        {"motion_forward_m", p.motion_forward_m},
                        {"average_speed_m_s", p.average_speed_m_s},
                        {"falls", p.falls},
                        {"first_fall_s", p.first_fall_s},
                        {"lockstep_waits_timed_out", p.lockstep_waits_timed_out},
                        {"stride_length_m", p.stride_length_m},
                        {"duty_factor", p.duty_factor}};
}

}  // namespace

const char* to_string(EndReason reason) {
  switch (reason) {
    case EndReason::duration:
      return "duration";
    case EndReason::signal:
      return "stop request";
    case EndReason::fault:
      return "fault";
  }
  return "?";
}

std::string format_summary(const RunSummary& s) {
  std::string out;
  auto line = [&out](const std::string& text) { out += text + '\n'; };
  line(fmt::format(
      "run: {} on the {} backend, {} clock at {:g} Hz; ended by {} after {:.2f} s of motion",
      s.robot, s.backend, s.lockstep ? "lockstep" : "real-time", s.rate_hz, to_string(s.end_reason),
      s.motion_time_s));
  for (const auto& fault : s.faults) line("FAULT " + fault);
  for (const auto& warning : s.health_warnings) line("WARNING " + warning);
  for (const auto& warning : s.stop_warnings) line("WARNING " + warning);
  if (!s.torque_cut.empty()) line("TORQUE CUT " + s.torque_cut);
  line(fmt::format("cycles: {}, overruns: {}, skipped cycles: {}", s.cycles, s.overruns,
                   s.skipped_cycles));
  line(fmt::format("period: p50 {}, p99 {}, max {}", ms(s.period.p50_s), ms(s.period.p99_s),
                   ms(s.period.max_s)));
  line(fmt::format("jitter (start - deadline): p50 {}, p99 {}, max {}", ms(s.jitter.p50_s),
                   ms(s.jitter.p99_s), ms(s.jitter.max_s)));
  line(fmt::format("work per cycle: p50 {}, p99 {}, max {}", ms(s.busy.p50_s), ms(s.busy.p99_s),
                   ms(s.busy.max_s)));
  if (!s.lockstep) {
    line(s.sched_fifo ? fmt::format("scheduling: SCHED_FIFO priority {}", s.sched_priority)
                      : "scheduling: " + s.sched_note);
    line(s.memory_locked ? "memory: locked" : "memory: " + s.mlock_note);
    for (const auto& note : s.io_thread_notes) line("I/O thread: " + note);
    for (const auto& note : s.device_thread_notes) line("simulated devices: " + note);
  }
  for (const auto& bus : s.buses) {
    line(fmt::format("bus {}: cycle time (read + write) p50 {}, p99 {}, max {}; late cycles {}",
                     bus.name, ms(bus.io.p50_s), ms(bus.io.p99_s), ms(bus.io.max_s),
                     bus.late_cycles));
  }
  line("tracking error, commanded vs measured (deg):");
  for (const auto& j : s.joints) {
    if (j.prismatic) {  // metres, printed in mm
      line(fmt::format("  {:<14} rms {:7.3f}  max {:7.3f} mm", j.name,
                       1e3 * j.rms_tracking_error_rad, 1e3 * j.max_tracking_error_rad));
      continue;
    }
    line(fmt::format("  {:<14} rms {:7.3f}  max {:7.3f}", j.name,
                     rad_to_deg(j.rms_tracking_error_rad), rad_to_deg(j.max_tracking_error_rad)));
  }
  line("devices:");
  for (const auto& d : s.devices) line(device_line(d));
  for (const auto& imu : s.imus) {
    line(fmt::format("imu {}: {} readings, {} late cycles, {} missing reports{}", imu.name,
                     imu.readings, imu.late_cycles, imu.missing_reports,
                     imu.faulted ? " (FAULTED: silent past its stale_timeout_s)" : ""));
  }
  if (s.physics) add_physics(out, *s.physics);
  add_telemetry(out, s);
  return out;
}

nlohmann::json to_json(const RunSummary& s) {
  nlohmann::json j;
  j["robot"] = s.robot;
  j["backend"] = s.backend;
  j["clock"] = s.lockstep ? "lockstep" : "realtime";
  j["rate_hz"] = s.rate_hz;
  j["end_reason"] = to_string(s.end_reason);
  j["exit_code"] = s.exit_code();
  j["faults"] = s.faults;
  j["health_warnings"] = s.health_warnings;
  j["stop_warnings"] = s.stop_warnings;
  j["cycles"] = s.cycles;
  j["overruns"] = s.overruns;
  j["skipped_cycles"] = s.skipped_cycles;
  j["torque_cut"] = s.torque_cut;
  j["motion_time_s"] = s.motion_time_s;
  j["period"] = timing_json(s.period);
  j["jitter"] = timing_json(s.jitter);
  j["work_per_cycle"] = timing_json(s.busy);
  j["realtime"] = {{"sched_fifo", s.sched_fifo},
                   {"priority", s.sched_priority},
                   {"sched_note", s.sched_note},
                   {"memory_locked", s.memory_locked},
                   {"mlock_note", s.mlock_note},
                   {"io_thread_notes", s.io_thread_notes},
                   {"device_thread_notes", s.device_thread_notes}};
  j["buses"] = nlohmann::json::array();
  for (const auto& bus : s.buses)
    j["buses"].push_back(
        {{"name", bus.name}, {"io", timing_json(bus.io)}, {"late_cycles", bus.late_cycles}});
  j["joints"] = nlohmann::json::array();
  for (const auto& joint : s.joints) {
    j["joints"].push_back({{"name", joint.name},
                           {"rms_tracking_error_rad", joint.rms_tracking_error_rad},
                           {"max_tracking_error_rad", joint.max_tracking_error_rad}});
  }
  j["devices"] = nlohmann::json::array();
  for (const auto& d : s.devices) j["devices"].push_back(device_json(d));
  j["imus"] = nlohmann::json::array();
  for (const auto& imu : s.imus) {
    j["imus"].push_back({{"name", imu.name},
                         {"readings", imu.readings},
                         {"late_cycles", imu.late_cycles},
                         {"missing_reports", imu.missing_reports},
                         {"faulted", imu.faulted}});
  }
  j["telemetry"] = {{"file", s.telemetry_file},
                    {"records", s.telemetry_records},
                    {"dropped", s.telemetry_dropped},
                    {"lost", s.telemetry_lost},
                    {"error", s.telemetry_error}};
  j["recording"] = {{"file", s.record_file},
                    {"messages", s.record_messages},
                    {"dropped", s.record_dropped},
                    {"lost", s.record_lost},
                    {"error", s.record_error}};
  if (s.physics) j["physics"] = physics_json(*s.physics);
  return j;
}

}  // namespace animrt
