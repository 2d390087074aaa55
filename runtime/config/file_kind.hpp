#pragma once
// What kind of animrt file a YAML document is, from its top-level keys: so
// that a gait, a show or a herd scene given where a robot file belongs is
// named as what it is rather than reported key by key.

#include <string>

#include "animrt/core/yaml_doc.hpp"

namespace animrt {

// "a gait file (stride_frequency_hz, curves)", or "" when the keys say
// nothing beyond what a robot file has.
std::string other_file_kind(const YamlNode& root);

// Throws InputError at the file's start when `root` is not a robot file but
// another kind of animrt file.
void require_robot_file(const YamlNode& root);

}  // namespace animrt
