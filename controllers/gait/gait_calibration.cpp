// Reading and writing walk calibration tables (format: docs/gait.md).

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "animrt/controllers/gait/walk_response.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

std::string shortest(double v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  (void)ec;
  return std::string(buf, end);
}

// Degrees/s that read back (deg_to_rad) to exactly `rad_s`.
std::string dps_text(double rad_s) {
  double c = rad_to_deg(rad_s);
  for (int k = 0; k < 8 && deg_to_rad(c) != rad_s; ++k) {
    c = std::nextafter(c, deg_to_rad(c) < rad_s ? 1e300 : -1e300);
  }
  return shortest(c);
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// Plausible achieved motion (docs/gait.md): 100 m/s is three times the
// fastest land animal; 100 turns a second is more than a tumbling figure
// spins.
constexpr double kMaxAchievedSpeed = 100.0;
constexpr double kMaxAchievedTurnDps = 36000.0;

}  // namespace

bool operator==(const MotionCommand& a, const MotionCommand& b) {
  return a.speed_m_s == b.speed_m_s && a.turn_rad_s == b.turn_rad_s;
}
bool operator==(const CalibrationPoint& a, const CalibrationPoint& b) {
  return a.commanded == b.commanded && a.achieved == b.achieved && a.fell == b.fell &&
         a.usable == b.usable;
}
bool operator==(const GaitCalibration& a, const GaitCalibration& b) {
  return a.gait_file == b.gait_file && a.model_file == b.model_file && a.tolerance == b.tolerance &&
         a.points == b.points;
}

bool calibration_usable(const CalibrationPoint& p, double tolerance) {
  const double v = p.commanded.speed_m_s;
  const double w = p.commanded.turn_rad_s;
  const double turn_allowed =
      std::max(tolerance * std::abs(w), deg_to_rad(kCalibrationTurnFloorDps));
  // A turn on the spot must stay on the spot, and turn the way it was told.
  const bool on_the_spot = v == 0.0 && w != 0.0;
  const double speed_allowed = on_the_spot ? kCalibrationSpotDriftMps : tolerance * v;
  return !p.fell && (v > 0.0 || on_the_spot) && std::isfinite(p.achieved.speed_m_s) &&
         std::abs(p.achieved.speed_m_s - v) <= speed_allowed &&
         std::isfinite(p.achieved.turn_rad_s) &&
         std::abs(p.achieved.turn_rad_s - w) <= turn_allowed;
}

std::string calibration_path_for(const std::string& gait_path) {
  std::filesystem::path p(gait_path);
  const std::string stem = p.stem().string();
  return p.replace_filename(stem + ".calibration.yaml").string();
}

GaitCalibration parse_gait_calibration(const std::string& text, const std::string& file_name) {
  const YamlNode root = YamlNode::load_string(text, file_name);
  root.allow_only({"gait", "model", "tolerance", "points"});
  GaitCalibration cal;
  const YamlNode gait = root.at("gait");
  cal.gait_file = gait.as_string();
  cal.gait_where = gait.location();
  if (cal.gait_file.empty()) gait.fail("expected the gait file it was measured for, found \"\"");
  const YamlNode model = root.at("model");
  cal.model_file = model.as_string();
  cal.model_where = model.location();
  if (cal.model_file.empty()) model.fail("expected the model file it walked on, found \"\"");
  cal.tolerance = root.at("tolerance").as_double_in(0.0, 1.0);
  const YamlNode points = root.at("points");
  if (!points.is_sequence() || points.items().empty())
    points.fail("expected a list of points, found " + points.describe());
  for (const YamlNode& node : points.items()) {
    node.allow_only(
        {"speed_m_s", "turn_dps", "achieved_speed_m_s", "achieved_turn_dps", "fell", "usable"});
    CalibrationPoint p;
    p.commanded.speed_m_s = node.at("speed_m_s").as_double_in(0.0, 100.0);
    p.commanded.turn_rad_s = deg_to_rad(node.at("turn_dps").as_double_in(-3600.0, 3600.0));
    p.fell = node.at("fell").as_bool();
    // A fall leaves the achieved motion meaningless, but a figure that fell
    // still moved as a body can: backwards too, a tumble spinning fast.
    p.achieved.speed_m_s =
        node.at("achieved_speed_m_s").as_double_in(-kMaxAchievedSpeed, kMaxAchievedSpeed);
    p.achieved.turn_rad_s = deg_to_rad(
        node.at("achieved_turn_dps").as_double_in(-kMaxAchievedTurnDps, kMaxAchievedTurnDps));
    p.usable = calibration_usable(p, cal.tolerance);
    if (const auto u = node.find("usable"); u && u->as_bool() != p.usable) {
      u->fail(std::string("usable is ") + (p.usable ? "false" : "true") + " but the point is " +
              (p.usable ? "" : "not ") + "within tolerance " + shortest(cal.tolerance) +
              " (speed and turn) without a fall");
    }
    cal.points.push_back(p);
  }
  return cal;
}

GaitCalibration load_gait_calibration(const std::string& path) {
  return parse_gait_calibration(read_input_file(path, kMaxYamlFileBytes), path);
}

void check_calibration_references(const GaitCalibration& cal, const std::string& calibration_path,
                                  const std::string& gait_path) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(calibration_path).parent_path();
  const auto resolve = [&](const std::string& given) {
    return (fs::path(given).is_absolute() ? fs::path(given) : folder / given).string();
  };
  const auto where = [](const Location& at) { return at.line > 0 ? at : Location{at.file, 0, 0}; };
  const std::string gait = resolve(cal.gait_file);
  const std::string against = " (resolved against the table's folder to " + quote_path(gait) + ")";
  if (const std::string problem = input_file_problem(gait); !problem.empty()) {
    throw InputError(where(cal.gait_where), "gait",
                     "gait file " + quote_path(cal.gait_file) + against + " " + problem);
  }
  std::error_code ec;
  if (!fs::equivalent(gait, gait_path, ec)) {
    throw InputError(where(cal.gait_where), "gait",
                     "this table was measured for " + quote_path(cal.gait_file) + against +
                         ", not for the gait beside it (" + quote_path(gait_path) +
                         "); measure it again with animrt gait calibrate");
  }
  const std::string model = resolve(cal.model_file);
  if (const std::string problem = input_file_problem(model, kMaxMediaFileBytes); !problem.empty()) {
    throw InputError(where(cal.model_where), "model",
                     "model file " + quote_path(cal.model_file) +
                         " (resolved against the table's folder to " + quote_path(model) + ") " +
                         problem);
  }
}

std::string format_gait_calibration(const GaitCalibration& cal) {
  std::string out;
  out += "# Walk calibration written by animrt gait calibrate (format: docs/gait.md).\n";
  out += "# speed_m_s and turn_dps were commanded, achieved_* measured on the model.\n";
  out += "gait: " + quoted(cal.gait_file) + "\n";
  out += "model: " + quoted(cal.model_file) + "\n";
  out += "tolerance: " + shortest(cal.tolerance) + "\n";
  out += cal.points.empty() ? "points: []\n" : "points:\n";
  for (const CalibrationPoint& p : cal.points) {
    out += "  - {speed_m_s: " + shortest(p.commanded.speed_m_s) +
           ", turn_dps: " + dps_text(p.commanded.turn_rad_s) +
           ", achieved_speed_m_s: " + shortest(p.achieved.speed_m_s) +
           ", achieved_turn_dps: " + dps_text(p.achieved.turn_rad_s) +
           ", fell: " + (p.fell ? "true" : "false") +
           ", usable: " + (calibration_usable(p, cal.tolerance) ? "true" : "false") + "}\n";
  }
  return out;
}

void write_gait_calibration(const std::string& path, const GaitCalibration& calibration) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  out << format_gait_calibration(calibration);
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
}

}  // namespace animrt
