#include "animrt/bridge/commission/servo_setup.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <thread>

#include "animrt/bridge/commission/serial_scan.hpp"
#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "animrt/core/error.hpp"
#include "dxl_packets.hpp"
#include "ft_packets.hpp"

namespace animrt::commission {
namespace {

using std::chrono::microseconds;
namespace xreg = dxl::xreg;
namespace freg = ft::reg;

// A servo restarts within about a second after Reboot or Factory Reset.
constexpr auto kRestartWait = std::chrono::milliseconds(2000);
// A read is asked again while silent, at least three times and for this
// long: a servo busy storing EEPROM, or a loaded host, answers late, and a
// read back that gives up early reports a change as failed that was made.
constexpr auto kReadWindow = std::chrono::milliseconds(500);
// Factory Reset parameter: everything except ID and Baud Rate.
constexpr std::uint8_t kResetKeepIdAndBaud = 0x02;

// Feetech STS Operating Mode (address 33).
struct FtMode {
  const char* name;
  std::uint8_t value;
};
constexpr FtMode kFtModes[] = {{"position", 0}, {"velocity", 1}, {"pwm", 2}, {"step", 3}};

int baud_index(const std::vector<int>& bauds, int baud) {
  const auto it = std::find(bauds.begin(), bauds.end(), baud);
  return it == bauds.end() ? -1 : static_cast<int>(it - bauds.begin());
}

std::string baud_list(const std::vector<int>& bauds) {
  std::string out;
  for (int b : bauds) out += (out.empty() ? "" : ", ") + std::to_string(b);
  return out;
}

}  // namespace

ServoSetup::ServoSetup(Family family, Open open, int id, int baud, microseconds timeout)
    : family_(family), open_(std::move(open)), id_(id), baud_(baud), timeout_(timeout) {
  if (id_ < 0 || id_ > max_id(family_)) {
    throw DeviceError("--id " + std::to_string(id_) + ": expected 0.." +
                      std::to_string(max_id(family_)));
  }
  line_ = open_(baud_);
  if (!carries_baud(line_->port(), baud_)) {
    fail("a pseudo-terminal cannot be set to this rate (it takes only the standard ones)");
  }
  check_answers(id_);
  if (family_ == Family::feetech) {
    const auto table = ft_detail::read(*line_, static_cast<std::uint8_t>(id_), 0,
                                       freg::max_angle_limit + 2, baud_, timeout_);
    if (table) scs_ = ft_detail::guess_series(*table) == ft::Series::scs;
  }
}

bool ServoSetup::sts() const { return family_ == Family::feetech && !scs_; }

int ServoSetup::max_id(Family family) {
  return family == Family::dynamixel2 ? 252 : ft::kMaxDeviceId;
}

std::string ServoSetup::where() const {
  return std::string(family_ == Family::dynamixel2 ? "dynamixel2" : "feetech") + " id " +
         std::to_string(id_) + " at " + std::to_string(baud_) + " baud on " + line_->port();
}

void ServoSetup::fail(const std::string& what) const { throw DeviceError(where() + ": " + what); }

void ServoSetup::check_answers(int id) {
  int answers = 0;
  bool damaged = false;
  // A late answer is no absent servo: ask up to three times while silent.
  for (int attempt = 0; attempt < 3 && answers == 0; ++attempt) {
    if (family_ == Family::dynamixel2) {
      // Two servos answering at once garble each other: bytes that are no
      // clean packet, as the scan counts them.
      const auto s = dxl_detail::ping(*line_, static_cast<std::uint8_t>(id), baud_, timeout_);
      for (const auto& p : s.packets) answers += p.id == id ? 1 : 0;
      damaged = s.damaged > 0 || s.stray > 0;
      if (damaged) ++answers;
    } else {
      const auto s = ft_detail::transact(*line_, static_cast<std::uint8_t>(id), ft::inst::ping, {},
                                         6, baud_, timeout_);
      for (const auto& p : s.packets) answers += p.id == id ? 1 : 0;
      damaged = s.damaged > 0;
      if (damaged) ++answers;
    }
  }
  if (answers == 0) fail("no answer to a ping (check the id, the baud rate and the wiring)");
  if (answers > 1 || damaged) {
    fail("several servos answer as this id; plug in one servo at a time");
  }
}

void ServoSetup::require_torque_off() {
  if (family_ != Family::dynamixel2) return;
  const auto torque = read(id_, xreg::torque_enable, 1, "Torque Enable");
  if (torque[0] != 0) {
    fail("torque is on, and the servo refuses EEPROM writes while it is; switch it off first");
  }
}

std::vector<std::uint8_t> ServoSetup::read(int id, std::uint16_t address, std::uint16_t length,
                                           const std::string& what) {
  std::optional<std::vector<std::uint8_t>> data;
  const auto until = std::chrono::steady_clock::now() + kReadWindow;
  for (int attempt = 0; !data && (attempt < 3 || std::chrono::steady_clock::now() < until);
       ++attempt) {
    data = family_ == Family::dynamixel2
               ? dxl_detail::read(*line_, static_cast<std::uint8_t>(id), address, length, baud_,
                                  timeout_)
               : ft_detail::read(*line_, static_cast<std::uint8_t>(id),
                                 static_cast<std::uint8_t>(address),
                                 static_cast<std::uint8_t>(length), baud_, timeout_);
  }
  if (!data) {
    fail("no answer reading " + what + " back" +
         (id != id_ ? " at id " + std::to_string(id) : std::string()));
  }
  return *data;
}

void ServoSetup::write(std::uint16_t address, std::span<const std::uint8_t> bytes,
                       const std::string& what) {
  if (family_ == Family::dynamixel2) {
    std::vector<std::uint8_t> params(2 + bytes.size());
    dxl::put_u16(params.data(), address);
    std::copy(bytes.begin(), bytes.end(), params.begin() + 2);
    const int error = dxl_detail::instruct(*line_, static_cast<std::uint8_t>(id_), dxl::inst::write,
                                           params, baud_, timeout_);
    // A new ID or baud rate may take effect before the status packet goes
    // out (it then comes from the new id, or at the new rate): the read
    // back decides.
    const bool may_be_silent = address == xreg::id || address == xreg::baud_rate;
    if (error < 0 && may_be_silent) return;
    if (error < 0) fail("no answer to the write of " + what);
    if ((error & 0x7F) != 0) {
      fail("the servo refused " + what + ": " +
           dxl_detail::describe_error(static_cast<std::uint8_t>(error)));
    }
    return;
  }
  std::vector<std::uint8_t> params(1 + bytes.size());
  params[0] = static_cast<std::uint8_t>(address);
  std::copy(bytes.begin(), bytes.end(), params.begin() + 1);
  // Feetech answers a write with its status bits (no refusal codes): the
  // read back is what tells.
  ft_detail::transact(*line_, static_cast<std::uint8_t>(id_), ft::inst::write, params, 6, baud_,
                      timeout_);
}

void ServoSetup::lock_eeprom(int id, bool locked) {
  if (family_ != Family::feetech) return;
  const std::uint8_t address = scs_ ? freg::scs_lock : freg::sts_lock;
  const std::uint8_t params[2] = {address, static_cast<std::uint8_t>(locked ? 1 : 0)};
  ft_detail::transact(*line_, static_cast<std::uint8_t>(id), ft::inst::write, params, 6, baud_,
                      timeout_);
}

void ServoSetup::write_verified(std::uint16_t address, std::span<const std::uint8_t> bytes,
                                int read_id, const std::string& what) {
  lock_eeprom(id_, false);
  write(address, bytes, what);
  lock_eeprom(read_id, true);
  const auto back = read(read_id, address, static_cast<std::uint16_t>(bytes.size()), what);
  if (!std::equal(back.begin(), back.end(), bytes.begin(), bytes.end())) {
    fail(what + " did not read back as written (the servo kept its old value)");
  }
}

std::string ServoSetup::set_id(int new_id) {
  if (new_id < 0 || new_id > max_id(family_)) {
    fail("new id " + std::to_string(new_id) + " is outside 0.." + std::to_string(max_id(family_)));
  }
  if (new_id == id_) return where() + ": id is already " + std::to_string(new_id);
  require_torque_off();
  // Never give a servo an id another servo on the line answers to.
  {
    int answers = 0;
    if (family_ == Family::dynamixel2) {
      const auto s = dxl_detail::ping(*line_, static_cast<std::uint8_t>(new_id), baud_, timeout_);
      answers = static_cast<int>(s.packets.size()) + s.damaged + (s.stray > 0 ? 1 : 0);
    } else {
      const auto s = ft_detail::transact(*line_, static_cast<std::uint8_t>(new_id), ft::inst::ping,
                                         {}, 6, baud_, timeout_);
      answers = static_cast<int>(s.packets.size()) + s.damaged;
    }
    if (answers > 0) fail("id " + std::to_string(new_id) + " is already taken on this line");
  }
  const std::uint8_t value = static_cast<std::uint8_t>(new_id);
  const int old = id_;
  write_verified(family_ == Family::dynamixel2 ? xreg::id : freg::id, {&value, 1}, new_id, "ID");
  id_ = new_id;
  return where() + ": id " + std::to_string(old) + " -> " + std::to_string(new_id) + " (read back)";
}

std::string ServoSetup::set_baud(int new_baud) {
  const std::vector<int>& bauds =
      family_ == Family::dynamixel2 ? dynamixel_bauds() : feetech_bauds();
  const int index = baud_index(bauds, new_baud);
  if (index < 0) fail("baud " + std::to_string(new_baud) + " is not one of " + baud_list(bauds));
  if (new_baud == baud_) return where() + ": baud rate is already " + std::to_string(new_baud);
  require_torque_off();
  // The line must reach the servo at its new rate, or the servo is
  // stranded there: tried before anything is written.
  const std::string cannot = "the line cannot be set to " + std::to_string(new_baud) + " baud";
  if (!carries_baud(line_->port(), new_baud))
    fail(cannot + " (a pseudo-terminal takes only the standard rates); nothing was written");
  line_.reset();
  try {
    open_(new_baud).reset();
  } catch (const std::exception& e) {
    line_ = open_(baud_);
    fail(cannot + " (" + e.what() + "); nothing was written");
  }
  line_ = open_(baud_);
  const std::uint8_t value = static_cast<std::uint8_t>(index);
  lock_eeprom(id_, false);
  write(family_ == Family::dynamixel2 ? xreg::baud_rate : freg::baud_rate, {&value, 1},
        "Baud Rate");
  // The servo now listens at the new rate: the line follows it there.
  const int old = baud_;
  line_.reset();
  baud_ = new_baud;
  line_ = open_(baud_);
  lock_eeprom(id_, true);
  const auto back =
      read(id_, family_ == Family::dynamixel2 ? xreg::baud_rate : freg::baud_rate, 1, "Baud Rate");
  if (back[0] != value) fail("Baud Rate did not read back as written");
  return where() + ": baud " + std::to_string(old) + " -> " + std::to_string(new_baud) +
         " (read back at the new rate)";
}

std::string ServoSetup::set_return_delay(int microseconds) {
  if (microseconds < 0 || microseconds > 508 || microseconds % 2 != 0) {
    fail("return delay " + std::to_string(microseconds) + " us: expected an even 0..508");
  }
  require_torque_off();
  const std::uint8_t value = static_cast<std::uint8_t>(microseconds / 2);
  write_verified(family_ == Family::dynamixel2 ? xreg::return_delay_time : freg::return_delay,
                 {&value, 1}, id_, "Return Delay Time");
  return where() + ": return delay " + std::to_string(microseconds) + " us (read back)";
}

std::string ServoSetup::mode_names() const {
  if (family_ == Family::dynamixel2) return dxl_detail::mode_names();
  std::string out;
  for (const FtMode& m : kFtModes) out += (out.empty() ? "" : ", ") + std::string(m.name);
  return out;
}

std::string ServoSetup::set_mode(const std::string& mode) {
  std::optional<std::uint8_t> value;
  if (family_ == Family::dynamixel2) {
    value = dxl_detail::mode_value(mode);
  } else {
    if (!sts()) fail("SCS servos have no operating mode register");
    for (const FtMode& m : kFtModes) {
      if (mode == m.name) value = m.value;
    }
  }
  if (!value) fail("unknown mode '" + mode + "': expected one of " + mode_names());
  require_torque_off();
  write_verified(family_ == Family::dynamixel2 ? xreg::operating_mode : freg::operating_mode,
                 {&*value, 1}, id_, "Operating Mode");
  return where() + ": operating mode " + mode + " (read back)";
}

std::string ServoSetup::set_limits(long min_ticks, long max_ticks) {
  const long top =
      family_ == Family::dynamixel2 ? 4095 : (sts() ? ft::kStsMaxPosition : ft::kScsMaxPosition);
  if (min_ticks < 0 || max_ticks > top || min_ticks >= max_ticks) {
    fail("limits " + std::to_string(min_ticks) + " " + std::to_string(max_ticks) +
         ": expected 0 <= MIN < MAX <= " + std::to_string(top) + " (ticks)");
  }
  require_torque_off();
  if (family_ == Family::dynamixel2) {
    std::array<std::uint8_t, 4> max{};
    std::array<std::uint8_t, 4> min{};
    dxl::put_u32(max.data(), static_cast<std::uint32_t>(max_ticks));
    dxl::put_u32(min.data(), static_cast<std::uint32_t>(min_ticks));
    write_verified(xreg::max_position_limit, max, id_, "Max Position Limit");
    write_verified(xreg::min_position_limit, min, id_, "Min Position Limit");
  } else {
    const ft::Series series = scs_ ? ft::Series::scs : ft::Series::sts;
    std::array<std::uint8_t, 4> both{};
    ft::put_u16(series, both.data(), static_cast<std::uint16_t>(min_ticks));
    ft::put_u16(series, both.data() + 2, static_cast<std::uint16_t>(max_ticks));
    write_verified(freg::min_angle_limit, both, id_, "Min/Max Angle Limit");
  }
  return where() + ": position limits " + std::to_string(min_ticks) + ".." +
         std::to_string(max_ticks) + " ticks (read back)";
}

void ServoSetup::wait_for_answer(const std::string& after) {
  const auto end = std::chrono::steady_clock::now() + kRestartWait;
  while (std::chrono::steady_clock::now() < end) {
    int answers = 0;
    if (family_ == Family::dynamixel2) {
      dxl_detail::instruct(*line_, static_cast<std::uint8_t>(id_), dxl::inst::ping, {}, baud_,
                           timeout_, &answers);
    } else {
      const auto s = ft_detail::transact(*line_, static_cast<std::uint8_t>(id_), ft::inst::ping, {},
                                         6, baud_, timeout_);
      answers = static_cast<int>(s.packets.size());
    }
    if (answers > 0) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  fail("no answer after " + after);
}

std::string ServoSetup::reboot() {
  if (family_ != Family::dynamixel2) fail("Feetech servos have no reboot instruction");
  const int error = dxl_detail::instruct(*line_, static_cast<std::uint8_t>(id_), dxl::inst::reboot,
                                         {}, baud_, timeout_);
  if (error < 0) fail("no answer to Reboot");
  if ((error & 0x7F) != 0) {
    fail("the servo refused Reboot: " +
         dxl_detail::describe_error(static_cast<std::uint8_t>(error)));
  }
  wait_for_answer("Reboot");
  return where() + ": rebooted, answers again";
}

std::string ServoSetup::factory_reset() {
  require_torque_off();
  if (family_ == Family::dynamixel2) {
    const std::uint8_t param = kResetKeepIdAndBaud;
    const int error = dxl_detail::instruct(*line_, static_cast<std::uint8_t>(id_),
                                           dxl::inst::factory_reset, {&param, 1}, baud_, timeout_);
    if (error < 0) fail("no answer to Factory Reset");
    if ((error & 0x7F) != 0) {
      fail("the servo refused Factory Reset: " +
           dxl_detail::describe_error(static_cast<std::uint8_t>(error)));
    }
  } else {
    ft_detail::transact(*line_, static_cast<std::uint8_t>(id_), ft::inst::reset, {}, 6, baud_,
                        timeout_);
  }
  wait_for_answer("Factory Reset");
  return where() +
         (family_ == Family::dynamixel2 ? ": factory reset (id and baud rate kept)"
                                        : ": factory reset") +
         ", answers again";
}

}  // namespace animrt::commission
