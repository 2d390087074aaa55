#pragma once
// Errors about user input (config, gait, grammar, model and audio files).
// Every message names the file, the line and column where known, and the key.

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace animrt {

// How much of a user's value an error line repeats: a 60 MB string in a file
// must not become a 60 MB "one line" error.
inline constexpr std::size_t kMaxQuotedChars = 80;

// `value` whole when it has at most `max_chars` characters, else its start
// and end around a marker that says how much was left out:
//   "abcdefgh[... 59999920 characters ...]stuvwxyz"
std::string elide(std::string_view value, std::size_t max_chars = kMaxQuotedChars);

// File names are quoted whole up to this length (a resolved path easily
// passes 80 characters), and elided beyond it like any value.
inline constexpr std::size_t kMaxQuotedPathChars = 256;

// elide(value) in double quotes: how a message quotes a user's value.
std::string quote(std::string_view value);
// The same for a file name, with kMaxQuotedPathChars.
std::string quote_path(std::string_view path);

// 1-based line and column; 0 means unknown.
struct Location {
  std::string file;
  int line = 0;
  int column = 0;
};

// Thrown for invalid input files. what() reads
//   "FILE:LINE:COLUMN: KEY: MESSAGE"
// (line/column or key omitted when unknown), one line, no trailing newline.
// Whatever a message was built from, what() stays short: the key is elided
// to kMaxQuotedChars, the file name and the message to a few hundred
// characters (the parts themselves stay whole in where(), key(), message()).
class InputError : public std::runtime_error {
 public:
  InputError(Location where, std::string key, std::string message);

  const Location& where() const { return where_; }
  const std::string& key() const { return key_; }
  const std::string& message() const { return message_; }

 private:
  Location where_;
  std::string key_;
  std::string message_;
};

// Thrown when a device or bus cannot be brought up (open, ping, configure).
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace animrt
