// Telling animrt's kinds of files apart (see file_kind.hpp).

#include "file_kind.hpp"

#include <array>
#include <string_view>

#include "animrt/core/error.hpp"

namespace animrt {
namespace {

struct FileKind {
  const char* name;
  const char* example;                   // a shipped file of the kind
  std::array<std::string_view, 4> keys;  // any one of them names the kind
  const char* how_to_check = "";         // where animrt checks a file of the kind
};

// Keys no robot file has; the first kind that has one of them wins.
constexpr std::array<FileKind, 7> kKinds{{
    {"a gait file",
     "configs/gaits/walk.yaml",
     {"stride_frequency_hz", "curves", "limbs", "steering"}},
    {"a gait's calibration table",
     "configs/gaits/walk.calibration.yaml",
     {"points", "tolerance", "gait", ""}},
    {"a herd scene", "configs/herd/flock.yaml", {"groups", "figures", "bounds_m", ""}},
    {"an evolve run file",
     "configs/evolve/quadruped_free.yaml",
     {"grammar", "seed_gait", "search", "fitness"}},
    {"a Modbus register map",
     "configs/modbus/linear_actuator.yaml",
     {"goal", "present", "enable", "unit"}},
    {"a show", "configs/shows/hello.yaml", {"duration_s", "tracks", "audio", ""}},
    {"a cue file",
     "configs/cues/animatronic.yaml",
     {"cues", "idle", "crossfade_s", "artnet"},
     "; check it with the robot that plays it: animrt validate ROBOT --cues FILE"},
}};

}  // namespace

std::string other_file_kind(const YamlNode& root) {
  if (!root.is_map()) return "";
  for (const FileKind& kind : kKinds) {
    std::string seen;
    for (std::string_view key : kind.keys) {
      if (!key.empty() && root.has(key)) seen += (seen.empty() ? "" : ", ") + std::string(key);
    }
    if (!seen.empty()) {
      return std::string(kind.name) + " (it has " + seen + "; like " + kind.example + ")" +
             kind.how_to_check;
    }
  }
  return "";
}

void require_robot_file(const YamlNode& root) {
  if (!root.is_map() || root.has("buses")) return;
  const std::string kind = other_file_kind(root);
  if (kind.empty()) return;
  throw InputError(Location{root.file(), 0, 0}, "",
                   "expected a robot file (name, loop, buses, joints, motion; like "
                   "configs/robots/quadruped.yaml), found " +
                       kind);
}

}  // namespace animrt
