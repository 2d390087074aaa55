// sACN (E1.31) data packets as a desk sends them, ones whose layers lie about
// their lengths, and the standard's arbitration between sources.

#include <gtest/gtest.h>

#include "animrt/runtime/sacn_receiver.hpp"

namespace animrt {
namespace {

void sacn_put16(std::vector<std::uint8_t>& p, std::size_t at, unsigned v) {
  p[at] = static_cast<std::uint8_t>(v >> 8);
  p[at + 1] = static_cast<std::uint8_t>(v & 0xff);
}

// The data packet's octets, laid out from the standard's tables.
std::vector<std::uint8_t> e131(int universe, std::vector<std::uint8_t> slots, int sequence,
                               int priority = 100, std::uint8_t source = 0x11,
                               std::uint8_t options = 0) {
  std::vector<std::uint8_t> p(126 + slots.size(), 0);
  sacn_put16(p, 0, 0x0010);
  const char id[] = "ASC-E1.17";
  std::copy(id, id + 9, p.begin() + 4);
  sacn_put16(p, 16, 0x7000 | static_cast<unsigned>(p.size() - 16));
  p[21] = 0x04;
  std::fill(p.begin() + 22, p.begin() + 38, source);
  sacn_put16(p, 38, 0x7000 | static_cast<unsigned>(p.size() - 38));
  p[43] = 0x02;
  p[44] = 'd';
  p[108] = static_cast<std::uint8_t>(priority);
  p[111] = static_cast<std::uint8_t>(sequence);
  p[112] = options;
  sacn_put16(p, 113, static_cast<unsigned>(universe));
  sacn_put16(p, 115, 0x7000 | static_cast<unsigned>(p.size() - 115));
  p[117] = 0x02;
  p[118] = 0xa1;
  sacn_put16(p, 121, 1);
  sacn_put16(p, 123, static_cast<unsigned>(slots.size() + 1));
  std::copy(slots.begin(), slots.end(), p.begin() + 126);
  return p;
}

TEST(Sacn, DataPacketCarriesItsSourceUniverseAndSlots) {
  SacnDmx dmx;
  const auto packet = e131(1234, {9, 8, 7}, 42, 150);
  ASSERT_EQ(parse_sacn(packet, dmx), SacnParse::dmx);
  EXPECT_EQ(dmx.universe, 1234);
  EXPECT_EQ(dmx.priority, 150);
  EXPECT_EQ(dmx.sequence, 42);
  EXPECT_EQ(dmx.cid[0], 0x11);
  ASSERT_EQ(dmx.data.size(), 3u);
  EXPECT_EQ(dmx.data[0], 9);
  EXPECT_EQ(dmx.data[2], 7);
  EXPECT_EQ(SacnReceiver::group(1234), "239.255.4.210");
}

TEST(Sacn, LayersThatDisagreeWithTheDatagramAreMalformed) {
  SacnDmx dmx;
  const auto good = e131(1, {1, 2}, 0);
  auto longer = good;
  longer.push_back(0);  // the layers' lengths no longer match
  EXPECT_EQ(parse_sacn(longer, dmx), SacnParse::malformed);
  EXPECT_EQ(parse_sacn(std::span(good).first(120), dmx), SacnParse::malformed);
  for (std::size_t at : {std::size_t{0}, std::size_t{8}, std::size_t{17}, std::size_t{39},
                         std::size_t{43}, std::size_t{116}, std::size_t{118}, std::size_t{124}}) {
    auto broken = good;
    broken[at] ^= 0x01;
    EXPECT_EQ(parse_sacn(broken, dmx), SacnParse::malformed) << "octet " << at;
  }
  EXPECT_EQ(parse_sacn(e131(1, {1}, 0, 201), dmx), SacnParse::malformed);
  EXPECT_EQ(parse_sacn(e131(0, {1}, 0), dmx), SacnParse::malformed);
  EXPECT_EQ(parse_sacn(e131(64000, {1}, 0), dmx), SacnParse::malformed);
  EXPECT_EQ(parse_sacn(e131(1, std::vector<std::uint8_t>(513, 0), 0), dmx), SacnParse::malformed);
  auto sync = good;
  sync[21] = 0x08;  // extended: synchronisation or discovery
  EXPECT_EQ(parse_sacn(sync, dmx), SacnParse::other);
}

SacnSources::Verdict sacn_take(SacnSources& sources, const std::vector<std::uint8_t>& packet,
                               double now) {
  SacnDmx dmx;
  EXPECT_EQ(parse_sacn(packet, dmx), SacnParse::dmx);
  return sources.take(dmx, now);
}

TEST(Sacn, LateSequenceNumbersAreDroppedAndWrapAround) {
  using V = SacnSources::Verdict;
  SacnSources sources;
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 250), 0.0), V::output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 250), 0.0), V::out_of_sequence);  // a duplicate
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 240), 0.0), V::out_of_sequence);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 4), 0.0), V::output);    // 250 -> 4 wraps
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 200), 0.0), V::output);  // far behind: a restart
}

TEST(Sacn, TheHighestPrioritySourceIsOutputUntilItIsLost) {
  using V = SacnSources::Verdict;
  SacnSources sources;
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 0, 100, 0x11), 0.0), V::output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 0, 150, 0x22), 0.1), V::output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 1, 100, 0x11), 0.2), V::lower_priority);
  // The high one falls silent: after the loss timeout the low one is output.
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 2, 100, 0x11), 0.1 + kSacnSourceLossS - 0.1),
            V::lower_priority);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 3, 100, 0x11), 0.1 + kSacnSourceLossS + 0.1),
            V::output);
  // A source that ends its stream is forgotten at once; preview data is never output.
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 1, 180, 0x33), 3.0), V::output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 2, 180, 0x33, 0x40), 3.0), V::not_output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 4, 100, 0x11), 3.0), V::output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 5, 100, 0x11, 0x80), 3.0), V::not_output);
  // Nor does preview data at a higher priority hold the live data back.
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 0, 200, 0x44, 0x80), 3.1), V::not_output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 6, 100, 0x11), 3.2), V::output);
  // A source that goes from live to preview only is lost as if silent.
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 0, 190, 0x55), 4.0), V::output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 1, 190, 0x55, 0x80), 4.1), V::not_output);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 7, 100, 0x11), 4.2), V::lower_priority);
  EXPECT_EQ(sacn_take(sources, e131(1, {1}, 8, 100, 0x11), 4.0 + kSacnSourceLossS + 0.1),
            V::output);
}

}  // namespace
}  // namespace animrt
