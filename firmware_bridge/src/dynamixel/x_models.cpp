#include "animrt/bridge/dynamixel/x_models.hpp"

#include <any>

namespace animrt::dxl {
namespace {

constexpr std::uint8_t kX430Fast = 45;  // X430 / X540 series
constexpr std::uint8_t kNever = 0;

constexpr XModel kModels[] = {
    {"XL430-W250", 1060, kX430Fast}, {"XC430-W150", 1070, kX430Fast},
    {"XC430-W240", 1080, kX430Fast}, {"XM430-W210", 1030, kX430Fast},
    {"XM430-W350", 1020, kX430Fast}, {"XH430-W210", 1010, kX430Fast},
    {"XH430-W350", 1000, kX430Fast}, {"XM540-W150", 1130, kX430Fast},
    {"XM540-W270", 1120, kX430Fast}, {"XH540-W150", 1110, kX430Fast},
    {"XH540-W270", 1100, kX430Fast}, {"2XL430-W250", 1090, kNever},
    {"2XC430-W250", 1160, kNever},
};

}  // namespace

std::span<const XModel> x_models() { return kModels; }

const XModel* find_x_model(std::string_view name) {
  for (const XModel& m : kModels) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

const XModel* find_x_model(std::uint16_t number) {
  for (const XModel& m : kModels) {
    if (m.number == number) return &m;
  }
  return nullptr;
}

std::string x_model_names() {
  std::string out;
  for (const XModel& m : kModels) {
    if (!out.empty()) out += ", ";
    out += m.name;
  }
  return out;
}

bool supports_fast_read(std::uint16_t model_number, std::uint8_t firmware) {
  const XModel* m = find_x_model(model_number);
  return m != nullptr && m->fast_read_firmware != kNever && firmware >= m->fast_read_firmware;
}

double current_unit_a(std::uint16_t model_number) {
  // Units from each model's control table: XH430 1.34 mA, XM430 / X540
  // 2.69 mA; XL430 and XC430 (and their dual versions) report Present Load.
  switch (model_number) {
    case 1010:
    case 1000:
      return 0.00134;
    case 1030:
    case 1020:
    case 1130:
    case 1120:
    case 1110:
    case 1100:
      return 0.00269;
    default:
      return 0.0;
  }
}

BusOptions bus_options(const BusConfig& bus) {
  if (const auto* o = std::any_cast<BusOptions>(&bus.options)) return *o;
  return {};
}

DeviceOptions device_options(const ActuatorBinding& binding) {
  if (const auto* o = std::any_cast<DeviceOptions>(&binding.options)) return *o;
  return {};
}

}  // namespace animrt::dxl
