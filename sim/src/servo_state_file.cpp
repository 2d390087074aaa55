#include "animrt/sim/servo_state_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::sim {
namespace {

bool parse_hex(const std::string& text, std::vector<std::uint8_t>& out) {
  if (text.size() % 2 != 0) return false;
  out.clear();
  for (std::size_t i = 0; i < text.size(); i += 2) {
    unsigned v = 0;
    for (std::size_t k = i; k < i + 2; ++k) {
      const char c = text[k];
      v <<= 4;
      if (c >= '0' && c <= '9') {
        v |= static_cast<unsigned>(c - '0');
      } else if (c >= 'a' && c <= 'f') {
        v |= static_cast<unsigned>(c - 'a' + 10);
      } else if (c >= 'A' && c <= 'F') {
        v |= static_cast<unsigned>(c - 'A' + 10);
      } else {
        return false;
      }
    }
    out.push_back(static_cast<std::uint8_t>(v));
  }
  return true;
}

}  // namespace

ServoStateFile::ServoStateFile(std::string path) : path_(std::move(path)) {
  // None yet: an empty state. Anything but a regular file is refused before
  // it is read or replaced: the state is saved by renaming a new file over
  // the path, which would replace a device such as /dev/zero with a file.
  std::istringstream in;
  if (input_file_problem(path_) != kFileMissing) in.str(read_input_file(path_));
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string bus, family, hex;
    long index = -1;
    Entry entry;
    if (!(words >> bus >> index >> family >> hex) || index < 0 || !parse_hex(hex, entry.bytes)) {
      throw InputError(Location{path_, number, 0}, "servo",
                       "expected 'BUS INDEX FAMILY HEX', found \"" + elide(line) + "\"");
    }
    entry.family = family;
    entry.line = number;
    entries_[{bus, static_cast<std::size_t>(index)}] = std::move(entry);
  }
  write_locked(false);
}

std::vector<std::uint8_t> ServoStateFile::find(const std::string& bus, std::size_t index,
                                               const ServoFamily& family) const {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find({bus, index});
  if (it == entries_.end()) return {};
  const Entry& e = it->second;
  const auto fail = [&](const std::string& problem) {
    throw InputError(Location{path_, e.line, 0}, "servo",
                     "bus " + bus + " servo " + std::to_string(index) + ": " + problem);
  };
  if (e.family != family.name) {
    fail("is a " + std::string(family.name) + ", found the EEPROM of a " + elide(e.family));
  }
  if (e.bytes.size() != family.eeprom_end) {
    fail("expected " + std::to_string(family.eeprom_end) + " bytes of EEPROM, found " +
         std::to_string(e.bytes.size()));
  }
  // 0xFE is the broadcast id, 0xFF none.
  if (const int id = e.bytes[family.id_address]; id >= 0xFE) {
    fail("id " + std::to_string(id) + " is no servo's (expected 0..253)");
  }
  if (const int code = e.bytes[family.baud_address];
      baud_of(family, e.bytes[family.baud_address]) == 0) {
    fail("Baud Rate " + std::to_string(code) + " names no baud rate");
  }
  return e.bytes;
}

void ServoStateFile::put(const std::string& bus, std::size_t index, std::string_view family,
                         std::span<const std::uint8_t> eeprom) {
  std::lock_guard lock(mutex_);
  Entry& e = entries_[{bus, index}];
  e.family = std::string(family);
  e.bytes.assign(eeprom.begin(), eeprom.end());
  e.line = 0;
  write_locked(true);
}

void ServoStateFile::write_locked(bool replace) const {
  const std::string temp = path_ + ".tmp";
  {
    std::ofstream out(temp, std::ios::trunc);
    out << "# animrt sim: EEPROM of each simulated serial servo (bus, index, family, bytes)\n";
    static constexpr char kHex[] = "0123456789abcdef";
    for (const auto& [key, entry] : entries_) {
      out << key.first << ' ' << key.second << ' ' << entry.family << ' ';
      for (std::uint8_t b : entry.bytes) out << kHex[b >> 4] << kHex[b & 15];
      out << '\n';
    }
    out.flush();
    if (!out) throw DeviceError("servo state " + path_ + ": cannot write " + temp);
  }
  if (!replace) {
    std::remove(temp.c_str());
    return;
  }
  if (std::rename(temp.c_str(), path_.c_str()) != 0) {
    throw DeviceError("servo state " + path_ + ": rename: " + std::strerror(errno));
  }
}

}  // namespace animrt::sim
