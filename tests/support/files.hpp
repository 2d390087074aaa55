#pragma once
// Where the tests find the project's own files (ANIMRT_SOURCE_DIR comes from
// tests/CMakeLists.txt), and whole-file reads and writes. Shared rather than
// file-local: each test binary compiles as one unity build, where two files'
// helpers of one name would collide.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace animrt {

inline const std::string kSourceRoot = ANIMRT_SOURCE_DIR;
inline const std::string kConfigsDir = kSourceRoot + "/configs";

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Creates the parent folders first.
inline void write_file(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace animrt
