#include "clip_names.hpp"

#include <cctype>

namespace animrt::seqnet::detail {

std::vector<Clip> clips_from_frame_names(const std::vector<std::string>& names) {
  struct Part {
    Clip clip;
    long first_number;
  };
  std::vector<Part> parts;
  std::string current;
  long previous = -1;
  for (std::size_t f = 0; f < names.size(); ++f) {
    std::string base = names[f];
    while (!base.empty() && std::isdigit(static_cast<unsigned char>(base.back()))) base.pop_back();
    const std::string digits = names[f].substr(base.size()).substr(0, 9);
    const long number = digits.empty() ? -1 : std::stol(digits);
    if (base.empty()) {
      current.clear();
      continue;
    }
    // Quake II numbers the frames of death1 as death101..death106 and of
    // death2 as death201..: a number that does not follow on starts a clip.
    const bool follows = number < 0 || previous < 0 || number == previous + 1;
    if (!parts.empty() && base == current && follows) {
      ++parts.back().clip.count;
    } else {
      parts.push_back(Part{Clip{base, static_cast<int>(f), 1, 0.0}, number});
      current = base;
    }
    previous = number;
  }
  // A name split into several clips: each is named by its first number's
  // hundreds (death101 -> death1) when those differ, else numbered in order.
  std::vector<Clip> clips;
  for (std::size_t a = 0; a < parts.size();) {
    std::size_t b = a + 1;
    while (b < parts.size() && parts[b].clip.name == parts[a].clip.name &&
           parts[b].clip.first == parts[b - 1].clip.first + parts[b - 1].clip.count) {
      ++b;
    }
    bool hundreds = b - a > 1;
    for (std::size_t k = a; k < b && hundreds; ++k) {
      hundreds = parts[k].first_number >= 100 &&
                 (k == a || parts[k].first_number / 100 != parts[k - 1].first_number / 100);
    }
    for (std::size_t k = a; k < b; ++k) {
      Clip c = parts[k].clip;
      if (b - a > 1) {
        c.name += hundreds ? std::to_string(parts[k].first_number / 100)
                           : "_" + std::to_string(k - a + 1);
      }
      clips.push_back(c);
    }
    a = b;
  }
  return clips;
}

}  // namespace animrt::seqnet::detail
