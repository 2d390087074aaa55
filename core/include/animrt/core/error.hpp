#pragma once
// Errors about user input (config, gait, grammar, model and audio files).
// Every message names the file, the line and column where known, and the key.

#include <stdexcept>
#include <string>

namespace animrt {

// 1-based line and column; 0 means unknown.
struct Location {
  std::string file;
  int line = 0;
  int column = 0;
};

// Thrown for invalid input files. what() reads
//   "FILE:LINE:COLUMN: KEY: MESSAGE"
// (line/column or key omitted when unknown), one line, no trailing newline.
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
