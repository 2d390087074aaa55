#include "animrt/bridge/modbus/register_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "animrt/core/yaml_doc.hpp"

namespace animrt::modbus {
namespace {

constexpr int kMaxAddress = 65535;

Table parse_table(const YamlNode& node, bool input_allowed) {
  const std::string t = node.as_string();
  if (t == "holding") return Table::holding;
  if (t == "input" && input_allowed) return Table::input;
  node.fail(input_allowed ? "expected holding or input, found " + node.describe()
                          : "expected holding (a goal must be writable), found " + node.describe());
}

DataType parse_type(const YamlNode& node) {
  const std::string t = node.as_string();
  if (t == "int16") return DataType::int16;
  if (t == "uint16") return DataType::uint16;
  if (t == "int32") return DataType::int32;
  if (t == "uint32") return DataType::uint32;
  if (t == "float32") return DataType::float32;
  node.fail("unknown type " + node.describe() +
            " (expected int16, uint16, int32, uint32 or float32)");
}

Register parse_register(const YamlNode& node, bool input_allowed, bool scaled) {
  if (!node.is_map()) node.fail("expected a map, found " + node.describe());
  if (scaled) {
    node.allow_only({"table", "address", "type", "word_order", "scale", "offset"});
  } else {
    node.allow_only({"table", "address", "type", "codes"});
  }
  Register r;
  r.where = node.location();
  r.table = parse_table(node.at("table"), input_allowed);
  r.type = parse_type(node.at("type"));
  const YamlNode address = node.at("address");
  r.address = static_cast<int>(address.as_int_in(0, kMaxAddress));
  if (r.end() - 1 > kMaxAddress)
    address.fail("a 32-bit value cannot start at the last address 65535");
  if (auto n = node.find("word_order")) {
    if (r.words() == 1)
      n->fail("word_order applies to 32-bit types only, found type " +
              std::string(to_string(r.type)));
    const std::string o = n->as_string();
    if (o == "high_first") {
      r.order = WordOrder::high_first;
    } else if (o == "low_first") {
      r.order = WordOrder::low_first;
    } else {
      n->fail("expected high_first or low_first, found " + n->describe());
    }
  }
  if (scaled) {
    const YamlNode scale = node.at("scale");
    r.scale = scale.as_double();
    if (!(std::isfinite(r.scale) && r.scale != 0.0)) {
      scale.fail("expected a non-zero number (SI units per count), found " + scale.describe());
    }
    if (auto n = node.find("offset")) r.offset = n->as_double();
  } else if (r.type != DataType::int16 && r.type != DataType::uint16) {
    node.at("type").fail("a status register is int16 or uint16, found " +
                         node.at("type").describe());
  }
  return r;
}

std::string span_text(Table t, int begin, int end) {
  return std::string(to_string(t)) + " " + std::to_string(begin) +
         (end - begin > 1 ? ".." + std::to_string(end - 1) : "");
}

// A register the map uses, for the overlap check.
struct Named {
  const char* key;
  Table table;
  int begin, end;
  Location where;
};

// The status register and its fault bits.
void parse_status(const YamlNode& status, RegisterMap& map, std::vector<Named>& used) {
  if (!status.is_map()) status.fail("expected a map, found " + status.describe());
  status.allow_only({"table", "address", "type", "fault_bits"});
  // The register part, without the fault bits.
  map.has_status = true;
  map.status.where = status.location();
  map.status.table = parse_table(status.at("table"), true);
  map.status.type = parse_type(status.at("type"));
  if (map.status.words() != 1) {
    status.at("type").fail("a status register is int16 or uint16, found " +
                           status.at("type").describe());
  }
  map.status.address = static_cast<int>(status.at("address").as_int_in(0, kMaxAddress));
  if (auto bits = status.find("fault_bits")) {
    for (const auto& [key, value] : bits->entries()) {
      int bit = -1;
      try {
        std::size_t used_chars = 0;
        bit = std::stoi(key, &used_chars);
        if (used_chars != key.size()) bit = -1;
      } catch (...) {
        bit = -1;
      }
      if (bit < 0 || bit > 15)
        value.fail("expected a bit number 0..15 as the key, found " + quote(key));
      map.faults.push_back(FaultBit{bit, value.as_string()});
      map.fault_mask = static_cast<std::uint16_t>(map.fault_mask | (1u << bit));
    }
  }
  used.push_back(
      {"status", map.status.table, map.status.address, map.status.end(), map.status.where});
}

// fault_code.codes: {CODE: name}, codes decimal or 0x hexadecimal.
void parse_codes(const YamlNode& codes, std::vector<FaultCode>& out) {
  if (!codes.is_map()) codes.fail("expected a map of code: name, found " + codes.describe());
  for (const auto& [key, value] : codes.entries()) {
    long code = -1;
    try {
      std::size_t used_chars = 0;
      code = std::stol(key, &used_chars, 0);
      if (used_chars != key.size()) code = -1;
    } catch (...) {
      code = -1;
    }
    if (code <= 0 || code > 65535)
      value.fail("expected a fault code 1..65535 (decimal or 0x hex) as the key, found " +
                 quote(key));
    out.push_back(FaultCode{static_cast<std::uint16_t>(code), value.as_string()});
  }
}

// The registers the drive reports its health in.
void parse_health(const YamlNode& health, RegisterMap& map, std::vector<Named>& used) {
  if (!health.is_map()) health.fail("expected a map, found " + health.describe());
  health.allow_only({"current", "temperature", "voltage", "fault_code"});
  HealthRegisters& h = map.health;
  h.where = health.location();
  if (auto n = health.find("current")) h.current = parse_register(*n, true, true);
  if (auto n = health.find("temperature")) h.temperature = parse_register(*n, true, true);
  if (auto n = health.find("voltage")) h.voltage = parse_register(*n, true, true);
  if (auto n = health.find("fault_code")) {
    h.fault_code = parse_register(*n, true, false);
    if (auto codes = n->find("codes")) parse_codes(*codes, h.codes);
  }
  if (!h.any()) health.fail("expected at least one of current, temperature, voltage, fault_code");
  static constexpr const char* kKeys[] = {"health.current", "health.temperature", "health.voltage",
                                          "health.fault_code"};
  const std::optional<Register>* regs[] = {&h.current, &h.temperature, &h.voltage, &h.fault_code};
  for (std::size_t k = 0; k < 4; ++k) {
    if (*regs[k])
      used.push_back(
          {kKeys[k], (*regs[k])->table, (*regs[k])->address, (*regs[k])->end(), (*regs[k])->where});
  }
}

// The coil or register that switches the drive on and off.
void parse_enable(const YamlNode& enable, RegisterMap& map, std::vector<Named>& used) {
  if (!enable.is_map()) enable.fail("expected a map, found " + enable.describe());
  enable.allow_only({"coil", "register", "on", "off"});
  Enable& e = map.enable;
  e.configured = true;
  e.where = enable.location();
  const auto coil = enable.find("coil");
  const auto reg = enable.find("register");
  if (coil && reg) reg->fail("give either coil or register, not both");
  if (!coil && !reg) enable.fail("missing key coil or register");
  e.coil = coil.has_value();
  e.address = static_cast<int>((coil ? *coil : *reg).as_int_in(0, kMaxAddress));
  const std::int64_t top = e.coil ? 1 : 65535;
  if (auto n = enable.find("on")) e.on = static_cast<std::uint16_t>(n->as_int_in(0, top));
  if (auto n = enable.find("off")) e.off = static_cast<std::uint16_t>(n->as_int_in(0, top));
  if (e.on == e.off)
    enable.at("on").fail("on and off must differ, both are " + std::to_string(e.on));
  if (!e.coil) used.push_back({"enable", Table::holding, e.address, e.address + 1, e.where});
}

// The drive's own guard against a dead host.
void parse_watchdog(const YamlNode& watchdog, RegisterMap& map, std::vector<Named>& used) {
  if (!watchdog.is_map()) watchdog.fail("expected a map, found " + watchdog.describe());
  watchdog.allow_only({"register", "unit_ms"});
  Watchdog& w = map.watchdog;
  w.configured = true;
  w.where = watchdog.location();
  w.address = static_cast<int>(watchdog.at("register").as_int_in(0, kMaxAddress));
  if (auto n = watchdog.find("unit_ms")) w.unit_ms = n->as_double_in(0.001, 60000.0);
  used.push_back({"watchdog", Table::holding, w.address, w.address + 1, w.where});
}

void parse_range(const YamlNode& range, RegisterMap& map) {
  range.allow_only({"min", "max"});
  map.has_range = true;
  map.range_min = range.at("min").as_double();
  const YamlNode max = range.at("max");
  map.range_max = max.as_double();
  if (!(map.range_max > map.range_min)) {
    max.fail("expected a value greater than min (" + format_number(map.range_min) + "), found " +
             max.describe());
  }
}

// Two registers of one table that share an address are refused.
void check_overlaps(const std::vector<Named>& used) {
  for (std::size_t i = 0; i < used.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const Named& a = used[j];
      const Named& b = used[i];
      if (a.table == b.table && a.begin < b.end && b.begin < a.end) {
        throw InputError(b.where, b.key,
                         "registers overlap: " + std::string(b.key) + " (" +
                             span_text(b.table, b.begin, b.end) + ") overlaps " + a.key + " (" +
                             span_text(a.table, a.begin, a.end) + ")");
      }
    }
  }
}

std::shared_ptr<const RegisterMap> parse(const YamlNode& root) {
  root.allow_only(
      {"name", "unit", "goal", "present", "status", "health", "enable", "watchdog", "range"});
  auto map = std::make_shared<RegisterMap>();
  map->file = root.file();
  map->name = root.get_string("name", "");
  const YamlNode unit = root.at("unit");
  map->unit = unit.as_string();
  if (map->unit != "rad" && map->unit != "m")
    unit.fail("expected rad or m, found " + unit.describe());
  map->goal = parse_register(root.at("goal"), false, true);
  map->present = parse_register(root.at("present"), true, true);

  std::vector<Named> used{
      {"goal", map->goal.table, map->goal.address, map->goal.end(), map->goal.where},
      {"present", map->present.table, map->present.address, map->present.end(),
       map->present.where}};
  if (auto status = root.find("status")) parse_status(*status, *map, used);
  if (auto health = root.find("health")) parse_health(*health, *map, used);
  if (auto enable = root.find("enable")) parse_enable(*enable, *map, used);
  if (auto watchdog = root.find("watchdog")) parse_watchdog(*watchdog, *map, used);
  if (auto range = root.find("range")) parse_range(*range, *map);
  check_overlaps(used);
  return map;
}

}  // namespace

const char* to_string(Table table) { return table == Table::holding ? "holding" : "input"; }

const char* to_string(DataType type) {
  switch (type) {
    case DataType::int16:
      return "int16";
    case DataType::uint16:
      return "uint16";
    case DataType::int32:
      return "int32";
    case DataType::uint32:
      return "uint32";
    case DataType::float32:
      return "float32";
  }
  return "?";
}

double Register::decode(const std::uint16_t* w) const {
  double raw = 0.0;
  if (words() == 1) {
    raw = type == DataType::int16 ? static_cast<double>(static_cast<std::int16_t>(w[0]))
                                  : static_cast<double>(w[0]);
  } else {
    const std::uint32_t hi = order == WordOrder::high_first ? w[0] : w[1];
    const std::uint32_t lo = order == WordOrder::high_first ? w[1] : w[0];
    const std::uint32_t bits = (hi << 16) | lo;
    if (type == DataType::int32) {
      raw = static_cast<double>(static_cast<std::int32_t>(bits));
    } else if (type == DataType::uint32) {
      raw = static_cast<double>(bits);
    } else {
      float f;
      std::memcpy(&f, &bits, sizeof f);
      raw = static_cast<double>(f);
    }
  }
  return raw * scale + offset;
}

void Register::encode(double si, std::uint16_t* w) const {
  const double raw = (si - offset) / scale;
  std::uint32_t bits = 0;
  switch (type) {
    case DataType::int16:
      w[0] = static_cast<std::uint16_t>(
          static_cast<std::int16_t>(std::clamp(std::round(raw), -32768.0, 32767.0)));
      return;
    case DataType::uint16:
      w[0] = static_cast<std::uint16_t>(std::clamp(std::round(raw), 0.0, 65535.0));
      return;
    case DataType::int32:
      bits = static_cast<std::uint32_t>(
          static_cast<std::int32_t>(std::clamp(std::round(raw), -2147483648.0, 2147483647.0)));
      break;
    case DataType::uint32:
      bits = static_cast<std::uint32_t>(std::clamp(std::round(raw), 0.0, 4294967295.0));
      break;
    case DataType::float32: {
      const float f = static_cast<float>(raw);
      std::memcpy(&bits, &f, sizeof bits);
      break;
    }
  }
  const auto hi = static_cast<std::uint16_t>(bits >> 16);
  const auto lo = static_cast<std::uint16_t>(bits & 0xFFFF);
  w[0] = order == WordOrder::high_first ? hi : lo;
  w[1] = order == WordOrder::high_first ? lo : hi;
}

std::string RegisterMap::fault_text(std::uint16_t value) const {
  std::string out;
  for (const FaultBit& f : faults) {
    if (value & (1u << f.bit)) out += (out.empty() ? "" : ", ") + f.name;
  }
  return out;
}

std::string HealthRegisters::code_name(std::uint32_t code) const {
  for (const FaultCode& c : codes) {
    if (c.code == code) return c.name;
  }
  return {};
}

std::vector<const Register*> HealthRegisters::list() const {
  std::vector<const Register*> out;
  for (const std::optional<Register>* r : {&current, &temperature, &voltage, &fault_code}) {
    if (*r) out.push_back(&**r);
  }
  return out;
}

std::vector<std::pair<Table, std::pair<int, int>>> RegisterMap::spans() const {
  std::vector<std::pair<Table, std::pair<int, int>>> out{
      {goal.table, {goal.address, goal.end()}}, {present.table, {present.address, present.end()}}};
  if (has_status) out.push_back({status.table, {status.address, status.end()}});
  for (const Register* r : health.list()) out.push_back({r->table, {r->address, r->end()}});
  if (enable.configured && !enable.coil)
    out.push_back({Table::holding, {enable.address, enable.address + 1}});
  if (watchdog.configured)
    out.push_back({Table::holding, {watchdog.address, watchdog.address + 1}});
  return out;
}

std::shared_ptr<const RegisterMap> load_register_map(const std::string& path) {
  return parse(YamlNode::load_file(path));
}

std::shared_ptr<const RegisterMap> load_register_map_text(const std::string& text,
                                                          const std::string& file_name) {
  return parse(YamlNode::load_string(text, file_name));
}

}  // namespace animrt::modbus
