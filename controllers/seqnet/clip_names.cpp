#include "clip_names.hpp"

#include <cctype>

namespace animrt::seqnet::detail {

std::vector<Clip> clips_from_frame_names(const std::vector<std::string>& names) {
  std::vector<Clip> clips;
  std::string current;
  for (std::size_t f = 0; f < names.size(); ++f) {
    std::string base = names[f];
    while (!base.empty() && std::isdigit(static_cast<unsigned char>(base.back()))) base.pop_back();
    if (base.empty()) {
      current.clear();
      continue;
    }
    if (!clips.empty() && base == current) {
      ++clips.back().count;
    } else {
      clips.push_back(Clip{base, static_cast<int>(f), 1, 0.0});
      current = base;
    }
  }
  return clips;
}

}  // namespace animrt::seqnet::detail
