#pragma once
// Small helpers the evolve reports share: a printf-formatted number, and an
// output file that throws when it cannot be written.

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

namespace animrt::evolve {

inline std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

inline std::ofstream open_out(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  return out;
}

inline void close_out(std::ofstream& out, const std::string& path) {
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path);
}

}  // namespace animrt::evolve
