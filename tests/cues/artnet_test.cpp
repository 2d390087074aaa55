// ArtDmx packets as a lighting desk sends them, and ones whose length lies.

#include <gtest/gtest.h>

#include "animrt/runtime/artnet_receiver.hpp"

namespace animrt {
namespace {

std::vector<std::uint8_t> art_dmx(int universe, std::vector<std::uint8_t> data, int length) {
  std::vector<std::uint8_t> p = {'A', 'r', 't', '-', 'N', 'e', 't', 0, 0x00, 0x50, 0, 14, 7, 0};
  p.push_back(static_cast<std::uint8_t>(universe & 0xff));
  p.push_back(static_cast<std::uint8_t>(universe >> 8));
  p.push_back(static_cast<std::uint8_t>(length >> 8));
  p.push_back(static_cast<std::uint8_t>(length & 0xff));
  p.insert(p.end(), data.begin(), data.end());
  return p;
}

TEST(ArtNet, ArtDmxCarriesItsUniverseAndChannels) {
  ArtDmx dmx;
  const auto packet = art_dmx(0x0123, {9, 8, 7, 6}, 4);
  ASSERT_EQ(parse_artnet(packet, dmx), ArtNetParse::dmx);
  EXPECT_EQ(dmx.universe, 0x0123);
  ASSERT_EQ(dmx.data.size(), 4u);
  EXPECT_EQ(dmx.data[0], 9);
  EXPECT_EQ(dmx.data[3], 6);
}

// Art-Net asks a sender for an even length; an odd one (a script sending
// three channels), with or without a padding byte, still carries them.
TEST(ArtNet, AnOddLengthCarriesItsChannels) {
  ArtDmx dmx;  // its data is a view into the packet: the packets outlive it
  const auto three = art_dmx(5, {9, 8, 7}, 3);
  ASSERT_EQ(parse_artnet(three, dmx), ArtNetParse::dmx);
  EXPECT_EQ(dmx.universe, 5);
  ASSERT_EQ(dmx.data.size(), 3u);
  EXPECT_EQ(dmx.data[2], 7);
  const auto padded = art_dmx(0, {42, 0}, 1);
  ASSERT_EQ(parse_artnet(padded, dmx), ArtNetParse::dmx);
  ASSERT_EQ(dmx.data.size(), 1u);
  EXPECT_EQ(dmx.data[0], 42);
  EXPECT_EQ(parse_artnet(art_dmx(0, {42, 0, 0}, 1), dmx), ArtNetParse::malformed);
}

TEST(ArtNet, LengthsThatDisagreeAreMalformedAndOtherOpcodesAreNotDmx) {
  ArtDmx dmx;
  EXPECT_EQ(parse_artnet(art_dmx(0, {1, 2}, 4), dmx), ArtNetParse::malformed);
  EXPECT_EQ(parse_artnet(art_dmx(0, {1, 2, 3}, 2), dmx), ArtNetParse::malformed);
  EXPECT_EQ(parse_artnet(art_dmx(0, {1, 2, 3, 4}, 2), dmx), ArtNetParse::malformed);
  EXPECT_EQ(parse_artnet(art_dmx(0, std::vector<std::uint8_t>(514, 0), 514), dmx),
            ArtNetParse::malformed);
  EXPECT_EQ(parse_artnet(art_dmx(0, {}, 0), dmx), ArtNetParse::malformed);
  // Net 0x80: outside the 15-bit Port-Address, not universe 0.
  EXPECT_EQ(parse_artnet(art_dmx(0x8000, {1, 2}, 2), dmx), ArtNetParse::malformed);
  EXPECT_EQ(parse_artnet(art_dmx(0x7fff, {1, 2}, 2), dmx), ArtNetParse::dmx);
  EXPECT_EQ(dmx.universe, 0x7fff);
  auto poll = art_dmx(0, {1, 2}, 2);
  poll[9] = 0x20;  // ArtPoll
  EXPECT_EQ(parse_artnet(poll, dmx), ArtNetParse::other);
  auto wrong_id = art_dmx(0, {1, 2}, 2);
  wrong_id[0] = 'a';
  EXPECT_EQ(parse_artnet(wrong_id, dmx), ArtNetParse::malformed);
}

}  // namespace
}  // namespace animrt
