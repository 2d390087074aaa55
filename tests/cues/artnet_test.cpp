// ArtDmx packets as a lighting desk sends them, and ones whose length lies;
// two desks on one universe merged.

#include <gtest/gtest.h>

#include <vector>

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
  // Art-Net 4: versions before 14 are not heard.
  auto old_version = art_dmx(0, {1, 2}, 2);
  old_version[11] = 13;
  EXPECT_EQ(parse_artnet(old_version, dmx), ArtNetParse::malformed);
  old_version[10] = 1;  // 269: a later version
  EXPECT_EQ(parse_artnet(old_version, dmx), ArtNetParse::dmx);
  EXPECT_EQ(dmx.sequence, 7);
}

UdpSender sender(std::uint8_t last) {
  UdpSender s;
  s.address = {127, 0, 0, last};
  s.port = 6454;
  return s;
}

ArtDmx frame(std::vector<std::uint8_t>& levels, int sequence) {
  ArtDmx d;
  d.sequence = sequence;
  d.data = levels;
  return d;
}

std::vector<int> merged(const ArtNetSources& s) { return {s.merged().begin(), s.merged().end()}; }

// Two desks on one universe (a main and a backup, say) merge as an Art-Net
// node merges them: each channel at the higher level (they used to take
// turns, packet by packet, and a cue channel restarted its cue with each);
// a third is not heard until one of the two has been silent for 10 s.
TEST(ArtNet, TwoSourcesMergeHighestLevelFirstAndAThirdIsIgnored) {
  ArtNetSources sources;
  std::vector<std::uint8_t> a = {4, 10, 0, 200}, b = {2, 50}, c = {9, 9};
  using V = ArtNetSources::Verdict;
  ASSERT_EQ(sources.take(sender(1), frame(a, 1), 0.0), V::output);
  EXPECT_EQ(merged(sources), (std::vector<int>{4, 10, 0, 200}));
  ASSERT_EQ(sources.take(sender(2), frame(b, 1), 0.02), V::output);
  EXPECT_EQ(merged(sources), (std::vector<int>{4, 50, 0, 200}));
  EXPECT_EQ(sources.take(sender(3), frame(c, 1), 0.04), V::third_source);
  a = {1, 0};  // the first desk pulls its faders down: the second's levels show
  ASSERT_EQ(sources.take(sender(1), frame(a, 2), 0.06), V::output);
  EXPECT_EQ(merged(sources), (std::vector<int>{2, 50}));
  // The second desk falls silent: 10 s on, the third takes its place.
  ASSERT_EQ(sources.take(sender(1), frame(a, 3), 9.0), V::output);
  EXPECT_EQ(sources.take(sender(3), frame(c, 1), 10.01), V::third_source);
  ASSERT_EQ(sources.take(sender(3), frame(c, 1), 10.03), V::output);
  EXPECT_EQ(merged(sources), (std::vector<int>{9, 9}));
}

// A packet overtaken on the way (1 to 19 behind its source's last) is
// dropped; the counter wraps from 255 to 1; the same number again (a sender
// that does not count) and 0 (numbering off) are taken.
TEST(ArtNet, APacketBehindItsSourcesLastIsDropped) {
  ArtNetSources sources;
  std::vector<std::uint8_t> levels = {1, 2};
  using V = ArtNetSources::Verdict;
  ASSERT_EQ(sources.take(sender(1), frame(levels, 200), 0.0), V::output);
  EXPECT_EQ(sources.take(sender(1), frame(levels, 199), 0.1), V::out_of_sequence);
  EXPECT_EQ(sources.take(sender(1), frame(levels, 181), 0.1), V::out_of_sequence);
  EXPECT_EQ(sources.take(sender(1), frame(levels, 200), 0.1), V::output);
  EXPECT_EQ(sources.take(sender(1), frame(levels, 255), 0.1), V::output);
  EXPECT_EQ(sources.take(sender(1), frame(levels, 1), 0.1), V::output);  // wrapped
  EXPECT_EQ(sources.take(sender(1), frame(levels, 254), 0.1), V::out_of_sequence);
  EXPECT_EQ(sources.take(sender(1), frame(levels, 0), 0.1), V::output);
  // Another source's numbers are its own.
  EXPECT_EQ(sources.take(sender(2), frame(levels, 190), 0.1), V::output);
}

}  // namespace
}  // namespace animrt
