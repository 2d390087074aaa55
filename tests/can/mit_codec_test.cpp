// MIT mode packing against the CubeMars AK Series Actuator Driver Manual
// v1.0.8 (section 5.3): the special frames are printed there byte for byte;
// the command frames below are computed with the manual's float_to_uint
// formula and bit layout (the manual prints no numeric command example),
// independently of this code (by a short Python script).

#include "animrt/bridge/can/mit_codec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace animrt::mit {
namespace {

std::vector<int> bytes(const can_frame& f) { return std::vector<int>(f.data, f.data + f.len); }

TEST(MitCodec, SpecialFramesFromTheManual) {
  EXPECT_EQ(bytes(special_frame(1, Special::enter_motor_mode)),
            (std::vector<int>{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFC}));
  EXPECT_EQ(bytes(special_frame(1, Special::exit_motor_mode)),
            (std::vector<int>{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFD}));
  EXPECT_EQ(bytes(special_frame(1, Special::set_zero)),
            (std::vector<int>{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFE}));
  EXPECT_EQ(special_frame(7, Special::set_zero).can_id, 7u);
  EXPECT_EQ(special_of(special_frame(3, Special::enter_motor_mode)), Special::enter_motor_mode);
  EXPECT_EQ(special_of(special_frame(3, Special::exit_motor_mode)), Special::exit_motor_mode);
  EXPECT_EQ(special_of(special_frame(3, Special::set_zero)), Special::set_zero);
}

TEST(MitCodec, ModelRangesFromTheManual) {
  ASSERT_NE(find_model("ak80-9"), nullptr);
  EXPECT_EQ(find_model("ak80-9")->v_max, 50.0);
  EXPECT_EQ(find_model("ak80-9")->t_max, 18.0);
  EXPECT_EQ(find_model("ak60-6")->v_max, 45.0);
  EXPECT_EQ(find_model("ak60-6")->t_max, 15.0);
  EXPECT_EQ(find_model("ak10-9")->t_max, 65.0);
  EXPECT_EQ(find_model("ak80-64")->t_max, 144.0);
  EXPECT_EQ(find_model("ak80-9")->p_max, 12.5);
  EXPECT_EQ(find_model("ak80-9")->kp_max, 500.0);
  EXPECT_EQ(find_model("ak80-9")->kd_max, 5.0);
  EXPECT_EQ(find_model("ak99"), nullptr);
}

struct Vector {
  Command command;
  const char* model;
  std::vector<int> expected;
};

TEST(MitCodec, CommandFramesComputedFromTheManualFormula) {
  const Vector vectors[] = {
      {{0, 0, 0, 0, 0}, "ak80-9", {0x7F, 0xFF, 0x7F, 0xF0, 0x00, 0x00, 0x07, 0xFF}},
      {{1.0, 0, 40, 1.0, 0}, "ak80-9", {0x8A, 0x3C, 0x7F, 0xF1, 0x47, 0x33, 0x37, 0xFF}},
      {{-12.5, -50, 0, 0, -18}, "ak80-9", {0, 0, 0, 0, 0, 0, 0, 0}},
      {{12.5, 50, 500, 5, 18}, "ak80-9", {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}},
      {{-0.5, 2.0, 10, 0.5, 1.5}, "ak60-6", {0x7A, 0xE0, 0x85, 0xA0, 0x51, 0x19, 0x98, 0xCC}},
  };
  for (const Vector& v : vectors) {
    const can_frame f = pack_command(5, v.command, *find_model(v.model));
    EXPECT_EQ(f.can_id, 5u);
    EXPECT_EQ(f.len, 8);
    EXPECT_EQ(bytes(f), v.expected) << "position " << v.command.position;
  }
}

TEST(MitCodec, ValuesOutsideTheRangeAreClamped) {
  const Ranges& r = *find_model("ak80-9");
  EXPECT_EQ(bytes(pack_command(1, {100, 100, 1000, 10, 100}, r)),
            bytes(pack_command(1, {12.5, 50, 500, 5, 18}, r)));
  EXPECT_EQ(bytes(pack_command(1, {-100, -100, -1, -1, -100}, r)),
            bytes(pack_command(1, {-12.5, -50, 0, 0, -18}, r)));
  EXPECT_EQ(float_to_uint(std::nan(""), -1, 1, 12), 0u);
}

TEST(MitCodec, RoundTripsAtTheRangeEdgesWithinOneStep) {
  const Ranges& r = *find_model("ak80-9");
  const double p_step = 25.0 / 65535, v_step = 100.0 / 4095, kp_step = 500.0 / 4095,
               kd_step = 5.0 / 4095, t_step = 36.0 / 4095;
  const double positions[] = {-12.5, -12.5 + p_step, -1e-9, 0.0, 1e-9, 12.5 - p_step, 12.5};
  for (double p : positions) {
    const Command c{p, r.v_max, r.kp_max, r.kd_min, r.t_min};
    Command back;
    ASSERT_TRUE(unpack_command(pack_command(2, c, r), r, back));
    EXPECT_NEAR(back.position, p, p_step) << p;
    EXPECT_LE(back.position, p + 1e-12);  // truncation never rounds up
    EXPECT_NEAR(back.velocity, r.v_max, v_step);
    EXPECT_NEAR(back.kp, r.kp_max, kp_step);
    EXPECT_NEAR(back.kd, 0.0, kd_step);
    EXPECT_NEAR(back.torque, r.t_min, t_step);
  }
  // The ends are exact.
  Command back;
  ASSERT_TRUE(unpack_command(pack_command(2, {12.5, -50, 0, 5, 18}, r), r, back));
  EXPECT_DOUBLE_EQ(back.position, 12.5);
  EXPECT_DOUBLE_EQ(back.velocity, -50.0);
  EXPECT_DOUBLE_EQ(back.kd, 5.0);
  EXPECT_DOUBLE_EQ(back.torque, 18.0);
}

TEST(MitCodec, ReplyLayoutAndRoundTrip) {
  const Ranges& r = *find_model("ak80-9");
  Reply in;
  in.motor_id = 9;
  in.position = 12.5;
  in.velocity = -50;
  in.torque = 18;
  const can_frame f6 = pack_reply(0, in, r);
  EXPECT_EQ(f6.can_id, 0u);
  // id | position FFFF | velocity 000 | torque FFF
  EXPECT_EQ(bytes(f6), (std::vector<int>{0x09, 0xFF, 0xFF, 0x00, 0x0F, 0xFF}));
  in.extended = true;
  in.temperature = 41;
  in.error = 3;
  in.position = -2.0;
  in.velocity = 3.0;
  in.torque = -1.0;
  Reply out;
  ASSERT_TRUE(unpack_reply(pack_reply(0, in, r), r, out));
  EXPECT_EQ(out.motor_id, 9);
  EXPECT_NEAR(out.position, -2.0, 25.0 / 65535);
  EXPECT_NEAR(out.velocity, 3.0, 100.0 / 4095);
  EXPECT_NEAR(out.torque, -1.0, 36.0 / 4095);
  EXPECT_TRUE(out.extended);
  EXPECT_EQ(out.temperature, 41);
  EXPECT_EQ(out.error, 3);
  can_frame bad = f6;
  bad.len = 5;
  EXPECT_FALSE(unpack_reply(bad, r, out));
}

TEST(MitCodec, SpecialFramesAreNotCommands) {
  Command c;
  EXPECT_FALSE(
      unpack_command(special_frame(1, Special::enter_motor_mode), *find_model("ak80-9"), c));
  can_frame short_frame = pack_command(1, {}, *find_model("ak80-9"));
  short_frame.len = 7;
  EXPECT_FALSE(unpack_command(short_frame, *find_model("ak80-9"), c));
}

}  // namespace
}  // namespace animrt::mit
