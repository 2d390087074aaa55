#pragma once
// Helpers for the seqnet tests: byte-level file writers, a tiny OBJ writer,
// and the real game models the tests extract from Debian packages.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace seqtest {

inline std::string temp_path(const std::string& name) {
  const char* base = std::getenv("TMPDIR");
  const std::filesystem::path dir = std::filesystem::path(base ? base : "/tmp") / "seqnet";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

struct Bytes {
  std::vector<std::uint8_t> data;
  void u8(std::uint8_t v) { data.push_back(v); }
  void i16(std::int16_t v) {
    const auto u = static_cast<std::uint16_t>(v);
    data.push_back(static_cast<std::uint8_t>(u & 0xff));
    data.push_back(static_cast<std::uint8_t>(u >> 8));
  }
  void i32(std::int32_t v) {
    const auto u = static_cast<std::uint32_t>(v);
    for (int k = 0; k < 4; ++k) data.push_back(static_cast<std::uint8_t>(u >> (8 * k)));
  }
  void f32(float v) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, 4);
    i32(static_cast<std::int32_t>(bits));
  }
  void text(const std::string& s, std::size_t width) {
    for (std::size_t k = 0; k < width; ++k)
      data.push_back(k < s.size() ? static_cast<std::uint8_t>(s[k]) : 0);
  }
  void put_i32(std::size_t at, std::int32_t v) {
    const auto u = static_cast<std::uint32_t>(v);
    for (int k = 0; k < 4; ++k)
      data[at + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(u >> (8 * k));
  }
  std::size_t size() const { return data.size(); }
  void save(const std::string& path) const {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data.data()),
              static_cast<std::streamsize>(data.size()));
  }
};

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// One frame as OBJ (1-based faces).
inline void write_obj_frame(const std::string& path, const animrt::seqnet::MeshSequence& s,
                            int frame) {
  std::ofstream out(path);
  out.precision(17);
  const auto& p = s.frames[static_cast<std::size_t>(frame)];
  for (Eigen::Index i = 0; i < p.cols(); ++i)
    out << "v " << p(0, i) << ' ' << p(1, i) << ' ' << p(2, i) << '\n';
  for (const auto& t : s.triangles)
    out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

// The real models; a missing package is a failure, since install-deps.sh
// installs them.
inline const char* kSydney = "/usr/share/doc/libirrlicht-dev/media/sydney.md2.gz";
inline const char* kPak0 = "/usr/share/games/openarena/baseoa/pak0.pk3";

inline std::string sydney_path() {
  if (!std::filesystem::exists(kSydney)) {
    ADD_FAILURE() << kSydney << " is missing: install the Debian package libirrlicht-doc "
                  << "(scripts/install-deps.sh)";
    return "";
  }
  return kSydney;
}

// Extracts sarge's lower.md3 and animation.cfg; returns the md3 path.
inline std::string sarge_lower_path() {
  if (!std::filesystem::exists(kPak0)) {
    ADD_FAILURE() << kPak0 << " is missing: install the Debian package openarena-data "
                  << "(scripts/install-deps.sh)";
    return "";
  }
  const std::string dir = temp_path("sarge");
  const std::string command =
      std::string("unzip -o -q -j ") + kPak0 +
      " models/players/sarge/lower.md3 models/players/sarge/animation.cfg -d " + dir;
  if (std::system(command.c_str()) != 0) {
    ADD_FAILURE() << "could not run: " << command << " (install the Debian package unzip)";
    return "";
  }
  return dir + "/lower.md3";
}

}  // namespace seqtest
