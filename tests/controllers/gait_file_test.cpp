#include "animrt/controllers/gait/gait_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "controllers/gait_file_error.hpp"

namespace animrt {
namespace {

// Line numbers matter: the error tests below replace lines of this text.
const std::vector<std::string> kBase = {
    /* 1 */ "name: test",
    /* 2 */ "stride_frequency_hz: 2.0",
    /* 3 */ "curves:",
    /* 4 */ "  hip: \"10 + 5*sin(2*PI*t)\"",
    /* 5 */ "  knee: -t * 2",
    /* 6 */ "limbs:",
    /* 7 */ "  a: 0.0",
    /* 8 */ "  b: 0.5",
    /* 9 */ "joints:",
    /* 10 */ "  j1: {curve: hip, limb: a}",
    /* 11 */ "  j2: {curve: knee, limb: b, sign: -1, scale: 2.0, offset_deg: 3}",
};

std::string join(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

// kBase with 1-based lines first..last replaced by `text` (which may hold
// several lines).
std::string with_lines(int first, int last, const std::string& text) {
  auto lines = kBase;
  lines.erase(lines.begin() + first, lines.begin() + last);
  lines[static_cast<std::size_t>(first - 1)] = text;
  return join(lines);
}

std::string with_line(int line, const std::string& text) { return with_lines(line, line, text); }

TEST(GaitFile, ReadsAValidFile) {
  const GaitFile g = parse_gait_file(join(kBase), "g.yaml");
  EXPECT_EQ(g.name, "test");
  EXPECT_EQ(g.file, "g.yaml");
  ASSERT_TRUE(g.stride_frequency_hz.has_value());
  EXPECT_EQ(*g.stride_frequency_hz, 2.0);
  EXPECT_FALSE(g.froude.has_value());
  EXPECT_EQ(g.stride_frequency(), 2.0);

  ASSERT_EQ(g.curves.size(), 2u);
  EXPECT_EQ(g.curves[0].name, "hip");
  EXPECT_EQ(g.curves[0].expression, "10 + 5*sin(2*PI*t)");
  EXPECT_EQ(g.curves[0].where.line, 4);
  EXPECT_EQ(g.curves[0].where.column, 9);  // after the quote
  EXPECT_EQ(g.curves[1].name, "knee");
  EXPECT_EQ(g.curves[1].expression, "-t * 2");
  EXPECT_EQ(g.curves[1].where.column, 9);

  ASSERT_EQ(g.limbs.size(), 2u);
  EXPECT_EQ(g.limbs[1].name, "b");
  EXPECT_EQ(g.limbs[1].phase, 0.5);

  ASSERT_EQ(g.joints.size(), 2u);
  const GaitJoint& j1 = g.joints[0];
  EXPECT_EQ(j1.name, "j1");
  EXPECT_EQ(j1.curve, "hip");
  EXPECT_EQ(j1.limb, "a");
  EXPECT_EQ(j1.sign, 1);  // defaults
  EXPECT_EQ(j1.scale, 1.0);
  EXPECT_EQ(j1.offset_deg, 0.0);
  EXPECT_EQ(j1.where.line, 10);
  EXPECT_EQ(j1.where.column, 3);
  const GaitJoint& j2 = g.joints[1];
  EXPECT_EQ(j2.sign, -1);
  EXPECT_EQ(j2.scale, 2.0);
  EXPECT_EQ(j2.offset_deg, 3.0);
}

TEST(GaitFile, FroudeTiming) {
  const GaitFile g =
      parse_gait_file(with_line(2, "froude: {number: 0.25, hip_height_m: 0.18}"), "g.yaml");
  EXPECT_FALSE(g.stride_frequency_hz.has_value());
  ASSERT_TRUE(g.froude.has_value());
  EXPECT_EQ(g.froude->number, 0.25);
  EXPECT_EQ(g.froude->hip_height_m, 0.18);
  EXPECT_NEAR(g.stride_frequency(), 1.84351390882, 1e-10);
}

TEST(GaitFile, UnknownKeys) {
  EXPECT_EQ(gait_file_error(with_line(1, "name: test\nspeed: 3")),
            "g.yaml:2:1: speed: unknown key (expected one of: name, stride_frequency_hz, froude, "
            "curves, limbs, joints, steering, balance, walks)");
  EXPECT_EQ(gait_file_error(with_line(10, "  j1: {curve: hip, limb: a, gain: 2}")),
            "g.yaml:10:29: joints.j1.gain: unknown key (expected one of: curve, limb, sign, scale, "
            "offset_deg)");
  EXPECT_EQ(gait_file_error(with_line(2, "froude: {number: 0.25, hip_height_m: 0.18, g: 9.8}")),
            "g.yaml:2:44: froude.g: unknown key (expected one of: number, hip_height_m)");
}

TEST(GaitFile, WrongTypes) {
  EXPECT_EQ(gait_file_error(with_line(2, "stride_frequency_hz: fast")),
            "g.yaml:2:22: stride_frequency_hz: expected a number, found \"fast\"");
  EXPECT_EQ(gait_file_error(with_lines(3, 5, "curves: [1, 2]")),
            "g.yaml:3:9: curves: expected a map, found [1, 2]");
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: [t]")),
            "g.yaml:4:8: curves.hip: expected a string, found [t]");
  EXPECT_EQ(gait_file_error(with_line(7, "  a: early")),
            "g.yaml:7:6: limbs.a: expected a number, found \"early\"");
  EXPECT_EQ(gait_file_error(with_line(11, "  j2: {curve: knee, limb: b, scale: big}")),
            "g.yaml:11:37: joints.j2.scale: expected a number, found \"big\"");
  EXPECT_EQ(gait_file_error(with_line(11, "  j2: {curve: knee, limb: b, sign: 2}")),
            "g.yaml:11:36: joints.j2.sign: expected 1 or -1, found \"2\"");
  EXPECT_EQ(gait_file_error(with_line(10, "  j1: hip")),
            "g.yaml:10:7: joints.j1: expected a map, found \"hip\"");
}

TEST(GaitFile, ImplausibleScaleAndOffset) {
  EXPECT_EQ(gait_file_error(with_line(11, "  j2: {curve: knee, limb: b, scale: 1e30}")),
            "g.yaml:11:37: joints.j2.scale: expected a number from -100 to 100, found \"1e30\"");
  EXPECT_EQ(gait_file_error(with_line(11, "  j2: {curve: knee, limb: b, offset_deg: -4000}")),
            "g.yaml:11:42: joints.j2.offset_deg: expected a number from -3600 to 3600, found "
            "\"-4000\"");
  // A gait built in memory gets the same check.
  GaitFile gait = parse_gait_file(join(kBase), "g.yaml");
  gait.joints[1].scale = -1e30;
  try {
    validate_gait(gait);
    ADD_FAILURE() << "scale accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "g.yaml:11:3: joints.j2.scale: expected a number from -100 to 100, "
                 "found -1e+30");
  }
}

TEST(GaitFile, MissingKeys) {
  EXPECT_EQ(gait_file_error(with_line(1, "# no name")),
            "g.yaml:2:1: name: required key is missing");
  EXPECT_EQ(gait_file_error(with_line(10, "  j1: {curve: hip}")),
            "g.yaml:10:7: joints.j1.limb: required key is missing");
  EXPECT_EQ(gait_file_error(with_line(2, "froude: {number: 0.25}")),
            "g.yaml:2:9: froude.hip_height_m: required key is missing");
  EXPECT_EQ(gait_file_error(with_line(1, "name: \"\"")),
            "g.yaml:1:7: name: expected a non-empty name");
}

TEST(GaitFile, StrideTiming) {
  EXPECT_EQ(gait_file_error(
                with_line(2, "stride_frequency_hz: 1\nfroude: {number: 0.25, hip_height_m: 0.18}")),
            "g.yaml:3:9: froude: give exactly one of stride_frequency_hz or froude, not both");
  EXPECT_EQ(gait_file_error(with_line(2, "# none")),
            "g.yaml:1:1: missing stride timing: give exactly one of stride_frequency_hz or froude");
  EXPECT_EQ(gait_file_error(with_line(2, "stride_frequency_hz: 0")),
            "g.yaml:2:22: stride_frequency_hz: expected a positive number, found \"0\"");
  EXPECT_EQ(gait_file_error(with_line(2, "stride_frequency_hz: -1.5")),
            "g.yaml:2:22: stride_frequency_hz: expected a positive number, found \"-1.5\"");
  EXPECT_EQ(gait_file_error(with_line(2, "froude: {number: 0, hip_height_m: 0.18}")),
            "g.yaml:2:18: froude.number: expected a positive number, found \"0\"");
}

TEST(GaitFile, ExpressionErrorsAtTheirColumnInTheFile) {
  // Double-quoted: the expression starts at column 9, after the quote.
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: \"10 + 5*sin(2*PI*t\"")),
            "g.yaml:4:26: curves.hip: expected ')' to close '(' at column 19");
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: \"10 + 5*sin(2*PI*x)\"")),
            "g.yaml:4:25: curves.hip: unknown name 'x' (expected t, PI, sin, cos)");
  // Plain: the expression starts where the scalar does.
  EXPECT_EQ(gait_file_error(with_line(5, "  knee: -t * x")),
            "g.yaml:5:14: curves.knee: unknown name 'x' (expected t, PI, sin, cos)");
  EXPECT_EQ(gait_file_error(with_line(5, "  knee: 1e999 + t")),
            "g.yaml:5:9: curves.knee: number out of range");
  // Single-quoted.
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: '1 + )'")),
            "g.yaml:4:13: curves.hip: unexpected ')'");
  // In a flow map, with extra spaces before the value.
  EXPECT_EQ(gait_file_error(with_lines(3, 5, "curves: {hip:   \"(t\", knee: t}")),
            "g.yaml:3:20: curves.hip: expected ')' to close '(' at column 18");
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: \"\"")),
            "g.yaml:4:9: curves.hip: empty expression");
}

TEST(GaitFile, ExpressionErrorsInTextThatDoesNotMapOneToOne) {
  // An escape or a line break between the start and the error: the error is
  // reported at the scalar with the column inside the expression.
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: \"1 +\\t)\"")),
            "g.yaml:4:8: curves.hip: unexpected ')' (column 5 of the expression)");
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: 1 +\n    x")),
            "g.yaml:4:8: curves.hip: unknown name 'x' (expected t, PI, sin, cos) (column 5 of the "
            "expression)");
  // Before the escape the columns still map.
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: \"1 + ) \\t\"")),
            "g.yaml:4:13: curves.hip: unexpected ')'");
}

TEST(GaitFile, UndefinedCurveOrLimb) {
  EXPECT_EQ(gait_file_error(with_line(10, "  j1: {curve: foot, limb: a}")),
            "g.yaml:10:15: joints.j1.curve: undefined curve 'foot' (curves: hip, knee)");
  EXPECT_EQ(gait_file_error(with_line(10, "  j1: {curve: hip, limb: c}")),
            "g.yaml:10:26: joints.j1.limb: undefined limb 'c' (limbs: a, b)");
}

TEST(GaitFile, CurveMustBeFinite) {
  // 1e308 * (1 + t) overflows from t = 817/1024 on.
  EXPECT_EQ(gait_file_error(with_line(4, "  hip: \"1e308 * (1 + t)\"")),
            "g.yaml:4:9: curves.hip: curve is not finite at t = 0.7978515625 stride cycles (value "
            "inf); it must be finite over the whole stride");
  EXPECT_EQ(gait_file_error(with_line(5, "  knee: 1e308 * 10 * 0")),
            "g.yaml:5:9: curves.knee: curve is not finite at t = 0 stride cycles (value nan); it "
            "must be finite over the whole stride");
}

TEST(GaitFile, NeedsJoints) {
  EXPECT_EQ(gait_file_error(with_lines(9, 11, "joints: {}")),
            "g.yaml:9:9: joints: a gait needs at least one joint");
}

TEST(GaitFile, LimbPhaseRange) {
  EXPECT_EQ(gait_file_error(with_line(8, "  b: 1.5")),
            "g.yaml:8:6: limbs.b: expected a number from 0 to 1, found \"1.5\"");
}

TEST(GaitFile, DuplicateKeys) {
  EXPECT_EQ(gait_file_error(with_line(8, "  a: 0.5")), "g.yaml:8:3: limbs.a: duplicate key");
}

TEST(GaitFile, MissingFile) {
  try {
    (void)load_gait_file("/nonexistent/walk.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/walk.yaml: cannot open file: No such file or directory");
  }
}

TEST(GaitFile, BadFixtureFile) {
  const std::string path = std::string(ANIMRT_SOURCE_DIR) + "/tests/data/gaits/bad_curve.yaml";
  try {
    (void)load_gait_file(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":6:43: curves.knee: unexpected '*'");
  }
}

GaitFile odd_gait() {
  GaitFile g;
  g.name = "evolved #7: \"best\"";
  g.froude = FroudeTiming{0.1 + 0.2, 0.1 + 0.07};
  g.curves.push_back({"c0", "6.97 + 7.7*sin(1*2*PI*t + -1.07)", {}});
  g.curves.push_back({"curve with spaces", "0.1*t/(t - t) - 1e-300", {}});
  g.curves.push_back({"null", "cos(t)", {}});
  g.limbs.push_back({"front", 1.0 / 3.0, {}});
  g.limbs.push_back({"1", 0.0, {}});
  g.joints.push_back({"lf_hip", "c0", "front", -1, 0.1 * 3, -0.0, {}});
  g.joints.push_back({"x: y", "curve with spaces", "1", 1, -99.99999999999999, 5e-324, {}});
  g.joints.push_back({"z", "null", "front", 1, 1.0, 0.0, {}});
  return g;
}

// walks: false marks a periodic motion that is not a walk (it winds down
// at no stop); it survives a write and a read, and a gait that does not
// walk cannot be steered or balanced.
TEST(GaitFile, Walks) {
  EXPECT_TRUE(parse_gait_file(join(kBase), "g.yaml").walks);
  const GaitFile g = parse_gait_file(with_line(1, "name: test\nwalks: false"), "g.yaml");
  EXPECT_FALSE(g.walks);
  const GaitFile back = parse_gait_file(format_gait_file(g), "back.yaml");
  EXPECT_FALSE(back.walks);
  EXPECT_TRUE(back == g) << format_gait_file(g);
  GaitFile other = g;
  other.walks = true;
  EXPECT_FALSE(other == g);
  EXPECT_EQ(gait_file_error(with_line(1, "name: test\nwalks: maybe")),
            "g.yaml:2:8: walks: expected true or false, found \"maybe\"");
  EXPECT_EQ(gait_file_error(with_line(1, "name: test\nwalks: false\nbalance: {tilt_m: 0.3}")),
            "g.yaml:2:8: walks: a gait that does not walk has no balance reflex: remove balance or "
            "walks");
}

TEST(GaitFile, Balance) {
  const GaitFile g = parse_gait_file(
      with_line(1, "name: test\nbalance: {tilt_m: 0.3, tilt_rate_m_s: 0.1}"), "g.yaml");
  ASSERT_TRUE(g.balance.has_value());
  EXPECT_EQ(g.balance->tilt_m, 0.3);
  EXPECT_EQ(g.balance->tilt_rate_m_s, 0.1);
  const GaitFile back = parse_gait_file(format_gait_file(g), "back.yaml");
  EXPECT_TRUE(back == g) << format_gait_file(g);
  GaitFile other = g;
  other.balance->tilt_m = 0.2;
  EXPECT_FALSE(other == g);
  // One gain is enough; the other defaults to 0.
  EXPECT_EQ(parse_gait_file(with_line(1, "name: test\nbalance: {tilt_rate_m_s: 0.1}"), "g.yaml")
                .balance->tilt_m,
            0.0);

  EXPECT_EQ(gait_file_error(with_line(1, "name: test\nbalance: {}")),
            "g.yaml:2:10: balance: give tilt_m or tilt_rate_m_s above 0 (or leave balance out)");
  EXPECT_EQ(gait_file_error(with_line(1, "name: test\nbalance: {tilt_m: 3}")),
            "g.yaml:2:19: balance.tilt_m: expected a number from 0 to 2, found \"3\"");
  EXPECT_EQ(gait_file_error(with_line(1, "name: test\nbalance: {tilt_m: -0.1}")),
            "g.yaml:2:19: balance.tilt_m: expected a number from 0 to 2, found \"-0.1\"");
  EXPECT_EQ(gait_file_error(with_line(1, "name: test\nbalance: {gain: 1}")),
            "g.yaml:2:11: balance.gain: unknown key (expected one of: tilt_m, tilt_rate_m_s)");

  GaitFile bad = g;
  bad.balance->tilt_m = std::nan("");
  try {
    validate_gait(bad);
    ADD_FAILURE() << "a balance gain that is not a number was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("balance: expected tilt_m and tilt_rate_m_s from 0 to 2"),
              std::string::npos)
        << e.what();
  }
}

TEST(GaitFile, FormatReadsBackEqual) {
  const GaitFile g = odd_gait();
  validate_gait(g);
  const std::string text = format_gait_file(g);
  const GaitFile back = parse_gait_file(text, "round.yaml");
  EXPECT_TRUE(back == g) << text;
  EXPECT_EQ(format_gait_file(back), text);
  EXPECT_EQ(back.limbs[0].phase, 1.0 / 3.0);  // exact, not 0.333...
}

TEST(GaitFile, WriteAndLoadRoundTrip) {
  const std::string walk = std::string(ANIMRT_SOURCE_DIR) + "/configs/gaits/walk.yaml";
  const std::string out = ::testing::TempDir() + "/gait_round_trip.yaml";
  for (const GaitFile& g : {load_gait_file(walk), odd_gait()}) {
    write_gait_file(g, out);
    const GaitFile back = load_gait_file(out);
    EXPECT_TRUE(back == g) << format_gait_file(g);
    EXPECT_EQ(back.file, out);
  }
}

TEST(GaitFile, EqualityIgnoresLocationsOnly) {
  GaitFile a = odd_gait();
  GaitFile b = odd_gait();
  b.file = "elsewhere.yaml";
  b.curves[0].where = Location{"x", 3, 4};
  EXPECT_TRUE(a == b);
  b.joints[1].offset_deg = 0.0;  // was 5e-324
  EXPECT_FALSE(a == b);
}

TEST(GaitFile, ValidateInMemory) {
  auto error = [](const GaitFile& g) {
    try {
      validate_gait(g);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  GaitFile g = odd_gait();
  EXPECT_EQ(error(g), "no error");
  g.curves[1].expression = "t +";
  EXPECT_EQ(error(g),
            "<input>: curves.curve with spaces: unexpected end of expression (column 4 of "
            "the expression)");
  g = odd_gait();
  g.joints[2].limb = "back";
  EXPECT_EQ(error(g), "<input>: joints.z.limb: undefined limb 'back' (limbs: front, 1)");
  g = odd_gait();
  g.joints[0].sign = 0;
  EXPECT_EQ(error(g), "<input>: joints.lf_hip.sign: expected 1 or -1, found 0");
  g = odd_gait();
  g.stride_frequency_hz = 1.0;
  EXPECT_EQ(error(g), "<input>: give exactly one of stride_frequency_hz or froude");
  g = odd_gait();
  g.joints.clear();
  EXPECT_EQ(error(g), "<input>: joints: a gait needs at least one joint");
  g = odd_gait();
  g.limbs[0].phase = 1.5;
  EXPECT_EQ(error(g), "<input>: limbs.front: expected a phase from 0 to 1, found 1.5");
  g = odd_gait();
  g.curves[0].expression = "1e308*(1 + t)";
  EXPECT_EQ(error(g),
            "<input>: curves.c0: curve is not finite at t = 0.7978515625 stride cycles "
            "(value inf); it must be finite over the whole stride");
}

}  // namespace
}  // namespace animrt
