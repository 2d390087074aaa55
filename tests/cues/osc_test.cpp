// OSC 1.0 packets as a show controller sends them, and malformed ones.

#include <gtest/gtest.h>

#include <cstring>

#include "animrt/runtime/osc_receiver.hpp"

namespace animrt {
namespace {

using Bytes = std::vector<std::uint8_t>;

void pad_string(Bytes& out, const std::string& s) {
  out.insert(out.end(), s.begin(), s.end());
  do out.push_back(0);
  while (out.size() % 4 != 0);
}
void put_word(Bytes& out, std::uint32_t w) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(w >> shift));
}

Bytes message(const std::string& address, const std::string& tags,
              std::vector<std::uint32_t> args) {
  Bytes out;
  pad_string(out, address);
  pad_string(out, tags);
  for (std::uint32_t a : args) put_word(out, a);
  return out;
}

TEST(Osc, AMessageWithIntAndFloatArguments) {
  float f = 0.25f;
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, 4);
  const Bytes packet = message("/pause", ",if", {7u, bits});
  std::vector<OscMessage> out;
  ASSERT_TRUE(parse_osc_packet(packet, out));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].address, "/pause");
  ASSERT_EQ(out[0].numbers.size(), 2u);
  EXPECT_EQ(out[0].numbers[0], 7.0);
  EXPECT_EQ(out[0].numbers[1], 0.25);
}

// Booleans and 64-bit numbers are numbers too, in their places: a
// controller that sends False to resume is heard as 0.
TEST(Osc, BooleansAndSixtyFourBitNumbersAreNumbersInOrder) {
  const double d = -2.5;
  std::uint64_t bits = 0;
  std::memcpy(&bits, &d, 8);
  const Bytes packet =
      message("/pause", ",FsThd",
              {0x61000000u, 0xffffffffu, 0xfffffffdu, static_cast<std::uint32_t>(bits >> 32),
               static_cast<std::uint32_t>(bits)});
  std::vector<OscMessage> out;
  ASSERT_TRUE(parse_osc_packet(packet, out));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].numbers, (std::vector<double>{0.0, 1.0, -3.0, -2.5}));
}

TEST(Osc, ABundleCarriesItsMessagesInOrder) {
  Bytes bundle;
  pad_string(bundle, "#bundle");
  put_word(bundle, 0);
  put_word(bundle, 1);  // time tag "immediately"
  for (const char* address : {"/cue/hello", "/stop"}) {
    const Bytes m = message(address, ",", {});
    put_word(bundle, static_cast<std::uint32_t>(m.size()));
    bundle.insert(bundle.end(), m.begin(), m.end());
  }
  std::vector<OscMessage> out;
  ASSERT_TRUE(parse_osc_packet(bundle, out));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].address, "/cue/hello");
  EXPECT_EQ(out[1].address, "/stop");
}

TEST(Osc, MalformedPacketsAreRefused) {
  std::vector<OscMessage> out;
  Bytes unpadded = {'/', 's', 't', 'o', 'p', 0};
  EXPECT_FALSE(parse_osc_packet(unpadded, out));
  Bytes no_slash = message("stop", ",", {});
  EXPECT_FALSE(parse_osc_packet(no_slash, out));
  Bytes short_arg = message("/pause", ",i", {});
  EXPECT_FALSE(parse_osc_packet(short_arg, out));
  Bytes bad_tag = message("/pause", ",x", {1u});
  EXPECT_FALSE(parse_osc_packet(bad_tag, out));
  Bytes unterminated(8, 'a');
  unterminated[0] = '/';
  EXPECT_FALSE(parse_osc_packet(unterminated, out));
  Bytes bundle;
  pad_string(bundle, "#bundle");
  put_word(bundle, 0);
  put_word(bundle, 1);
  put_word(bundle, 400);  // an element longer than the packet
  EXPECT_FALSE(parse_osc_packet(bundle, out));
  EXPECT_FALSE(parse_osc_packet(Bytes{}, out));
}

}  // namespace
}  // namespace animrt
