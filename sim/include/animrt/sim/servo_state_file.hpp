#pragma once
// Where simulated serial servos keep their EEPROM across `animrt sim`
// restarts (--state FILE): one line per servo, "BUS INDEX FAMILY HEX"
// (the bus's name in the robot file, the servo's place on it, 0-based, the
// family's name and the EEPROM bytes). Rewritten whole (next to the file,
// then renamed) whenever a servo's EEPROM changes, so a killed simulator
// leaves the last complete state. Safe from any thread.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <map>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "animrt/core/clock.hpp"
#include "animrt/sim/servo_eeprom.hpp"
#include "animrt/sim/simulated_bus.hpp"

namespace animrt::sim {

class ServoStateFile {
 public:
  // Reads `path` if it exists (a missing file is an empty state) and writes
  // its content to the file's temporary neighbour at once, so a path that
  // cannot be written fails here (the file itself is replaced only when a
  // servo's EEPROM changes, so errors name its lines as the user wrote them); throws
  // InputError naming the file when it is not a regular file (a device, a
  // FIFO, a folder), and its line for a line it cannot read; DeviceError
  // when it cannot write.
  explicit ServoStateFile(std::string path);

  const std::string& path() const { return path_; }
  // What servo `index` of bus `bus` kept: empty when the file holds nothing
  // for it. InputError at the entry's line when it is of another family, not
  // the family's EEPROM size, or holds an id or baud rate no servo can have
  // (the servo would come up at its defaults or unreachable, and the id and
  // baud rate it was given be lost when the file is next saved).
  std::vector<std::uint8_t> find(const std::string& bus, std::size_t index,
                                 const ServoFamily& family) const;
  // Records a servo's EEPROM and rewrites the file; throws DeviceError if the
  // file cannot be written.
  void put(const std::string& bus, std::size_t index, std::string_view family,
           std::span<const std::uint8_t> eeprom);

 private:
  struct Entry {
    std::string family;
    std::vector<std::uint8_t> bytes;
    int line = 0;  // in the file as read; 0 once written by us
  };
  // Writes the entries to the temporary file, and renames it over the path
  // when `replace`.
  void write_locked(bool replace) const;

  std::string path_;
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, std::size_t>, Entry> entries_;
};

// One bus's serial servos brought up as a ServoStartup says, and their
// EEPROM saved to its state file when it changes (and at exit). `Servos` is a
// family's firmware (size(), at(i)); each servo has eeprom(),
// restore_eeprom(), factory_reset() and set_plugged().
class ServoStartupKeeper {
 public:
  ServoStartupKeeper(const ServoStartup& startup, std::string bus)
      : factory_(startup.factory), file_(startup.state), bus_(std::move(bus)) {}

  template <class Servos, class FactoryReset>
  void start(Servos& servos, Nanos now, FactoryReset&& factory_reset) {
    for (std::size_t i = 0; i < servos.size(); ++i) {
      auto& s = servos.at(i);
      if (factory_) {
        factory_reset(s);
        s.set_plugged(i == 0, now);  // the user plugs in one new servo at a time
      }
      if (file_ != nullptr) {
        const std::vector<std::uint8_t> kept = file_->find(bus_, i, s.eeprom().family());
        if (!kept.empty()) s.restore_eeprom(kept, now);
      }
      saved_.push_back(s.eeprom().changes());
    }
  }
  // After each packet: saves the servos whose EEPROM changed. `all` (at
  // exit): every servo. Never throws; a failed write is kept in error().
  template <class Servos>
  void save(Servos& servos, bool all = false) noexcept {
    if (file_ == nullptr) return;
    for (std::size_t i = 0; i < servos.size() && i < saved_.size(); ++i) {
      const ServoEeprom& e = servos.at(i).eeprom();
      if (!all && e.changes() == saved_[i]) continue;
      try {
        file_->put(bus_, i, e.family().name, e.kept());
        saved_[i] = e.changes();
      } catch (const std::exception& ex) {
        error_ = ex.what();
      }
    }
  }
  const std::string& error() const { return error_; }

 private:
  bool factory_;
  ServoStateFile* file_;
  std::string bus_;
  std::vector<std::uint64_t> saved_;
  std::string error_;
};

}  // namespace animrt::sim
