#include "animrt/bridge/can/mit_codec.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace animrt::mit {
namespace {

// Manual v1.0.8, MIT mode parameter table: position +-12.5 rad, kp 0..500,
// kd 0..5 for every model; velocity and torque per model.
constexpr std::pair<std::string_view, Ranges> kModels[] = {
    {"ak10-9", {-12.5, 12.5, -50.0, 50.0, 0, 500, 0, 5, -65.0, 65.0}},
    {"ak60-6", {-12.5, 12.5, -45.0, 45.0, 0, 500, 0, 5, -15.0, 15.0}},
    {"ak70-10", {-12.5, 12.5, -50.0, 50.0, 0, 500, 0, 5, -25.0, 25.0}},
    {"ak80-6", {-12.5, 12.5, -76.0, 76.0, 0, 500, 0, 5, -12.0, 12.0}},
    {"ak80-9", {-12.5, 12.5, -50.0, 50.0, 0, 500, 0, 5, -18.0, 18.0}},
    {"ak80-64", {-12.5, 12.5, -8.0, 8.0, 0, 500, 0, 5, -144.0, 144.0}},
};

constexpr std::uint8_t kSpecialFill = 0xFF;

}  // namespace

const Ranges* find_model(std::string_view model) {
  for (const auto& [name, ranges] : kModels) {
    if (name == model) return &ranges;
  }
  return nullptr;
}

std::string supported_models() {
  std::string out;
  for (const auto& [name, ranges] : kModels) out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

std::uint32_t float_to_uint(double x, double min, double max, int bits) {
  const double full = static_cast<double>((1u << bits) - 1u);
  if (!(x > min)) return 0;  // also NaN
  if (x >= max) return static_cast<std::uint32_t>(full);
  // Truncation, as the vendor's float_to_uint (a cast to int).
  const double v = (x - min) * full / (max - min);
  return static_cast<std::uint32_t>(std::clamp(v, 0.0, full));
}

double uint_to_float(std::uint32_t value, double min, double max, int bits) {
  const double full = static_cast<double>((1u << bits) - 1u);
  return static_cast<double>(value) * (max - min) / full + min;
}

can_frame pack_command(canid_t motor_id, const Command& c, const Ranges& r) {
  const std::uint32_t p = float_to_uint(c.position, r.p_min, r.p_max, 16);
  const std::uint32_t v = float_to_uint(c.velocity, r.v_min, r.v_max, 12);
  const std::uint32_t kp = float_to_uint(c.kp, r.kp_min, r.kp_max, 12);
  const std::uint32_t kd = float_to_uint(c.kd, r.kd_min, r.kd_max, 12);
  const std::uint32_t t = float_to_uint(c.torque, r.t_min, r.t_max, 12);
  can_frame f{};
  f.can_id = motor_id;
  f.len = 8;
  f.data[0] = static_cast<std::uint8_t>(p >> 8);
  f.data[1] = static_cast<std::uint8_t>(p);
  f.data[2] = static_cast<std::uint8_t>(v >> 4);
  f.data[3] = static_cast<std::uint8_t>(((v & 0xF) << 4) | (kp >> 8));
  f.data[4] = static_cast<std::uint8_t>(kp);
  f.data[5] = static_cast<std::uint8_t>(kd >> 4);
  f.data[6] = static_cast<std::uint8_t>(((kd & 0xF) << 4) | (t >> 8));
  f.data[7] = static_cast<std::uint8_t>(t);
  return f;
}

bool unpack_command(const can_frame& f, const Ranges& r, Command& out) {
  if (f.len != 8 || (f.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0) return false;
  if (special_of(f) != Special::none) return false;
  const std::uint32_t p = (f.data[0] << 8) | f.data[1];
  const std::uint32_t v = (f.data[2] << 4) | (f.data[3] >> 4);
  const std::uint32_t kp = ((f.data[3] & 0xF) << 8) | f.data[4];
  const std::uint32_t kd = (f.data[5] << 4) | (f.data[6] >> 4);
  const std::uint32_t t = ((f.data[6] & 0xF) << 8) | f.data[7];
  out.position = uint_to_float(p, r.p_min, r.p_max, 16);
  out.velocity = uint_to_float(v, r.v_min, r.v_max, 12);
  out.kp = uint_to_float(kp, r.kp_min, r.kp_max, 12);
  out.kd = uint_to_float(kd, r.kd_min, r.kd_max, 12);
  out.torque = uint_to_float(t, r.t_min, r.t_max, 12);
  return true;
}

can_frame pack_reply(canid_t master_id, const Reply& reply, const Ranges& r) {
  const std::uint32_t p = float_to_uint(reply.position, r.p_min, r.p_max, 16);
  const std::uint32_t v = float_to_uint(reply.velocity, r.v_min, r.v_max, 12);
  const std::uint32_t t = float_to_uint(reply.torque, r.t_min, r.t_max, 12);
  can_frame f{};
  f.can_id = master_id;
  f.len = reply.extended ? 8 : 6;
  f.data[0] = reply.motor_id;
  f.data[1] = static_cast<std::uint8_t>(p >> 8);
  f.data[2] = static_cast<std::uint8_t>(p);
  f.data[3] = static_cast<std::uint8_t>(v >> 4);
  f.data[4] = static_cast<std::uint8_t>(((v & 0xF) << 4) | (t >> 8));
  f.data[5] = static_cast<std::uint8_t>(t);
  if (reply.extended) {
    f.data[6] = reply.temperature;
    f.data[7] = reply.error;
  }
  return f;
}

bool unpack_reply(const can_frame& f, const Ranges& r, Reply& out) {
  if ((f.len != 6 && f.len != 8) || (f.can_id & (CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0) return false;
  const std::uint32_t p = (f.data[1] << 8) | f.data[2];
  const std::uint32_t v = (f.data[3] << 4) | (f.data[4] >> 4);
  const std::uint32_t t = ((f.data[4] & 0xF) << 8) | f.data[5];
  out.motor_id = f.data[0];
  out.position = uint_to_float(p, r.p_min, r.p_max, 16);
  out.velocity = uint_to_float(v, r.v_min, r.v_max, 12);
  out.torque = uint_to_float(t, r.t_min, r.t_max, 12);
  out.extended = f.len == 8;
  out.temperature = out.extended ? f.data[6] : 0;
  out.error = out.extended ? f.data[7] : 0;
  return true;
}

can_frame special_frame(canid_t motor_id, Special which) {
  can_frame f{};
  f.can_id = motor_id;
  f.len = 8;
  for (int i = 0; i < 7; ++i) f.data[i] = kSpecialFill;
  switch (which) {
    case Special::enter_motor_mode:
      f.data[7] = 0xFC;
      break;
    case Special::exit_motor_mode:
      f.data[7] = 0xFD;
      break;
    case Special::set_zero:
      f.data[7] = 0xFE;
      break;
    case Special::none:
      f.data[7] = 0x00;
      break;
  }
  return f;
}

Special special_of(const can_frame& f) {
  if (f.len != 8) return Special::none;
  for (int i = 0; i < 7; ++i) {
    if (f.data[i] != kSpecialFill) return Special::none;
  }
  switch (f.data[7]) {
    case 0xFC:
      return Special::enter_motor_mode;
    case 0xFD:
      return Special::exit_motor_mode;
    case 0xFE:
      return Special::set_zero;
    default:
      return Special::none;
  }
}

}  // namespace animrt::mit
