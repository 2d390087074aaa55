#include "animrt/sim/servo_answers.hpp"

#include <algorithm>

namespace animrt::sim {

void collide(Answers& out, std::size_t first) {
  if (out.list.size() < first + 2) return;
  const std::size_t begin = out.list[first].offset;
  std::size_t end = begin;
  for (std::size_t k = first; k < out.list.size(); ++k) {
    end = std::max(end, begin + (k - first) + out.list[k].size);
  }
  std::vector<std::uint8_t> wire(end - begin, 0);
  for (std::size_t k = first; k < out.list.size(); ++k) {
    const std::span<const std::uint8_t> p = out.packet(out.list[k]);
    for (std::size_t i = 0; i < p.size(); ++i) wire[(k - first) + i] |= p[i];
  }
  Answers::Answer merged = out.list[first];
  merged.size = wire.size();
  out.bytes.resize(begin);
  out.bytes.insert(out.bytes.end(), wire.begin(), wire.end());
  out.list.resize(first);
  out.list.push_back(merged);
}

}  // namespace animrt::sim
