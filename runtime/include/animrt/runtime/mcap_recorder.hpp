#pragma once
// A run's recording as MCAP (`animrt run --record RUN.mcap`), fed like the
// CSV telemetry: the cycle pushes numbers into preallocated single-producer
// single-consumer rings (never blocking, allocating or touching a file) and
// a writer thread formats them as JSON messages and writes the file.
//
// Channels, each message timestamped on the wall clock at the run's start
// plus its run time:
//   /joint_states     foxglove.JointStates  measured positions, every cycle
//   /joint_commands   foxglove.JointStates  the safety filter's output, every cycle
//   /events           foxglove.Log          faults, warnings, stop, motion start and end
//   /loop             animrt.LoopStats      period, jitter, work per cycle
//   /devices/<bus>/<joint>/status  animrt.DeviceStatus  per device, ~10 Hz
// and the Metadata record "animrt" (robot, rate, joints, start time).
//
// Adding a channel is one add() before start() and one push() per sample
// (see docs/cli.md, "Recording a run").

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "animrt/runtime/cycle.hpp"
#include "animrt/runtime/mcap_writer.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "animrt/runtime/telemetry.hpp"

namespace animrt {

// One recorded channel of numbers: a JSON message per pushed record, with
// `timestamp` and one number per field (a non-finite number is null).
struct RecordChannel {
  // "/loop"; per device, the last part of /devices/<bus>/<joint>/<topic>.
  std::string topic;
  std::string schema;               // schema name: "animrt.DeviceHealth"
  std::vector<std::string> fields;  // in push order
  bool per_device = false;          // push (t, device, fields...); else (t, fields...)
  std::size_t capacity = 4096;      // records the ring holds before it drops
};

// Log levels of foxglove.Log.
enum class LogLevel : std::uint8_t { debug = 1, info = 2, warning = 3, error = 4, fatal = 5 };

class McapRecorder {
 public:
  // Creates the file (throws std::runtime_error naming it if it cannot).
  McapRecorder(const std::string& path, const RobotModel& model);
  ~McapRecorder();
  McapRecorder(const McapRecorder&) = delete;
  McapRecorder& operator=(const McapRecorder&) = delete;

  // Before start(): a channel; returns the handle push() takes.
  std::size_t add(RecordChannel channel);
  // Writes the schemas, channels and metadata and starts the writer thread.
  void start();

  // The cycle's side (one producer thread per channel: the rings are
  // single-producer): never blocks, allocates or touches a file; false (and
  // counted as dropped) when the channel's ring is full. A per-device
  // record's device is its index over the model's buses in order (bus 0's
  // devices, then bus 1's...): device_index().
  bool push(std::size_t channel, std::span<const double> record);
  bool push_joints(double t, std::span<const double> commands, std::span<const double> measured);
  bool push_event(const CycleEvent& e);
  bool push_stop_request(double t);
  bool push_loop(double t, double period_s, double jitter_s, double busy_s, std::uint64_t overruns,
                 std::uint64_t skipped);
  std::size_t device_index(std::size_t bus, std::size_t device) const {
    return device_base_[bus] + device;
  }
  std::size_t device_status_channel() const { return device_status_; }

  // Drains the rings and stops the writer thread.
  void finish();
  // After finish(): lines for /events (the run's end), then the summary and
  // footer; the file is complete.
  void close(std::span<const std::pair<LogLevel, std::string>> notes = {});

  std::uint64_t messages() const;  // written to the file
  std::uint64_t dropped() const;   // rings full
  std::uint64_t lost() const;      // did not reach the file
  int error() const;               // errno of the first failed write

 private:
  enum class Kind { joints, events, numbers };
  struct Channel {
    RecordChannel spec;
    Kind kind;
    std::unique_ptr<TelemetryRing> ring;
    std::vector<std::uint16_t> ids;  // MCAP channel per device (or one)
    std::vector<std::uint32_t> sequence;
  };
  void drain();
  void write_record(Channel& c, std::span<const double> r);
  std::uint64_t log_time(double t) const;
  void write_log(std::uint64_t time, LogLevel level, const std::string& text);
  std::string describe(std::span<const double> event) const;

  const RobotModel& model_;
  mcap::Writer writer_;
  std::vector<Channel> channels_;
  std::vector<std::size_t> device_base_;
  std::vector<std::string> device_names_;  // "<bus>/<joint>"
  // The built-in channels' handles, in the order the constructor adds them.
  static constexpr std::size_t joints_ = 0, events_ = 1;
  std::size_t loop_ = 0, device_status_ = 0;
  std::uint16_t log_channel_ = 0;
  std::uint32_t log_sequence_ = 0;
  std::uint64_t start_ns_ = 0;
  double last_t_ = 0.0;
  std::vector<double> scratch_;  // the writer thread's record
  std::vector<double> cycle_;    // the cycle's joint record
  std::string json_;
  bool started_ = false;
  mutable std::mutex mutex_;  // the writer against the counters' readers
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace animrt
