// Reading, checking and writing gait files (format: configs/gaits/walk.yaml).

#include "animrt/controllers/gait/gait_file.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/controllers/gait/froude.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

constexpr double kMaxScale = 100.0;
constexpr double kMaxOffsetDeg = 3600.0;
// Walking gaits stay well below Fr 1 in this convention; beyond 10 is a typo.
constexpr double kMaxFroude = 10.0;
constexpr double kMaxTurnDps = 3600.0;

// Plausible ranges of the timing and size keys (docs/gait.md lists them).
// A stride beyond 10 Hz reverses each joint 20 times a second, faster than
// any hobby or industrial servo follows and than any animal steps; one
// stride in more than 1000 s is a pose held, not a gait.
constexpr double kMinStrideHz = 0.001;
constexpr double kMaxStrideHz = 10.0;
// From a 1 cm toy to a 10 m figure, taller at the hip than any animal.
constexpr double kMinHipHeightM = 0.01;
constexpr double kMaxHipHeightM = 10.0;
constexpr double kMinTrackWidthM = 0.001;
constexpr double kMaxTrackWidthM = 10.0;
// Five times gravity: more than any legged animal's start (about 13 m/s^2
// for a cheetah), far more than a walking figure can take.
constexpr double kMaxAccelerationMs2 = 50.0;

// A curve must be finite over one stride; it is sampled this many times.
constexpr int kFiniteSamples = 1024;

std::string join_names(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? std::string("none") : out;
}

std::string shortest_exact(double v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  (void)ec;  // 32 bytes always hold a double
  return std::string(buf, end);
}

// Throws if the compiled curve is not finite somewhere on [0, 1).
void check_finite(const Expression& curve, const std::function<void(const std::string&)>& fail) {
  for (int i = 0; i < kFiniteSamples; ++i) {
    const double t = static_cast<double>(i) / kFiniteSamples;  // exact binary fractions
    const double v = curve.eval(t);
    if (!std::isfinite(v)) {
      fail("curve is not finite at t = " + shortest_exact(t) + " stride cycles (value " +
           (std::isnan(v) ? std::string("nan") : shortest_exact(v)) +
           "); it must be finite over the whole stride");
    }
  }
}

// ---- positions of expression characters inside the YAML file ----

// The 0-based offset in `text` of the start of 1-based `line`, or npos.
std::size_t line_start(const std::string& text, int line) {
  std::size_t pos = 0;
  for (int l = 1; l < line; ++l) {
    pos = text.find('\n', pos);
    if (pos == std::string::npos) return pos;
    ++pos;
  }
  return pos;
}

// Where the scalar's characters begin and how to walk them: yaml-cpp marks a
// quoted scalar at its opening quote.
struct ScalarSource {
  std::size_t begin = std::string::npos;  // offset in the file text of the first character
  char quote = 0;                         // '"', '\'' or 0 (plain)
  int line = 0;                           // 1-based
  int column = 0;                         // 1-based column of `begin`
};

ScalarSource scalar_source(const std::string& text, const Location& mark) {
  ScalarSource src;
  const std::size_t ls = line_start(text, mark.line);
  if (ls == std::string::npos || mark.column <= 0) return src;
  const std::size_t at = ls + static_cast<std::size_t>(mark.column - 1);
  if (at >= text.size()) return src;
  const char c = text[at];
  if (c == '|' || c == '>') return src;  // block scalars start on the next line
  src.quote = (c == '"' || c == '\'') ? c : 0;
  src.begin = src.quote ? at + 1 : at;
  src.line = mark.line;
  src.column = mark.column + (src.quote ? 1 : 0);
  return src;
}

// The file column of the expression's 1-based `expr_column`, when the
// scalar's text up to there is on one line and free of escapes (so one
// expression character is one file character); otherwise nullopt.
std::optional<int> file_column(const std::string& text, const ScalarSource& src,
                               const std::string& expression, int expr_column) {
  if (src.begin == std::string::npos) return std::nullopt;
  std::size_t pos = src.begin;
  for (int i = 1; i < expr_column; ++i) {
    if (pos >= text.size() || text[pos] == '\n' || text[pos] == '\r') return std::nullopt;
    if (src.quote == '"' && text[pos] == '\\') return std::nullopt;
    if (src.quote == '\'' && text[pos] == '\'') return std::nullopt;  // '' is one quote
    if (static_cast<std::size_t>(i - 1) < expression.size() &&
        text[pos] != expression[static_cast<std::size_t>(i - 1)]) {
      return std::nullopt;  // folded or otherwise transformed text
    }
    ++pos;
  }
  return src.column + (expr_column - 1);
}

[[noreturn]] void throw_expression_error(const ExpressionError& e, const std::string& text,
                                         const YamlNode& node, const std::string& expression) {
  const Location mark = node.location();
  const ScalarSource src = scalar_source(text, mark);
  const auto col = file_column(text, src, expression, e.column());
  std::string message = e.detail();
  if (e.related_column() > 0) {
    const auto related = file_column(text, src, expression, e.related_column());
    message += related ? " at column " + std::to_string(*related)
                       : " at column " + std::to_string(e.related_column()) + " of the expression";
  }
  if (col) throw InputError(Location{mark.file, src.line, *col}, node.path(), message);
  // Multi-line or escaped text: point at the scalar and say where inside.
  throw InputError(mark, node.path(),
                   message + " (column " + std::to_string(e.column()) + " of the expression)");
}

// ---- reading ----

// Marks of a map's keys, in order (YamlNode::entries() gives the values').
std::vector<Location> key_locations(const YamlNode& map) {
  std::vector<Location> out;
  for (auto it = map.raw().begin(); it != map.raw().end(); ++it) {
    const YAML::Mark m = it->first.Mark();
    out.push_back(m.is_null() ? map.location() : Location{map.file(), m.line + 1, m.column + 1});
  }
  return out;
}

// A number > 0 (the usual message below that) within lo..hi.
double positive_in(const YamlNode& node, double lo, double hi) {
  const double v = node.as_positive_double();
  if (v < lo || v > hi) {
    node.fail("expected a number from " + format_number(lo) + " to " + format_number(hi) +
              ", found " + node.describe());
  }
  return v;
}

int read_sign(const YamlNode& node) {
  const double v = node.as_double();
  if (v != 1.0 && v != -1.0) node.fail("expected 1 or -1, found " + quote(node.as_string()));
  return v > 0 ? 1 : -1;
}

void read_timing(const YamlNode& root, GaitFile& gait) {
  const auto freq = root.find("stride_frequency_hz");
  const auto froude = root.find("froude");
  if (freq && froude) {
    froude->fail("give exactly one of stride_frequency_hz or froude, not both");
  }
  if (!freq && !froude) {
    throw InputError(root.location(), "",
                     "missing stride timing: give exactly one of stride_frequency_hz or froude");
  }
  if (freq) {
    gait.stride_frequency_hz = positive_in(*freq, kMinStrideHz, kMaxStrideHz);
    return;
  }
  froude->allow_only({"number", "hip_height_m"});
  FroudeTiming timing;
  timing.number = positive_in(froude->at("number"), 1e-6, kMaxFroude);
  timing.hip_height_m = positive_in(froude->at("hip_height_m"), kMinHipHeightM, kMaxHipHeightM);
  // Both in range can still give a stride no figure can follow (Fr 10 at
  // 1 cm is 34 Hz).
  const double f = froude_stride_frequency(timing.number, timing.hip_height_m);
  if (f < kMinStrideHz || f > kMaxStrideHz) {
    froude->fail("number " + format_number(timing.number) + " at hip_height_m " +
                 format_number(timing.hip_height_m) + " is a stride frequency of " +
                 format_number(f) + " Hz, expected " + format_number(kMinStrideHz) + " to " +
                 format_number(kMaxStrideHz) + " Hz");
  }
  gait.froude = timing;
}

// Larger gains than this move a leg by more than it is long for a small tilt.
constexpr double kMaxBalanceGain = 2.0;

void read_balance(const YamlNode& root, GaitFile& gait) {
  const auto node = root.find("balance");
  if (!node) return;
  node->allow_only({"tilt_m", "tilt_rate_m_s"});
  GaitBalance b;
  b.where = node->location();
  if (auto v = node->find("tilt_m")) b.tilt_m = v->as_double_in(0.0, kMaxBalanceGain);
  if (auto v = node->find("tilt_rate_m_s")) {
    b.tilt_rate_m_s = v->as_double_in(0.0, kMaxBalanceGain);
  }
  if (b.tilt_m == 0.0 && b.tilt_rate_m_s == 0.0) {
    node->fail("give tilt_m or tilt_rate_m_s above 0 (or leave balance out)");
  }
  gait.balance = b;
}

void read_curves(const YamlNode& root, const std::string& text, GaitFile& gait) {
  const YamlNode curves = root.at("curves");
  const auto entries = curves.entries();
  for (const auto& entry : entries) {
    const YamlNode& node = entry.second;  // not a structured binding: lambdas capture it
    GaitCurve curve;
    curve.name = entry.first;
    curve.expression = node.as_string();
    const ScalarSource src = scalar_source(text, node.location());
    curve.where = src.begin == std::string::npos ? node.location()
                                                 : Location{node.file(), src.line, src.column};
    Expression compiled;
    try {
      compiled = Expression::compile(curve.expression);
    } catch (const ExpressionError& e) {
      throw_expression_error(e, text, node, curve.expression);
    }
    check_finite(compiled, [&](const std::string& message) {
      throw InputError(curve.where, node.path(), message);
    });
    gait.curves.push_back(std::move(curve));
  }
}

void read_limbs(const YamlNode& root, GaitFile& gait) {
  const YamlNode limbs = root.at("limbs");
  const auto locations = key_locations(limbs);
  const auto entries = limbs.entries();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    GaitLimb limb;
    limb.name = entries[i].first;
    limb.phase = entries[i].second.as_double_in(0.0, 1.0);
    limb.where = locations[i];
    gait.limbs.push_back(std::move(limb));
  }
}

std::vector<std::string> curve_names(const GaitFile& gait) {
  std::vector<std::string> out;
  for (const auto& c : gait.curves) out.push_back(c.name);
  return out;
}

std::vector<std::string> limb_names(const GaitFile& gait) {
  std::vector<std::string> out;
  for (const auto& l : gait.limbs) out.push_back(l.name);
  return out;
}

void read_joints(const YamlNode& root, GaitFile& gait) {
  const YamlNode joints = root.at("joints");
  const auto locations = key_locations(joints);
  const auto entries = joints.entries();
  if (entries.empty()) joints.fail("a gait needs at least one joint");
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const YamlNode& node = entries[i].second;
    node.allow_only({"curve", "limb", "sign", "scale", "offset_deg"});
    GaitJoint joint;
    joint.name = entries[i].first;
    joint.where = locations[i];
    const YamlNode curve = node.at("curve");
    joint.curve = curve.as_string();
    if (!gait.find_curve(joint.curve)) {
      curve.fail("undefined curve '" + elide(joint.curve) +
                 "' (curves: " + join_names(curve_names(gait)) + ")");
    }
    const YamlNode limb = node.at("limb");
    joint.limb = limb.as_string();
    if (!gait.find_limb(joint.limb)) {
      limb.fail("undefined limb '" + elide(joint.limb) +
                "' (limbs: " + join_names(limb_names(gait)) + ")");
    }
    if (auto sign = node.find("sign")) joint.sign = read_sign(*sign);
    // A curve is in degrees already: a scale beyond 100 or an offset beyond
    // ten turns is a typo, not a gait.
    if (auto n = node.find("scale")) joint.scale = n->as_double_in(-kMaxScale, kMaxScale);
    if (auto n = node.find("offset_deg"))
      joint.offset_deg = n->as_double_in(-kMaxOffsetDeg, kMaxOffsetDeg);
    gait.joints.push_back(std::move(joint));
  }
}

// Names in a list, each once.
std::vector<std::string> read_names(const YamlNode& list) {
  if (!list.is_sequence()) list.fail("expected a list of names, found " + list.describe());
  std::vector<std::string> out;
  for (const YamlNode& item : list.items()) {
    std::string name = item.as_string();
    for (const auto& seen : out) {
      if (seen == name) item.fail("'" + elide(name) + "' is listed twice");
    }
    out.push_back(std::move(name));
  }
  return out;
}

void read_steering(const YamlNode& root, GaitFile& gait) {
  const auto node = root.find("steering");
  if (!node) return;
  node->allow_only({"min_froude", "max_froude", "max_turn_dps", "max_acceleration_m_s2",
                    "hip_height_m", "track_width_m", "sides", "yaw_joints", "lift_curves",
                    "swing_offset", "fixed_cadence", "turn_on_the_spot", "spot_track_width_m",
                    "spot_swing_offset"});
  GaitSteering s;
  s.where = node->location();
  const YamlNode min_fr = node->at("min_froude");
  s.min_froude = min_fr.as_double_in(1e-6, kMaxFroude);
  const YamlNode max_fr = node->at("max_froude");
  s.max_froude = max_fr.as_double_in(1e-6, kMaxFroude);
  if (s.max_froude < s.min_froude) {
    max_fr.fail("max_froude (" + shortest_exact(s.max_froude) + ") is below min_froude (" +
                shortest_exact(s.min_froude) + ")");
  }
  s.max_turn_rad_s = deg_to_rad(node->at("max_turn_dps").as_double_in(0.0, kMaxTurnDps));
  s.max_acceleration_m_s2 =
      positive_in(node->at("max_acceleration_m_s2"), 1e-6, kMaxAccelerationMs2);
  if (const auto h = node->find("hip_height_m")) {
    s.hip_height_m = positive_in(*h, kMinHipHeightM, kMaxHipHeightM);
  } else if (gait.froude) {
    s.hip_height_m = gait.froude->hip_height_m;
  } else {
    node->at("hip_height_m");  // throws: required with stride_frequency_hz
  }
  s.track_width_m = positive_in(node->at("track_width_m"), kMinTrackWidthM, kMaxTrackWidthM);
  const YamlNode sides = node->at("sides");
  sides.allow_only({"left", "right"});
  for (const char* side : {"left", "right"}) {
    const YamlNode list = sides.at(side);
    std::vector<std::string> names = read_names(list);
    if (names.empty()) list.fail("expected at least one limb");
    const auto items = list.items();
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (!gait.find_limb(names[i])) {
        items[i].fail("undefined limb '" + elide(names[i]) +
                      "' (limbs: " + join_names(limb_names(gait)) + ")");
      }
      for (const auto& l : s.left) {
        if (l == names[i]) items[i].fail("limb '" + elide(names[i]) + "' is on both sides");
      }
    }
    (side[0] == 'l' ? s.left : s.right) = std::move(names);
  }
  if (const auto yaw = node->find("yaw_joints")) {
    s.yaw_joints = read_names(*yaw);
    const auto items = yaw->items();
    for (std::size_t i = 0; i < s.yaw_joints.size(); ++i) {
      bool mapped = false;
      for (const auto& j : gait.joints) mapped = mapped || j.name == s.yaw_joints[i];
      if (!mapped) {
        items[i].fail("yaw joint '" + elide(s.yaw_joints[i]) +
                      "' is not one of the gait's joints (map it under joints)");
      }
    }
  }
  if (const auto off = node->find("swing_offset")) s.swing_offset = off->as_double_in(-5.0, 0.9);
  if (const auto fixed = node->find("fixed_cadence")) s.fixed_cadence = fixed->as_bool();
  if (const auto spot = node->find("turn_on_the_spot")) s.turn_on_the_spot = spot->as_bool();
  s.spot_swing_offset = s.swing_offset;
  if (const auto off = node->find("spot_swing_offset"))
    s.spot_swing_offset = off->as_double_in(-5.0, 0.9);
  s.spot_track_width_m = s.track_width_m;
  if (const auto w = node->find("spot_track_width_m"))
    s.spot_track_width_m = positive_in(*w, kMinTrackWidthM, kMaxTrackWidthM);
  if (const auto lift = node->find("lift_curves")) {
    s.lift_curves = read_names(*lift);
    const auto items = lift->items();
    for (std::size_t i = 0; i < s.lift_curves.size(); ++i) {
      bool defined = false;
      for (const auto& c : gait.curves) defined = defined || c.name == s.lift_curves[i];
      if (!defined) items[i].fail("undefined curve '" + elide(s.lift_curves[i]) + "'");
    }
  }
  gait.steering = std::move(s);
}

// ---- writing ----

bool needs_quotes(const std::string& s) {
  if (s.empty()) return true;
  static const char* const kSpecial[] = {"null", "true", "false", "yes", "no",
                                         "on",   "off",  "y",     "n"};
  std::string lower;
  for (char c : s) lower += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  for (const char* w : kSpecial) {
    if (lower == w) return true;
  }
  const auto plain = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  };
  if (s[0] >= '0' && s[0] <= '9') return true;
  for (char c : s) {
    if (!plain(c)) return true;
  }
  return false;
}

std::string double_quoted(const std::string& s) {
  static const char kHex[] = "0123456789abcdef";
  std::string out = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7f) {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string name_text(const std::string& s) { return needs_quotes(s) ? double_quoted(s) : s; }

void validate_steering(const GaitFile& gait) {
  if (!gait.steering) return;
  const GaitSteering& s = *gait.steering;
  const Location at = s.where.line > 0 ? s.where : Location{gait.file, 0, 0};
  const auto fail = [&](const std::string& key, const std::string& message) {
    throw InputError(at, "steering." + key, message);
  };
  const auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };
  if (!in(s.min_froude, 1e-6, kMaxFroude)) fail("min_froude", "expected a number from 1e-06 to 10");
  if (!in(s.max_froude, s.min_froude, kMaxFroude))
    fail("max_froude", "expected a number from min_froude to 10");
  if (!in(s.max_turn_rad_s, 0.0, deg_to_rad(kMaxTurnDps)))
    fail("max_turn_dps", "expected a number from 0 to 3600");
  const auto range = [](double lo, double hi) {
    return "expected a number from " + format_number(lo) + " to " + format_number(hi);
  };
  if (!in(s.max_acceleration_m_s2, 1e-6, kMaxAccelerationMs2))
    fail("max_acceleration_m_s2", range(1e-6, kMaxAccelerationMs2));
  if (!in(s.hip_height_m, kMinHipHeightM, kMaxHipHeightM))
    fail("hip_height_m", range(kMinHipHeightM, kMaxHipHeightM));
  if (!in(s.track_width_m, kMinTrackWidthM, kMaxTrackWidthM))
    fail("track_width_m", range(kMinTrackWidthM, kMaxTrackWidthM));
  if (s.left.empty() || s.right.empty()) fail("sides", "each side needs at least one limb");
  for (const auto* side : {&s.left, &s.right}) {
    for (std::size_t i = 0; i < side->size(); ++i) {
      const std::string& limb = (*side)[i];
      if (!gait.find_limb(limb)) fail("sides", "undefined limb '" + elide(limb) + "'");
      for (std::size_t k = 0; k < i; ++k) {
        if ((*side)[k] == limb) fail("sides", "limb '" + elide(limb) + "' is listed twice");
      }
    }
  }
  for (const auto& l : s.left) {
    for (const auto& r : s.right) {
      if (l == r) fail("sides", "limb '" + elide(l) + "' is on both sides");
    }
  }
  for (const auto& y : s.yaw_joints) {
    bool mapped = false;
    for (const auto& j : gait.joints) mapped = mapped || j.name == y;
    if (!mapped) fail("yaw_joints", "yaw joint '" + elide(y) + "' is not one of the gait's joints");
  }
  if (!in(s.swing_offset, -5.0, 0.9)) fail("swing_offset", "expected a number from -5 to 0.9");
  if (!in(s.spot_swing_offset, -5.0, 0.9))
    fail("spot_swing_offset", "expected a number from -5 to 0.9");
  if (s.spot_track_width_m != 0.0 && !in(s.spot_track_width_m, kMinTrackWidthM, kMaxTrackWidthM))
    fail("spot_track_width_m", range(kMinTrackWidthM, kMaxTrackWidthM));
  for (const auto& c : s.lift_curves) {
    bool defined = false;
    for (const auto& gc : gait.curves) defined = defined || gc.name == c;
    if (!defined) fail("lift_curves", "undefined curve '" + elide(c) + "'");
  }
}

std::string names_text(const std::vector<std::string>& names) {
  std::string out = "[";
  for (const auto& n : names) out += (out.size() > 1 ? ", " : "") + name_text(n);
  return out + "]";
}

// Degrees/s that read back (deg_to_rad) to exactly `rad_s`.
double exact_dps(double rad_s) {
  double c = rad_to_deg(rad_s);
  for (int k = 0; k < 8 && deg_to_rad(c) != rad_s; ++k) {
    c = std::nextafter(c, deg_to_rad(c) < rad_s ? 1e300 : -1e300);
  }
  return c;
}

// Steering and the balance reflex are for a walk.
void validate_walks(const GaitFile& gait) {
  if (gait.walks) return;
  if (gait.steering) {
    throw InputError(gait.walks_where, "walks",
                     "a gait that does not walk cannot be steered: remove steering or walks");
  }
  if (gait.balance) {
    throw InputError(gait.walks_where, "walks",
                     "a gait that does not walk has no balance reflex: remove balance or walks");
  }
}

}  // namespace

double GaitFile::stride_frequency() const {
  if (stride_frequency_hz) return *stride_frequency_hz;
  if (froude) return froude_stride_frequency(froude->number, froude->hip_height_m);
  return 0.0;
}

const GaitCurve* GaitFile::find_curve(const std::string& curve_name) const {
  for (const auto& c : curves) {
    if (c.name == curve_name) return &c;
  }
  return nullptr;
}

const GaitLimb* GaitFile::find_limb(const std::string& limb_name) const {
  for (const auto& l : limbs) {
    if (l.name == limb_name) return &l;
  }
  return nullptr;
}

bool operator==(const GaitCurve& a, const GaitCurve& b) {
  return a.name == b.name && a.expression == b.expression;
}
bool operator==(const GaitLimb& a, const GaitLimb& b) {
  return a.name == b.name && a.phase == b.phase;
}
bool operator==(const GaitJoint& a, const GaitJoint& b) {
  return a.name == b.name && a.curve == b.curve && a.limb == b.limb && a.sign == b.sign &&
         a.scale == b.scale && a.offset_deg == b.offset_deg;
}
bool operator==(const FroudeTiming& a, const FroudeTiming& b) {
  return a.number == b.number && a.hip_height_m == b.hip_height_m;
}
bool operator==(const GaitFile& a, const GaitFile& b) {
  return a.name == b.name && a.stride_frequency_hz == b.stride_frequency_hz &&
         a.froude == b.froude && a.curves == b.curves && a.limbs == b.limbs &&
         a.joints == b.joints && a.steering == b.steering && a.balance == b.balance &&
         a.walks == b.walks;
}
bool operator==(const GaitBalance& a, const GaitBalance& b) {
  return a.tilt_m == b.tilt_m && a.tilt_rate_m_s == b.tilt_rate_m_s;
}

double GaitSteering::min_speed_m_s() const { return froude_velocity(min_froude, hip_height_m); }
double GaitSteering::max_speed_m_s() const { return froude_velocity(max_froude, hip_height_m); }

bool operator==(const GaitSteering& a, const GaitSteering& b) {
  return a.min_froude == b.min_froude && a.max_froude == b.max_froude &&
         a.max_turn_rad_s == b.max_turn_rad_s &&
         a.max_acceleration_m_s2 == b.max_acceleration_m_s2 && a.hip_height_m == b.hip_height_m &&
         a.track_width_m == b.track_width_m && a.left == b.left && a.right == b.right &&
         a.yaw_joints == b.yaw_joints && a.lift_curves == b.lift_curves &&
         a.swing_offset == b.swing_offset && a.fixed_cadence == b.fixed_cadence &&
         a.turn_on_the_spot == b.turn_on_the_spot && a.spot_track_width_m == b.spot_track_width_m &&
         a.spot_swing_offset == b.spot_swing_offset;
}

GaitFile parse_gait_file(const std::string& text, const std::string& file_name) {
  const YamlNode root = YamlNode::load_string(text, file_name);
  root.allow_only({"name", "stride_frequency_hz", "froude", "curves", "limbs", "joints", "steering",
                   "balance", "walks"});
  GaitFile gait;
  gait.file = file_name;
  const YamlNode name = root.at("name");
  gait.name = name.as_string();
  if (gait.name.empty()) name.fail("expected a non-empty name");
  read_timing(root, gait);
  read_curves(root, text, gait);
  read_limbs(root, gait);
  read_joints(root, gait);
  read_steering(root, gait);
  read_balance(root, gait);
  if (const auto walks = root.find("walks")) {
    gait.walks = walks->as_bool();
    gait.walks_where = walks->location();
  }
  validate_walks(gait);
  return gait;
}

GaitFile load_gait_file(const std::string& path) {
  return parse_gait_file(read_input_file(path, kMaxYamlFileBytes), path);
}

void validate_gait(const GaitFile& gait) {
  const Location top{gait.file, 0, 0};
  if (gait.name.empty()) throw InputError(top, "name", "expected a non-empty name");
  if (gait.stride_frequency_hz.has_value() == gait.froude.has_value()) {
    throw InputError(top, "", "give exactly one of stride_frequency_hz or froude");
  }
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (gait.stride_frequency_hz && !positive(*gait.stride_frequency_hz)) {
    throw InputError(
        top, "stride_frequency_hz",
        "expected a positive number, found " + shortest_exact(*gait.stride_frequency_hz));
  }
  if (gait.stride_frequency_hz &&
      !(*gait.stride_frequency_hz >= kMinStrideHz && *gait.stride_frequency_hz <= kMaxStrideHz)) {
    throw InputError(top, "stride_frequency_hz",
                     "expected a number from " + format_number(kMinStrideHz) + " to " +
                         format_number(kMaxStrideHz) + ", found " +
                         shortest_exact(*gait.stride_frequency_hz));
  }
  if (gait.froude && !(positive(gait.froude->number) && positive(gait.froude->hip_height_m))) {
    throw InputError(top, "froude", "number and hip_height_m must be positive");
  }
  if (gait.froude) {
    const FroudeTiming& f = *gait.froude;
    const double hz = froude_stride_frequency(f.number, f.hip_height_m);
    if (f.number > kMaxFroude || f.hip_height_m < kMinHipHeightM ||
        f.hip_height_m > kMaxHipHeightM || !(hz >= kMinStrideHz && hz <= kMaxStrideHz)) {
      throw InputError(top, "froude",
                       "expected number up to " + format_number(kMaxFroude) + ", hip_height_m " +
                           format_number(kMinHipHeightM) + " to " + format_number(kMaxHipHeightM) +
                           " and a stride frequency of " + format_number(kMinStrideHz) + " to " +
                           format_number(kMaxStrideHz) + " Hz");
    }
  }
  for (std::size_t i = 0; i < gait.curves.size(); ++i) {
    const GaitCurve& c = gait.curves[i];
    const std::string key = "curves." + c.name;
    for (std::size_t j = 0; j < i; ++j) {
      if (gait.curves[j].name == c.name) throw InputError(c.where, key, "duplicate curve");
    }
    Expression compiled;
    try {
      compiled = Expression::compile(c.expression);
    } catch (const ExpressionError& e) {
      throw InputError(
          c.where, key,
          e.message() + " (column " + std::to_string(e.column()) + " of the expression)");
    }
    check_finite(compiled, [&](const std::string& m) { throw InputError(c.where, key, m); });
  }
  for (std::size_t i = 0; i < gait.limbs.size(); ++i) {
    const GaitLimb& l = gait.limbs[i];
    const std::string key = "limbs." + l.name;
    for (std::size_t j = 0; j < i; ++j) {
      if (gait.limbs[j].name == l.name) throw InputError(l.where, key, "duplicate limb");
    }
    if (!(l.phase >= 0.0 && l.phase <= 1.0)) {
      throw InputError(l.where, key,
                       "expected a phase from 0 to 1, found " + shortest_exact(l.phase));
    }
  }
  if (gait.joints.empty()) throw InputError(top, "joints", "a gait needs at least one joint");
  for (std::size_t i = 0; i < gait.joints.size(); ++i) {
    const GaitJoint& j = gait.joints[i];
    const std::string key = "joints." + j.name;
    for (std::size_t k = 0; k < i; ++k) {
      if (gait.joints[k].name == j.name) throw InputError(j.where, key, "duplicate joint");
    }
    if (!gait.find_curve(j.curve)) {
      throw InputError(j.where, key + ".curve",
                       "undefined curve '" + elide(j.curve) +
                           "' (curves: " + join_names(curve_names(gait)) + ")");
    }
    if (!gait.find_limb(j.limb)) {
      throw InputError(
          j.where, key + ".limb",
          "undefined limb '" + elide(j.limb) + "' (limbs: " + join_names(limb_names(gait)) + ")");
    }
    if (j.sign != 1 && j.sign != -1) {
      throw InputError(j.where, key + ".sign", "expected 1 or -1, found " + std::to_string(j.sign));
    }
    if (!std::isfinite(j.scale) || !std::isfinite(j.offset_deg)) {
      throw InputError(j.where, key, "scale and offset_deg must be finite");
    }
    if (std::abs(j.scale) > kMaxScale) {
      throw InputError(j.where, key + ".scale",
                       "expected a number from -100 to 100, found " + format_number(j.scale));
    }
    if (std::abs(j.offset_deg) > kMaxOffsetDeg) {
      throw InputError(
          j.where, key + ".offset_deg",
          "expected a number from -3600 to 3600, found " + format_number(j.offset_deg));
    }
  }
  validate_steering(gait);
  validate_walks(gait);
  if (gait.balance) {
    const GaitBalance& b = *gait.balance;
    const auto gain = [](double v) { return std::isfinite(v) && v >= 0.0 && v <= kMaxBalanceGain; };
    if (!gain(b.tilt_m) || !gain(b.tilt_rate_m_s) || (b.tilt_m == 0.0 && b.tilt_rate_m_s == 0.0)) {
      throw InputError(b.where, "balance",
                       "expected tilt_m and tilt_rate_m_s from 0 to 2, not both 0");
    }
  }
}

std::string format_gait_file(const GaitFile& gait) {
  std::string out;
  out += "# Gait file written by animrt (format: configs/gaits/walk.yaml).\n";
  out += "name: " + double_quoted(gait.name) + "\n";
  if (gait.stride_frequency_hz) {
    out += "stride_frequency_hz: " + shortest_exact(*gait.stride_frequency_hz) + "\n";
  }
  if (gait.froude) {
    out += "froude: {number: " + shortest_exact(gait.froude->number) +
           ", hip_height_m: " + shortest_exact(gait.froude->hip_height_m) + "}\n";
  }
  out += gait.curves.empty() ? "curves: {}\n" : "curves:\n";
  for (const auto& c : gait.curves) {
    out += "  " + name_text(c.name) + ": " + double_quoted(c.expression) + "\n";
  }
  out += gait.limbs.empty() ? "limbs: {}\n" : "limbs:\n";
  for (const auto& l : gait.limbs) {
    out += "  " + name_text(l.name) + ": " + shortest_exact(l.phase) + "\n";
  }
  out += gait.joints.empty() ? "joints: {}\n" : "joints:\n";
  for (const auto& j : gait.joints) {
    out += "  " + name_text(j.name) + ": {curve: " + name_text(j.curve) +
           ", limb: " + name_text(j.limb) + ", sign: " + std::to_string(j.sign) +
           ", scale: " + shortest_exact(j.scale) + ", offset_deg: " + shortest_exact(j.offset_deg) +
           "}\n";
  }
  if (gait.steering) {
    const GaitSteering& s = *gait.steering;
    out += "steering:\n";
    out += "  min_froude: " + shortest_exact(s.min_froude) + "\n";
    out += "  max_froude: " + shortest_exact(s.max_froude) + "\n";
    out += "  max_turn_dps: " + shortest_exact(exact_dps(s.max_turn_rad_s)) + "\n";
    out += "  max_acceleration_m_s2: " + shortest_exact(s.max_acceleration_m_s2) + "\n";
    out += "  hip_height_m: " + shortest_exact(s.hip_height_m) + "\n";
    out += "  track_width_m: " + shortest_exact(s.track_width_m) + "\n";
    out += "  sides: {left: " + names_text(s.left) + ", right: " + names_text(s.right) + "}\n";
    if (!s.yaw_joints.empty()) out += "  yaw_joints: " + names_text(s.yaw_joints) + "\n";
    if (!s.lift_curves.empty()) out += "  lift_curves: " + names_text(s.lift_curves) + "\n";
    if (s.swing_offset != 0.0) out += "  swing_offset: " + shortest_exact(s.swing_offset) + "\n";
    if (s.fixed_cadence) out += "  fixed_cadence: true\n";
    if (s.turn_on_the_spot) out += "  turn_on_the_spot: true\n";
    if (s.spot_track_width_m > 0.0 && s.spot_track_width_m != s.track_width_m)
      out += "  spot_track_width_m: " + shortest_exact(s.spot_track_width_m) + "\n";
    if (s.spot_swing_offset != s.swing_offset)
      out += "  spot_swing_offset: " + shortest_exact(s.spot_swing_offset) + "\n";
  }
  if (!gait.walks) out += "walks: false\n";
  if (gait.balance) {
    out += "balance: {tilt_m: " + shortest_exact(gait.balance->tilt_m) +
           ", tilt_rate_m_s: " + shortest_exact(gait.balance->tilt_rate_m_s) + "}\n";
  }
  return out;
}

void write_gait_file(const GaitFile& gait, const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  out << format_gait_file(gait);
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
}

}  // namespace animrt
