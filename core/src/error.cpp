#include "animrt/core/error.hpp"

namespace animrt {
namespace {

// Limits of what() beyond the quoted values: a path can be long, a message
// may list the names it expected, but neither runs to megabytes.
constexpr std::size_t kMaxFileChars = 1024;
constexpr std::size_t kMaxMessageChars = 1024;

std::string format(const Location& where, const std::string& key, const std::string& message) {
  std::string out = where.file.empty() ? std::string("<input>") : elide(where.file, kMaxFileChars);
  if (where.line > 0) {
    out += ':' + std::to_string(where.line);
    if (where.column > 0) out += ':' + std::to_string(where.column);
  }
  out += ": ";
  if (!key.empty()) out += elide(key) + ": ";
  out += elide(message, kMaxMessageChars);
  return out;
}

}  // namespace

std::string elide(std::string_view value, std::size_t max_chars) {
  if (value.size() <= max_chars) return std::string(value);
  const std::size_t head = (max_chars + 1) / 2;
  const std::size_t tail = max_chars - head;
  const std::size_t left_out = value.size() - head - tail;
  std::string out(value.substr(0, head));
  out += "[... " + std::to_string(left_out) + " characters ...]";
  out += value.substr(value.size() - tail);
  return out;
}

std::string quote(std::string_view value) { return '"' + elide(value) + '"'; }

std::string quote_path(std::string_view path) {
  return '"' + elide(path, kMaxQuotedPathChars) + '"';
}

InputError::InputError(Location where, std::string key, std::string message)
    : std::runtime_error(format(where, key, message)),
      where_(std::move(where)),
      key_(std::move(key)),
      message_(std::move(message)) {}

}  // namespace animrt
