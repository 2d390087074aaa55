// The run's MCAP recording: rings filled by the cycle, JSON written by a
// thread (see mcap_recorder.hpp).

#include "animrt/runtime/mcap_recorder.hpp"

#include <fmt/format.h>
#include <time.h>

#include <chrono>
#include <cmath>
#include <iterator>

namespace animrt {
namespace {

constexpr std::size_t kRecordJointCapacity = 1 << 14;  // records, as the CSV's ring
constexpr std::size_t kRecordEventWidth = 7;           // t, kind, joint, bus, device, health, value
constexpr double kRecordStopRequest = 255.0;           // an event kind of the recording's own

std::string timestamp_schema() {
  return R"("timestamp":{"type":"object","properties":{"sec":{"type":"integer","minimum":0},)"
         R"("nsec":{"type":"integer","minimum":0,"maximum":999999999}}})";
}

std::string joint_states_schema() {
  return R"({"title":"foxglove.JointStates","type":"object","properties":{)" + timestamp_schema() +
         R"(,"joints":{"type":"array","items":{"type":"object","properties":{)"
         R"("name":{"type":"string"},"position":{"type":"number"},"velocity":{"type":"number"},)"
         R"("acceleration":{"type":"number"},"effort":{"type":"number"}}}}}})";
}

std::string log_schema() {
  return R"({"title":"foxglove.Log","type":"object","properties":{)" + timestamp_schema() +
         R"(,"level":{"type":"integer","enum":[0,1,2,3,4,5]},"message":{"type":"string"},)"
         R"("name":{"type":"string"},"file":{"type":"string"},"line":{"type":"integer","minimum":0}}})";
}

std::string numbers_schema(const RecordChannel& c) {
  std::string s =
      R"({"title":")" + c.schema + R"(","type":"object","properties":{)" + timestamp_schema();
  if (c.per_device) s += R"(,"device":{"type":"string"})";
  for (const auto& f : c.fields) s += ",\"" + f + R"(":{"type":["number","null"]})";
  return s + "}}";
}

void json_number(std::string& out, double v) {
  if (std::isfinite(v)) {
    fmt::format_to(std::back_inserter(out), "{:.9g}", v);
  } else {
    out += "null";
  }
}

void json_timestamp(std::string& out, std::uint64_t ns) {
  fmt::format_to(std::back_inserter(out), R"("timestamp":{{"sec":{},"nsec":{}}})",
                 ns / 1'000'000'000, ns % 1'000'000'000);
}

// JSON string contents: names and messages are ours, but a joint named by a
// user may hold anything.
void json_escaped(std::string& out, std::string_view s) {
  for (const char ch : s) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      fmt::format_to(std::back_inserter(out), "\\u{:04x}", static_cast<unsigned>(ch));
    } else {
      out += ch;
    }
  }
}

std::uint64_t record_wall_now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000ull +
         static_cast<std::uint64_t>(ts.tv_nsec);
}

}  // namespace

McapRecorder::McapRecorder(const std::string& path, const RobotModel& model)
    : model_(model), writer_(path) {
  std::size_t devices = 0;
  for (const BusModel& bus : model.buses) {
    device_base_.push_back(devices);
    for (std::size_t d = 0; d < bus.joint.size(); ++d) {
      const int j = bus.joint[d];
      device_names_.push_back(bus.name + "/" +
                              (j >= 0 ? model.joint_names[static_cast<std::size_t>(j)]
                                      : "id" + std::to_string(bus.device_id[d])));
    }
    devices += bus.joint.size();
  }
  const std::size_t n = model.joint_count();
  channels_.push_back(Channel{
      RecordChannel{"/joint_states", "foxglove.JointStates", {}, false, kRecordJointCapacity},
      Kind::joints,
      std::make_unique<TelemetryRing>(1 + 2 * n, kRecordJointCapacity),
      {},
      {}});
  cycle_.assign(1 + 2 * n, 0.0);
  channels_.push_back(Channel{RecordChannel{"/events", "foxglove.Log", {}, false, 1024},
                              Kind::events,
                              std::make_unique<TelemetryRing>(kRecordEventWidth, 1024),
                              {},
                              {}});
  loop_ = add(RecordChannel{"/loop",
                            "animrt.LoopStats",
                            {"period_s", "jitter_s", "busy_s", "overruns", "skipped_cycles"},
                            false,
                            kRecordJointCapacity});
  device_status_ =
      add(RecordChannel{"status",
                        "animrt.DeviceStatus",
                        {"health", "faulted", "transactions", "timeouts", "crc_errors",
                         "protocol_errors", "hardware_errors", "hardware_error_status"},
                        true,
                        4096});
}

McapRecorder::~McapRecorder() {
  finish();
  close();
}

std::size_t McapRecorder::add(RecordChannel channel) {
  const std::size_t width = 1 + (channel.per_device ? 1 : 0) + channel.fields.size();
  const std::size_t capacity = channel.capacity;
  channels_.push_back(Channel{
      std::move(channel), Kind::numbers, std::make_unique<TelemetryRing>(width, capacity), {}, {}});
  return channels_.size() - 1;
}

void McapRecorder::start() {
  start_ns_ = record_wall_now_ns();
  mcap::StringMap info{{"robot", model_.name},
                       {"rate_hz", fmt::format("{}", model_.rate_hz)},
                       {"start_time_ns", std::to_string(start_ns_)},
                       {"motion", model_.motion}};
  std::string joints;
  for (const auto& name : model_.joint_names) joints += (joints.empty() ? "" : ",") + name;
  info.emplace_back("joints", joints);
  writer_.add_metadata("animrt", info);
  std::size_t width = 0;
  for (Channel& c : channels_) {
    width = std::max(width, c.ring->width());
    if (c.kind == Kind::joints) {
      const auto schema =
          writer_.add_schema("foxglove.JointStates", "jsonschema", joint_states_schema());
      c.ids = {writer_.add_channel(schema, "/joint_states", "json"),
               writer_.add_channel(schema, "/joint_commands", "json")};
    } else if (c.kind == Kind::events) {
      const auto schema = writer_.add_schema("foxglove.Log", "jsonschema", log_schema());
      log_channel_ = writer_.add_channel(schema, c.spec.topic, "json");
      c.ids = {log_channel_};
    } else {
      const auto schema = writer_.add_schema(c.spec.schema, "jsonschema", numbers_schema(c.spec));
      if (c.spec.per_device) {
        for (const auto& device : device_names_) {
          c.ids.push_back(
              writer_.add_channel(schema, "/devices/" + device + "/" + c.spec.topic, "json"));
        }
      } else {
        c.ids = {writer_.add_channel(schema, c.spec.topic, "json")};
      }
    }
    c.sequence.assign(c.ids.size(), 0);
  }
  scratch_.assign(width, 0.0);
  started_ = true;
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_acquire)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    drain();
  });
}

bool McapRecorder::push(std::size_t channel, std::span<const double> record) {
  return channels_[channel].ring->push(record);
}

bool McapRecorder::push_joints(double t, std::span<const double> commands,
                               std::span<const double> measured) {
  double* buf = cycle_.data();
  buf[0] = t;
  std::copy(commands.begin(), commands.end(), buf + 1);
  std::copy(measured.begin(), measured.end(), buf + 1 + commands.size());
  return channels_[joints_].ring->push(std::span<const double>(buf, 1 + 2 * model_.joint_count()));
}

bool McapRecorder::push_event(const CycleEvent& e) {
  const double r[kRecordEventWidth] = {e.t,
                                       static_cast<double>(e.kind),
                                       static_cast<double>(e.joint),
                                       static_cast<double>(e.bus),
                                       static_cast<double>(e.device),
                                       static_cast<double>(e.health),
                                       e.value};
  return channels_[events_].ring->push(r);
}

bool McapRecorder::push_stop_request(double t) {
  const double r[kRecordEventWidth] = {t, kRecordStopRequest, -1, 0, 0, 0, 0};
  return channels_[events_].ring->push(r);
}

bool McapRecorder::push_loop(double t, double period_s, double jitter_s, double busy_s,
                             std::uint64_t overruns, std::uint64_t skipped) {
  const double r[6] = {
      t, period_s, jitter_s, busy_s, static_cast<double>(overruns), static_cast<double>(skipped)};
  return channels_[loop_].ring->push(r);
}

std::uint64_t McapRecorder::log_time(double t) const {
  return start_ns_ + static_cast<std::uint64_t>(std::llround(std::max(0.0, t) * 1e9));
}

std::string McapRecorder::describe(std::span<const double> e) const {
  const auto kind = static_cast<int>(e[1]);
  const int joint = static_cast<int>(e[2]);
  const auto bus = static_cast<std::size_t>(e[3]);
  const auto device = static_cast<std::size_t>(e[4]);
  const std::string joint_name =
      joint >= 0 && static_cast<std::size_t>(joint) < model_.joint_count()
          ? model_.joint_names[static_cast<std::size_t>(joint)]
          : "";
  const std::string device_name =
      bus < device_base_.size() && device_base_[bus] + device < device_names_.size()
          ? device_names_[device_base_[bus] + device]
          : "bus " + std::to_string(bus);
  static constexpr const char* kHealth[] = {"ok", "timeout", "protocol error", "hardware error"};
  const auto health = static_cast<std::size_t>(e[5]);
  switch (kind) {
    case static_cast<int>(EventKind::motion_started):
      return "motion started";
    case static_cast<int>(EventKind::motion_ended):
      return "motion ended";
    case static_cast<int>(EventKind::device_fault):
      return fmt::format("device fault: {} ({}); other joints ramped to home", device_name,
                         health < std::size(kHealth) ? kHealth[health] : "unknown");
    case static_cast<int>(EventKind::motion_fault):
      return fmt::format("motion fault: joint {} got a non-finite target", joint_name);
    case static_cast<int>(EventKind::following_error):
      return fmt::format("following error: {} ({}) RMS error {:.4g}", device_name, joint_name,
                         e[6]);
    case static_cast<int>(EventKind::stop_deadline):
      return "stop deadline: the stop ramp ran over; torque off at once";
    case static_cast<int>(EventKind::aborted):
      return "second stop request: torque off at once";
    case static_cast<int>(EventKind::stop_unreached):
      return fmt::format("stop: {} not at its stop pose at torque off ({:.4g} off)", joint_name,
                         e[6]);
    case static_cast<int>(kRecordStopRequest):
      return "stop requested: ramping to home";
    default:
      return fmt::format("event {}", kind);
  }
}

void McapRecorder::write_log(std::uint64_t time, LogLevel level, const std::string& text) {
  json_.clear();
  json_ += '{';
  json_timestamp(json_, time);
  fmt::format_to(std::back_inserter(json_), R"(,"level":{},"message":")", static_cast<int>(level));
  json_escaped(json_, text);
  json_ += R"(","name":"animrt","file":"","line":0})";
  writer_.write(log_channel_, log_sequence_++, time, time, json_);
}

void McapRecorder::write_record(Channel& c, std::span<const double> r) {
  const std::uint64_t time = log_time(r[0]);
  last_t_ = std::max(last_t_, r[0]);
  if (c.kind == Kind::joints) {
    const std::size_t n = model_.joint_count();
    // Measured, then commanded: one foxglove.JointStates each.
    for (int k = 0; k < 2; ++k) {
      const double* v = r.data() + 1 + (k == 0 ? n : 0);
      json_.clear();
      json_ += '{';
      json_timestamp(json_, time);
      json_ += R"(,"joints":[)";
      for (std::size_t j = 0; j < n; ++j) {
        json_ += j ? R"(,{"name":")" : R"({"name":")";
        json_escaped(json_, model_.joint_names[j]);
        json_ += R"(","position":)";
        json_number(json_, v[j]);
        json_ += '}';
      }
      json_ += "]}";
      const auto kk = static_cast<std::size_t>(k);
      writer_.write(c.ids[kk], c.sequence[kk]++, time, time, json_);
    }
    return;
  }
  if (c.kind == Kind::events) {
    const auto kind = static_cast<int>(r[1]);
    const LogLevel level = kind == static_cast<int>(EventKind::device_fault) ||
                                   kind == static_cast<int>(EventKind::motion_fault) ||
                                   kind == static_cast<int>(EventKind::following_error)
                               ? LogLevel::error
                               : (kind == static_cast<int>(EventKind::stop_deadline) ||
                                          kind == static_cast<int>(EventKind::aborted)
                                      ? LogLevel::warning
                                      : LogLevel::info);
    write_log(time, level, describe(r));
    return;
  }
  std::size_t at = 0;
  std::size_t first = 1;
  if (c.spec.per_device) {
    if (!(r[1] >= 0.0 && r[1] < static_cast<double>(c.ids.size()))) return;  // no such device
    at = static_cast<std::size_t>(r[1]);
    first = 2;
  }
  json_.clear();
  json_ += '{';
  json_timestamp(json_, time);
  if (c.spec.per_device) {
    json_ += R"(,"device":")";
    json_escaped(json_, device_names_[at]);
    json_ += '"';
  }
  for (std::size_t f = 0; f < c.spec.fields.size(); ++f) {
    json_ += ",\"" + c.spec.fields[f] + "\":";
    json_number(json_, r[first + f]);
  }
  json_ += '}';
  writer_.write(c.ids[at], c.sequence[at]++, time, time, json_);
}

void McapRecorder::drain() {
  std::lock_guard lock(mutex_);
  for (Channel& c : channels_) {
    const std::span<double> r(scratch_.data(), c.ring->width());
    while (c.ring->pop(r)) write_record(c, r);
  }
}

void McapRecorder::finish() {
  if (thread_.joinable()) {
    stop_.store(true, std::memory_order_release);
    thread_.join();
  }
}

void McapRecorder::close(std::span<const std::pair<LogLevel, std::string>> notes) {
  finish();
  std::lock_guard lock(mutex_);
  if (started_) {
    for (const auto& [level, text] : notes) write_log(log_time(last_t_), level, text);
  }
  writer_.close();
}

std::uint64_t McapRecorder::messages() const {
  std::lock_guard lock(mutex_);
  return writer_.messages() - writer_.lost();
}

std::uint64_t McapRecorder::dropped() const {
  std::uint64_t n = 0;
  for (const Channel& c : channels_) n += c.ring->dropped();
  return n;
}

std::uint64_t McapRecorder::lost() const {
  std::lock_guard lock(mutex_);
  return writer_.lost();
}

int McapRecorder::error() const {
  std::lock_guard lock(mutex_);
  return writer_.error();
}

}  // namespace animrt
