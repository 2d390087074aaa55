// MIT motor-mode frames, both directions, with the ranges of a model chosen
// by the first input byte: unpacked values must stay inside the ranges.

#include <linux/can.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "animrt/bridge/can/mit_codec.hpp"

namespace {

bool inside(double x, double lo, double hi) { return std::isfinite(x) && x >= lo && x <= hi; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt::mit;
  if (size < 1) return 0;
  static const char* const models[] = {"ak10-9", "ak60-6", "ak70-10", "ak80-6", "ak80-9", "none"};
  const Ranges* found = find_model(models[data[0] % 6]);
  const Ranges ranges = found ? *found : Ranges{};
  std::size_t pos = 1;
  while (size - pos >= 1) {
    can_frame f{};
    f.can_id = 1;
    f.can_dlc = data[pos++];
    const std::size_t n = std::min<std::size_t>({8, f.can_dlc, size - pos});
    std::memcpy(f.data, data + pos, n);
    pos += n;
    Command c;
    if (unpack_command(f, ranges, c)) {
      if (!inside(c.position, ranges.p_min, ranges.p_max) ||
          !inside(c.torque, ranges.t_min, ranges.t_max))
        std::abort();
      (void)pack_command(1, c, ranges);
    }
    Reply r;
    if (unpack_reply(f, ranges, r)) {
      if (!inside(r.position, ranges.p_min, ranges.p_max) ||
          !inside(r.velocity, ranges.v_min, ranges.v_max))
        std::abort();
      (void)pack_reply(0, r, ranges);
    }
    (void)special_of(f);
  }
  return 0;
}
