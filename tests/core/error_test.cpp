#include "animrt/core/error.hpp"

#include <gtest/gtest.h>

#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

TEST(InputError, FormatsFileLineColumnKey) {
  InputError e(Location{"robot.yaml", 12, 7}, "joints[3].home_deg", "expected a number");
  EXPECT_STREQ(e.what(), "robot.yaml:12:7: joints[3].home_deg: expected a number");
}

TEST(InputError, OmitsUnknownParts) {
  InputError e(Location{"robot.yaml", 0, 0}, "", "file is empty");
  EXPECT_STREQ(e.what(), "robot.yaml: file is empty");
}

std::string error_of(const std::string& text, void (*use)(const YamlNode&)) {
  try {
    use(YamlNode::load_string(text, "t.yaml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(YamlNode, UnknownKeyIsReportedAtTheKey) {
  auto msg = error_of("a: 1\n  \nbogus: 2\n", [](const YamlNode& n) { n.allow_only({"a"}); });
  EXPECT_EQ(msg, "t.yaml:3:1: bogus: unknown key (expected one of: a)");
}

TEST(YamlNode, WrongTypeNamesWhatWasFound) {
  auto msg = error_of("outer:\n  rate: fast\n",
                      [](const YamlNode& n) { (void)n.at("outer").at("rate").as_double(); });
  EXPECT_EQ(msg, "t.yaml:2:9: outer.rate: expected a number, found \"fast\"");
}

TEST(YamlNode, MissingKeyNamesTheFullPath) {
  auto msg = error_of("outer:\n  x: 1\n", [](const YamlNode& n) { (void)n.at("outer").at("y"); });
  EXPECT_EQ(msg, "t.yaml:2:3: outer.y: required key is missing");
}

TEST(YamlNode, RangeCheckAndListPaths) {
  auto msg = error_of("v: [1, 2, 300]\n", [](const YamlNode& n) {
    for (const auto& item : n.at("v").items()) (void)item.as_int_in(0, 255);
  });
  EXPECT_EQ(msg, "t.yaml:1:11: v[2]: expected an integer from 0 to 255, found \"300\"");
}

TEST(YamlNode, SyntaxErrorHasALine) {
  auto msg = error_of("a: [1, 2\nb: 3\n", [](const YamlNode&) {});
  EXPECT_NE(msg.find("t.yaml:"), std::string::npos);
  EXPECT_NE(msg.find("YAML syntax error"), std::string::npos);
}

TEST(YamlNode, DuplicateKeyIsAnError) {
  auto msg = error_of("a: 1\na: 2\n", [](const YamlNode& n) { n.allow_only({"a"}); });
  EXPECT_EQ(msg, "t.yaml:2:1: a: duplicate key");
}

}  // namespace
}  // namespace animrt

namespace animrt {
namespace {

TEST(YamlNode, AnEmptyValueIsReportedAtItsKey) {
  auto msg = error_of("a: 1\nbuses:\njoints: {}\n",
                      [](const YamlNode& n) { (void)n.at("buses").entries(); });
  EXPECT_EQ(msg, "t.yaml:2:1: buses: expected a map, found nothing");
}

}  // namespace
}  // namespace animrt
