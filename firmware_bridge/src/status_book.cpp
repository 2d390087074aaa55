#include "animrt/bridge/status_book.hpp"

#include <utility>

namespace animrt {

StatusBook::StatusBook(const BusConfig& config, std::string where, std::string noun)
    : name_(config.name), where_(std::move(where)), noun_(std::move(noun)) {
  for (const ActuatorBinding& b : config.actuators) {
    ids_.push_back(b.device_id);
    joints_.push_back(b.joint);
  }
  status_.resize(ids_.size());
  reset();
}

void StatusBook::reset() {
  for (std::size_t i = 0; i < status_.size(); ++i) {
    status_[i] = DeviceStatus{};
    status_[i].device_id = ids_[i];
  }
}

std::string StatusBook::prefix() const { return "bus " + name_ + " (" + where_ + "): "; }

std::string StatusBook::describe(std::size_t device) const {
  return noun_ + " " + std::to_string(ids_[device]) + " (" + joints_[device] + ")";
}

}  // namespace animrt
