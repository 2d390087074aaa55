// The Maestro command codec against the examples printed in the Pololu
// Maestro Servo Controller User's Guide (section 5.c "Command Protocols" and
// section 5.e "Serial Servo Commands").

#include "animrt/bridge/maestro/maestro_codec.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

namespace animrt::maestro {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr Address kCompact{Form::compact, 0};
constexpr Address kDevice12{Form::pololu, 12};

template <typename F>
Bytes encode(F&& f) {
  std::array<std::uint8_t, kMaxCommand> buf{};
  const std::size_t n = f(std::span<std::uint8_t>(buf));
  return Bytes(buf.begin(), buf.begin() + static_cast<long>(n));
}

std::vector<Command> parse(const Bytes& bytes, int* errors = nullptr) {
  Parser p;
  std::vector<Command> out;
  for (std::uint8_t b : bytes) {
    const ParseResult r = p.feed(b);
    if (r == ParseResult::command) out.push_back(p.command());
    if (r == ParseResult::protocol_error && errors) ++*errors;
  }
  return out;
}

// 5.c: compact protocol, servo 0 to 1500 us: 0x84, 0x00, 0x70, 0x2E.
TEST(MaestroCodec, GuideCompactSetTargetServo0) {
  EXPECT_EQ(encode([](auto out) { return encode_set_target(kCompact, 0, 1500 * 4, out); }),
            (Bytes{0x84, 0x00, 0x70, 0x2E}));
}

// 5.c: Pololu protocol, device 12, servo 0 to 1500 us: 0xAA, 0x0C, 0x04, 0x00, 0x70, 0x2E.
TEST(MaestroCodec, GuidePololuSetTargetDevice12) {
  EXPECT_EQ(encode([](auto out) { return encode_set_target(kDevice12, 0, 6000, out); }),
            (Bytes{0xAA, 0x0C, 0x04, 0x00, 0x70, 0x2E}));
}

// 5.e: channel 2 to 1500 us (6000 = 01011101110000b): 0x84, 0x02, 0x70, 0x2E.
TEST(MaestroCodec, GuideSetTargetChannel2) {
  EXPECT_EQ(encode([](auto out) { return encode_set_target(kCompact, 2, 6000, out); }),
            (Bytes{0x84, 0x02, 0x70, 0x2E}));
}

// 5.e: channel 3 off (0) and channel 4 neutral (6000):
// 0x9F, 0x02, 0x03, 0x00, 0x00, 0x70, 0x2E.
TEST(MaestroCodec, GuideSetMultipleTargets) {
  const std::uint16_t targets[] = {0, 6000};
  EXPECT_EQ(
      encode([&](auto out) { return encode_set_multiple_targets(kCompact, 3, targets, out); }),
      (Bytes{0x9F, 0x02, 0x03, 0x00, 0x00, 0x70, 0x2E}));
}

// 5.e: speed of channel 5 to 140 (3.5 us/ms): 0x87, 0x05, 0x0C, 0x01.
TEST(MaestroCodec, GuideSetSpeed) {
  EXPECT_EQ(encode([](auto out) { return encode_set_speed(kCompact, 5, 140, out); }),
            (Bytes{0x87, 0x05, 0x0C, 0x01}));
}

// Command layouts of 5.e (no worked example printed for these).
TEST(MaestroCodec, AccelerationPositionErrorsLayouts) {
  EXPECT_EQ(encode([](auto out) { return encode_set_acceleration(kCompact, 1, 255, out); }),
            (Bytes{0x89, 0x01, 0x7F, 0x01}));
  EXPECT_EQ(encode([](auto out) { return encode_get_position(kCompact, 7, out); }),
            (Bytes{0x90, 0x07}));
  EXPECT_EQ(encode([](auto out) { return encode_get_position(kDevice12, 7, out); }),
            (Bytes{0xAA, 0x0C, 0x10, 0x07}));
  EXPECT_EQ(encode([](auto out) { return encode_get_errors(kCompact, out); }), (Bytes{0xA1}));
  EXPECT_EQ(encode([](auto out) { return encode_get_errors(kDevice12, out); }),
            (Bytes{0xAA, 0x0C, 0x21}));
  const std::uint8_t answer[] = {0x70, 0x17};  // little endian
  EXPECT_EQ(decode_answer(answer), 6000);
}

TEST(MaestroCodec, RefusesValuesThatDoNotFitSevenBitBytes) {
  EXPECT_TRUE(encode([](auto out) { return encode_set_target(kCompact, 128, 6000, out); }).empty());
  EXPECT_TRUE(encode([](auto out) { return encode_set_target(kCompact, 0, 0x4000, out); }).empty());
  EXPECT_TRUE(encode([](auto out) {
                return encode_set_target(Address{Form::pololu, 128}, 0, 6000, out);
              }).empty());
  std::array<std::uint8_t, 3> small{};
  EXPECT_EQ(encode_set_target(kCompact, 0, 6000, small), 0u);
}

TEST(MaestroCodec, ParserReadsWhatTheEncoderWrites) {
  const std::uint16_t targets[] = {4000, 8000, 6000};
  Bytes stream =
      encode([&](auto out) { return encode_set_multiple_targets(kDevice12, 2, targets, out); });
  const Bytes more = encode([](auto out) { return encode_set_speed(kCompact, 5, 140, out); });
  stream.insert(stream.end(), more.begin(), more.end());
  int errors = 0;
  const auto commands = parse(stream, &errors);
  EXPECT_EQ(errors, 0);
  ASSERT_EQ(commands.size(), 2u);
  EXPECT_EQ(commands[0].command, cmd::set_multiple_targets);
  EXPECT_TRUE(commands[0].pololu_form);
  EXPECT_EQ(commands[0].device, 12);
  EXPECT_EQ(commands[0].channel, 2);
  ASSERT_EQ(commands[0].count, 3);
  EXPECT_EQ(commands[0].targets[0], 4000);
  EXPECT_EQ(commands[0].targets[1], 8000);
  EXPECT_EQ(commands[0].targets[2], 6000);
  EXPECT_EQ(commands[1].command, cmd::set_speed);
  EXPECT_EQ(commands[1].channel, 5);
  EXPECT_EQ(commands[1].value, 140);
}

TEST(MaestroCodec, ParserFlagsBadInputAndRecovers) {
  int errors = 0;
  // Stray data byte; unknown command; Set Target cut short by Get Errors
  // (which then starts a new command).
  const auto commands = parse({0x12, 0x80, 0x84, 0x00, 0xA1, 0x90, 0x03}, &errors);
  EXPECT_EQ(errors, 3);
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].command, cmd::get_position);
  EXPECT_EQ(commands[0].channel, 3);
}

}  // namespace
}  // namespace animrt::maestro
