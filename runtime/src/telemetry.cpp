#include "animrt/runtime/telemetry.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <iterator>
#include <stdexcept>

#include "animrt/core/input_file.hpp"

namespace animrt {
namespace {

// Text gathered before one write(2): a few hundred records.
constexpr std::size_t kFlushBytes = 1 << 16;

}  // namespace

TelemetryRing::TelemetryRing(std::size_t width, std::size_t capacity)
    : width_(width), capacity_(capacity), slots_(width * capacity, 0.0) {}

bool TelemetryRing::push(std::span<const double> record) {
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  const std::uint64_t tail = tail_.load(std::memory_order_acquire);
  if (head - tail >= capacity_) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  std::memcpy(&slots_[(head % capacity_) * width_], record.data(), width_ * sizeof(double));
  head_.store(head + 1, std::memory_order_release);
  return true;
}

bool TelemetryRing::pop(std::span<double> out) {
  const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
  const std::uint64_t head = head_.load(std::memory_order_acquire);
  if (tail == head) return false;
  std::memcpy(out.data(), &slots_[(tail % capacity_) * width_], width_ * sizeof(double));
  tail_.store(tail + 1, std::memory_order_release);
  return true;
}

TelemetryWriter::TelemetryWriter(const std::string& path, std::span<const std::string> joint_names,
                                 TelemetryRing& ring, std::span<const std::string> extra_columns)
    : ring_(ring), record_(ring.width(), 0.0) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    throw std::runtime_error("cannot write telemetry file " + path + ": " + std::strerror(errno));
  }
  // The header goes out with the first records: a file that takes nothing
  // is found by the same path as a disk that fills during the run.
  pending_ = "time_s";
  for (const auto& name : joint_names) pending_ += ',' + name + "_cmd_rad";
  for (const auto& name : joint_names) pending_ += ',' + name + "_meas_rad";
  for (const auto& name : extra_columns) pending_ += ',' + name;
  pending_ += '\n';
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_acquire)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    drain();
  });
}

TelemetryWriter::~TelemetryWriter() {
  finish();
  if (fd_ >= 0) ::close(fd_);
}

void TelemetryWriter::finish() {
  if (thread_.joinable()) {
    stop_.store(true, std::memory_order_release);
    thread_.join();
  }
}

void TelemetryWriter::drain() {
  while (ring_.pop(record_)) {
    for (std::size_t i = 0; i < record_.size(); ++i) {
      if (i) pending_ += ',';
      fmt::format_to(std::back_inserter(pending_), "{:.9g}", record_[i]);
    }
    pending_ += '\n';
    line_ends_.push_back(pending_.size());
    if (pending_.size() >= kFlushBytes) flush_pending();
  }
  flush_pending();
}

bool TelemetryWriter::flush_pending() {
  std::size_t done = 0;
  const int failed = write_all(fd_, pending_.data(), pending_.size(), &done);
  std::uint64_t whole = 0;
  while (whole < line_ends_.size() && line_ends_[whole] <= done) ++whole;
  written_.fetch_add(whole, std::memory_order_relaxed);
  lost_.fetch_add(line_ends_.size() - whole, std::memory_order_relaxed);
  if (failed != 0) {
    int none = 0;
    error_.compare_exchange_strong(none, failed);
  }
  pending_.clear();
  line_ends_.clear();
  return failed == 0;
}

}  // namespace animrt
