// Replaying a telemetry CSV into a RunMonitor (see telemetry_replay.hpp).

#include "animrt/runtime/telemetry_replay.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "animrt/runtime/mcap_reader.hpp"

namespace animrt {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) out.push_back(field);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The recording's start from its animrt metadata; false when it has none.
bool telemetry_mcap_start(const mcap::ReadFile& file, std::uint64_t& start) {
  bool have_start = false;
  for (const auto& [name, entries] : file.metadata) {
    for (const auto& [key, value] : entries) {
      if (name != "animrt" || key != "start_time_ns") continue;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), start);
      have_start = ec == std::errc() && end == value.data() + value.size();
    }
  }
  return have_start;
}

// A message's positions, in the order of the first message's joints.
void append_telemetry_positions(const std::string& path, const mcap::ReadFile& file,
                                const mcap::ReadMessage& m, std::vector<std::string>& names,
                                std::vector<double>& out) {
  nlohmann::json j = nlohmann::json::parse(m.data, nullptr, false);
  const auto bad = [&](const std::string& what) {
    throw InputError(Location{path, 0, 0}, "",
                     "message " + std::to_string(m.sequence) + " of " +
                         file.channels.at(m.channel).topic + ": " + what);
  };
  if (!j.is_object() || !j.contains("joints") || !j["joints"].is_array()) {
    bad("expected a foxglove.JointStates JSON object with joints");
  }
  const auto& joints = j["joints"];
  if (names.empty()) {
    for (const auto& joint : joints) {
      if (!joint.is_object() || !joint.contains("name") || !joint["name"].is_string()) {
        bad("expected each joint to have a name");
      }
      names.push_back(joint["name"].get<std::string>());
    }
    if (names.empty()) bad("expected at least one joint");
  }
  if (joints.size() != names.size()) {
    bad("expected " + std::to_string(names.size()) + " joints, found " +
        std::to_string(joints.size()));
  }
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const auto& joint = joints[k];
    const bool named = joint.is_object() && joint.contains("name") && joint["name"].is_string() &&
                       joint["name"].get_ref<const std::string&>() == names[k];
    if (!named) {
      bad("expected joint " + names[k] + " at position " + std::to_string(k + 1));
    }
    const auto it = joint.find("position");
    out.push_back(it != joint.end() && it->is_number() ? it->get<double>()
                                                       : std::numeric_limits<double>::quiet_NaN());
  }
}

}  // namespace

TelemetryRecording load_telemetry_csv(const std::string& path) {
  const std::string text = read_input_file(path);
  TelemetryRecording rec;
  rec.file = path;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  const auto fail = [&](int column, const std::string& message) {
    throw InputError(Location{path, line_no, column}, "", message);
  };
  // A file saved on Windows ends its lines with CR LF: the CR is no part
  // of the last field (and invisible in a message quoting it).
  const auto next_line = [&in, &line] {
    if (!std::getline(in, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next_line()) fail(0, "expected a telemetry CSV header, found an empty file");
  ++line_no;
  const std::vector<std::string> header = split(line);
  // time_s, n commands, n measurements, then device health columns (5 per
  // device whose bus reads health), which a replay does not use.
  std::size_t n = 0;
  while (1 + n < header.size() && ends_with(header[1 + n], "_cmd_rad")) ++n;
  if (header.empty() || header[0] != "time_s" || n == 0 || header.size() < 1 + 2 * n) {
    fail(1,
         "expected the header time_s,<joint>_cmd_rad,...,<joint>_meas_rad,... of animrt run "
         "--telemetry, found " +
             quote(line));
  }
  for (std::size_t j = 0; j < n; ++j) {
    const std::string& cmd = header[1 + j];
    const std::string& meas = header[1 + n + j];
    const std::string name = cmd.substr(0, cmd.size() - 8);
    if (meas != name + "_meas_rad") {
      fail(0, "expected " + name + "_meas_rad as column " + std::to_string(2 + n + j) + ", found " +
                  quote(meas));
    }
    rec.joints.push_back(name);
  }
  for (std::size_t c = 1 + 2 * n; c < header.size(); ++c) {
    const std::string& h = header[c];
    bool known = false;
    for (const char* suffix :
         {"_temp_c", "_current_a", "_voltage_v", "_torque_nm", "_error_bits", "_qw", "_qx", "_qy",
          "_qz", "_rate_x_rad_s", "_rate_y_rad_s", "_rate_z_rad_s"}) {
      known = known || ends_with(h, suffix);
    }
    if (!known) {
      fail(0,
           "expected a device health column (<joint>_temp_c, _current_a, _voltage_v, _torque_nm or "
           "_error_bits) or an IMU column (<imu>_qw, _qx, _qy, _qz, _rate_x_rad_s, _rate_y_rad_s, "
           "_rate_z_rad_s) as column " +
               std::to_string(c + 1) + ", found " + quote(h));
    }
  }
  const std::size_t width = header.size();
  while (next_line()) {
    ++line_no;
    if (line.empty()) continue;
    const std::vector<std::string> fields = split(line);
    if (fields.size() != width) {
      fail(1,
           "expected " + std::to_string(width) + " fields, found " + std::to_string(fields.size()));
    }
    int col = 1;
    std::vector<double> values(fields.size());
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const std::string& f = fields[i];
      const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), values[i]);
      if (ec != std::errc() || end != f.data() + f.size()) {
        fail(col, "expected a number, found " + quote(f));
      }
      // The time and the joints' angles are drawn and replayed: finite.
      if (i < 1 + 2 * n && !std::isfinite(values[i])) {
        fail(col, "expected a finite number, found " + quote(f));
      }
      col += static_cast<int>(f.size()) + 1;
    }
    if (!rec.t.empty() && !(values[0] >= rec.t.back())) {
      fail(1, "time goes backwards (" + quote(fields[0]) + " after " + format_number(rec.t.back()) +
                  ")");
    }
    rec.t.push_back(values[0]);
    rec.cmd.insert(rec.cmd.end(), values.begin() + 1, values.begin() + 1 + static_cast<long>(n));
    rec.meas.insert(rec.meas.end(), values.begin() + 1 + static_cast<long>(n),
                    values.begin() + 1 + static_cast<long>(2 * n));
  }
  if (rec.t.empty()) fail(0, "expected at least one row after the header");
  return rec;
}

TelemetryRecording load_telemetry_mcap(const std::string& path) {
  const mcap::ReadFile file = mcap::read_file(path);
  const auto fail = [&](const std::string& message) {
    throw InputError(Location{path, 0, 0}, "", message);
  };
  const mcap::ReadChannel* meas = file.channel("/joint_states");
  const mcap::ReadChannel* cmd = file.channel("/joint_commands");
  if (!meas || !cmd) {
    fail("expected the channels /joint_states and /joint_commands of animrt run --record");
  }
  std::uint64_t start = 0;
  bool have_start = telemetry_mcap_start(file, start);
  TelemetryRecording rec;
  rec.file = path;
  std::vector<const mcap::ReadMessage*> commands;
  for (const mcap::ReadMessage& m : file.messages) {
    if (m.channel == cmd->id) commands.push_back(&m);
  }
  std::size_t next_command = 0;
  for (const mcap::ReadMessage& m : file.messages) {
    if (m.channel != meas->id) continue;
    if (!have_start) {
      start = m.log_time;
      have_start = true;
    }
    append_telemetry_positions(path, file, m, rec.joints, rec.meas);
    // The command of the same cycle: the same log time.
    while (next_command < commands.size() && commands[next_command]->log_time < m.log_time) {
      ++next_command;
    }
    if (next_command == commands.size() || commands[next_command]->log_time != m.log_time) {
      fail("no /joint_commands message at the time of /joint_states message " +
           std::to_string(m.sequence));
    }
    append_telemetry_positions(path, file, *commands[next_command++], rec.joints, rec.cmd);
    // The difference first: nanoseconds since 1970 do not fit a double's mantissa.
    const double t = m.log_time >= start ? static_cast<double>(m.log_time - start) * 1e-9
                                         : -static_cast<double>(start - m.log_time) * 1e-9;
    if (!rec.t.empty() && t < rec.t.back()) {
      fail("time goes backwards at /joint_states message " + std::to_string(m.sequence));
    }
    rec.t.push_back(t);
  }
  if (rec.t.empty()) fail("expected at least one /joint_states message");
  return rec;
}

TelemetryRecording load_telemetry(const std::string& path) {
  check_input_file(path, kMaxMediaFileBytes);  // before the peek: a FIFO would block it
  char head[sizeof mcap::kMagic] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(head, sizeof head);
  if (in.gcount() == sizeof head &&
      mcap::has_magic(std::span(reinterpret_cast<const std::uint8_t*>(head), sizeof head))) {
    return load_telemetry_mcap(path);
  }
  return load_telemetry_csv(path);
}

RobotModel replay_model(const TelemetryRecording& recording, const RobotConfig* robot) {
  RobotModel m;
  m.name = robot ? robot->name : recording.file;
  m.rate_hz = robot ? robot->rate_hz : 0.0;
  if (!robot && recording.rows() > 1) {
    const double span = recording.t.back() - recording.t.front();
    if (span > 0) m.rate_hz = static_cast<double>(recording.rows() - 1) / span;
  }
  m.dt = m.rate_hz > 0 ? 1.0 / m.rate_hz : 0.0;
  m.period = from_seconds(m.dt);
  for (const std::string& name : recording.joints) {
    JointLimits limits{-std::numbers::pi, std::numbers::pi, 10.0, 100.0};
    double home = 0.0;
    bool prismatic = false;
    if (robot) {
      const auto it = std::find_if(robot->joints.begin(), robot->joints.end(),
                                   [&](const JointSpec& j) { return j.name == name; });
      if (it == robot->joints.end()) {
        throw InputError(Location{recording.file, 1, 0}, "",
                         "joint " + name + " of the recording is not a joint of " + robot->file);
      }
      limits = it->limits;
      home = it->home;
      prismatic = it->type == JointType::prismatic;
    }
    m.joint_names.push_back(name);
    m.limits.push_back(limits);
    m.home.push_back(home);
    m.prismatic.push_back(prismatic ? 1 : 0);
    m.following_error.push_back(0.0);
    m.slots.push_back(JointSlot{});
  }
  // The robot's buses, when they can be laid over the recording's joints.
  if (robot && robot->joints.size() == recording.joints.size()) {
    for (const BusConfig& bus : robot->buses) {
      BusModel b;
      b.name = bus.name;
      for (const ActuatorBinding& a : bus.actuators) {
        const auto at = std::find(recording.joints.begin(), recording.joints.end(), a.joint);
        b.joint.push_back(static_cast<int>(at - recording.joints.begin()));
        b.device_id.push_back(a.device_id);
      }
      m.buses.push_back(std::move(b));
    }
  }
  return m;
}

TelemetryReplay::TelemetryReplay(const TelemetryRecording& recording, RunMonitor& monitor)
    : recording_(recording), monitor_(monitor), vel_(recording.joints.size(), 0.0) {
  publish(0);
  thread_ = std::thread([this] { loop(); });
}

TelemetryReplay::~TelemetryReplay() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void TelemetryReplay::seek(double t_s, bool playing) {
  const auto it = std::upper_bound(recording_.t.begin(), recording_.t.end(), t_s);
  const std::size_t row =
      it == recording_.t.begin() ? 0 : static_cast<std::size_t>(it - recording_.t.begin()) - 1;
  {
    std::lock_guard lock(mutex_);
    row_ = row;
    playing_ = playing;
    moved_ = true;
    publish(row);
  }
  changed_.notify_all();
}

void TelemetryReplay::publish(std::size_t row) {
  const std::size_t n = recording_.joints.size();
  const double* cmd = recording_.cmd.data() + row * n;
  const double* meas = recording_.meas.data() + row * n;
  for (std::size_t j = 0; j < n; ++j) {
    vel_[j] = 0.0;
    if (row > 0 && recording_.t[row] > recording_.t[row - 1]) {
      vel_[j] = (cmd[j] - cmd[j - n]) / (recording_.t[row] - recording_.t[row - 1]);
    }
  }
  monitor_.publish_sample(recording_.t[row], RunPhaseView::motion, row,
                          std::span<const double>(cmd, n), std::span<const double>(meas, n), vel_);
}

void TelemetryReplay::loop() {
  using Steady = std::chrono::steady_clock;
  std::unique_lock lock(mutex_);
  // Row `row_` is shown at `shown`; the next one is due its time later.
  Steady::time_point shown = Steady::now();
  while (!quit_) {
    if (!playing_) {
      changed_.wait(lock, [this] { return quit_ || moved_; });
      moved_ = false;
      shown = Steady::now();
      continue;
    }
    const std::size_t next = row_ + 1 < recording_.rows() ? row_ + 1 : 0;  // loop at the end
    const double gap = next == 0 ? 0.5 : recording_.t[next] - recording_.t[row_];
    const auto due = shown + std::chrono::duration_cast<Steady::duration>(
                                 std::chrono::duration<double>(std::max(0.0, gap)));
    if (changed_.wait_until(lock, due, [this] { return quit_ || moved_; })) {
      moved_ = false;
      shown = Steady::now();
      continue;
    }
    row_ = next;
    shown = due;
    publish(row_);
  }
}

}  // namespace animrt
