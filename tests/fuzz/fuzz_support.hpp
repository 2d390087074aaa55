#pragma once
// Shared by the harnesses. Parsers that read from a path get the fuzz input
// through a file in a private temporary directory of the process; that
// directory links the source tree's config folders, so a robot file written
// to <dir>/robots/ finds ../gaits, ../modbus, ../head as the shipped ones do.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace animrt::fuzz {

inline const std::string& work_dir() {
  // Never destroyed: the exit handler below still needs it.
  static const std::string* const dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::string pattern =
        std::string(base != nullptr && *base != '\0' ? base : "/tmp") + "/animrt_fuzz_XXXXXX";
    if (::mkdtemp(pattern.data()) == nullptr) std::abort();
    namespace fs = std::filesystem;
    const fs::path configs = fs::path(ANIMRT_SOURCE_DIR) / "configs";
    for (const char* sub : {"gaits", "modbus", "models", "head", "shows", "grammars", "evolve"})
      fs::create_directory_symlink(configs / sub, fs::path(pattern) / sub);
    fs::create_directory(fs::path(pattern) / "robots");
    // remove_all deletes the links, never what they point to.
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(work_dir(), ignored);
    });
    return new std::string(pattern);
  }();
  return *dir;
}

// Writes the input to <work_dir>/<name> and returns that path.
inline std::string write_input(const std::uint8_t* data, std::size_t size,
                               const std::string& name) {
  const std::string path = work_dir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) std::abort();
  return path;
}

inline std::string as_text(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

}  // namespace animrt::fuzz
