#include "animrt/runtime/telemetry.hpp"

#include <chrono>
#include <cstring>
#include <stdexcept>

namespace animrt {

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
                                 TelemetryRing& ring)
    : out_(path), ring_(ring), record_(ring.width(), 0.0) {
  if (!out_) throw std::runtime_error("cannot write telemetry file " + path);
  out_ << "time_s";
  for (const auto& name : joint_names) out_ << ',' << name << "_cmd_rad";
  for (const auto& name : joint_names) out_ << ',' << name << "_meas_rad";
  out_ << '\n';
  out_.precision(9);
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_acquire)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    drain();
  });
}

TelemetryWriter::~TelemetryWriter() { finish(); }

void TelemetryWriter::finish() {
  if (thread_.joinable()) {
    stop_.store(true, std::memory_order_release);
    thread_.join();
    out_.flush();
  }
}

void TelemetryWriter::drain() {
  while (ring_.pop(record_)) {
    for (std::size_t i = 0; i < record_.size(); ++i) {
      if (i) out_ << ',';
      out_ << record_[i];
    }
    out_ << '\n';
    written_.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace animrt
