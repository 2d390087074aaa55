#pragma once
// Telemetry leaves the real-time cycle through a preallocated
// single-producer single-consumer ring; a writer thread drains it to CSV.
// The cycle never blocks: when the ring is full, records are dropped and
// counted.

#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace animrt {

class TelemetryRing {
 public:
  // `width` doubles per record, `capacity` records.
  TelemetryRing(std::size_t width, std::size_t capacity);
  // Producer side (real-time thread). Returns false (and counts) when full.
  bool push(std::span<const double> record);
  // Consumer side. Copies the oldest record into `out`; false when empty.
  bool pop(std::span<double> out);
  std::size_t width() const { return width_; }
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::size_t width_;
  std::size_t capacity_;
  std::vector<double> slots_;
  alignas(64) std::atomic<std::uint64_t> head_{0};  // next write (producer)
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // next read (consumer)
  std::atomic<std::uint64_t> dropped_{0};
};

// Drains a ring into a CSV file: `time_s,<joint>_cmd_rad,<joint>_meas_rad,...`,
// then the extra columns (device health: `<joint>_temp_c`, `_current_a`,
// `_voltage_v`, `_torque_nm`, `_error_bits`; nan where not read).
// A record that cannot be written (a full disk, /dev/full, a pipe whose
// reader left) is counted as lost with the first error, never silently: a
// record that is not on disk is a fault of the record, and the run says so.
class TelemetryWriter {
 public:
  // Opens the file (throws std::runtime_error naming it if it cannot).
  TelemetryWriter(const std::string& path, std::span<const std::string> joint_names,
                  TelemetryRing& ring, std::span<const std::string> extra_columns = {});
  ~TelemetryWriter();
  // Drains what is left and closes the file.
  void finish();
  std::uint64_t written() const { return written_.load(); }
  // Records taken from the ring that did not reach the file (a record cut
  // short by a failed write counts as lost).
  std::uint64_t lost() const { return lost_.load(); }
  // errno of the first failed write (0: none failed, the header included).
  int error() const { return error_.load(); }

 private:
  void drain();
  // Writes the pending text; records whose line did not reach the file whole
  // are counted lost. Returns whether everything was written.
  bool flush_pending();

  int fd_ = -1;
  TelemetryRing& ring_;
  std::vector<double> record_;
  std::string pending_;                 // formatted text not yet written
  std::vector<std::size_t> line_ends_;  // end offset in pending_ of each record's line
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> lost_{0};
  std::atomic<int> error_{0};
  std::thread thread_;
};

}  // namespace animrt
