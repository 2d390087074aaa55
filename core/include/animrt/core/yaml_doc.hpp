#pragma once
// Strict reading of YAML input files on top of yaml-cpp. Every accessor that
// finds something wrong throws InputError naming the file, line, column and
// the dotted key path (for example "joints.lf_hip.limits.velocity_dps").

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "animrt/core/error.hpp"

namespace animrt {

// What a YAML input may hold before yaml-cpp builds its tree. yaml-cpp keeps
// some 500 bytes per node (a value, a list or a map, keys included) and a long
// value several times over, so these bound what one file can make it allocate
// to about 50 MiB. The largest shipped configuration has some 600 nodes in
// 7.5 KB: the limits leave a hand-written show or table a hundredfold room.
inline constexpr std::uintmax_t kMaxYamlFileBytes = std::uintmax_t{4} << 20;  // 4 MiB
inline constexpr std::size_t kMaxYamlNodes = 100000;

class YamlNode {
 public:
  // Parses a file; a missing file, a YAML syntax error or a file past the
  // limits above is an InputError.
  static YamlNode load_file(const std::string& path);
  // Parses text as if it came from `file_name` (for tests, embedded text and
  // files read first), with the same limits.
  static YamlNode load_string(const std::string& text, const std::string& file_name);

  const std::string& file() const { return *file_; }
  const std::string& path() const { return path_; }  // dotted key path, "" at the root
  Location location() const;
  const YAML::Node& raw() const { return node_; }

  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }

  // Map access. `at` requires the key; `find` returns nullopt when absent.
  bool has(std::string_view key) const;
  YamlNode at(std::string_view key) const;
  std::optional<YamlNode> find(std::string_view key) const;
  // Rejects any key not listed (reports the first unknown one at its own
  // position) and requires the node to be a map.
  void allow_only(std::initializer_list<std::string_view> keys) const;
  void allow_only(std::span<const std::string_view> keys) const;
  // Entries of a map in file order; duplicate keys are an error.
  std::vector<std::pair<std::string, YamlNode>> entries() const;
  // Items of a sequence in file order.
  std::vector<YamlNode> items() const;

  // Scalars, with the expected type named in the error.
  std::string as_string() const;
  double as_double() const;
  std::int64_t as_int() const;
  bool as_bool() const;
  // Range-checked numbers (inclusive bounds).
  double as_double_in(double lo, double hi) const;
  std::int64_t as_int_in(std::int64_t lo, std::int64_t hi) const;
  double as_positive_double() const;  // > 0, finite

  // Convenience: `at(key).as_...()` with a default when absent.
  double get_double(std::string_view key, double fallback) const;
  std::string get_string(std::string_view key, const std::string& fallback) const;
  bool get_bool(std::string_view key, bool fallback) const;

  // Throws InputError at this node.
  [[noreturn]] void fail(const std::string& message) const;
  // What the node holds, for messages: "nothing", "a map", a short list of
  // plain values as written ("[1, 2]"), "a list" (of maps or lists),
  // "a list of N items" (a long one) or the quoted scalar.
  std::string describe() const;

 private:
  YamlNode(std::shared_ptr<const std::string> file, YAML::Node node, std::string path,
           YAML::Mark mark);
  YamlNode child(const YAML::Node& node, std::string path) const;

  std::shared_ptr<const std::string> file_;
  YAML::Node node_;
  std::string path_;
  YAML::Mark mark_;  // where this node (or, if null, its key) is
};

// Shortest readable form of a number, as messages print them ("0.02", "100").
std::string format_number(double value);

}  // namespace animrt
