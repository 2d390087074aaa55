#include "animrt/core/error.hpp"

#include <gtest/gtest.h>

#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

TEST(InputError, FormatsFileLineColumnKey) {
  InputError e(Location{"robot.yaml", 12, 7}, "joints[3].home_deg", "expected a number");
  EXPECT_STREQ(e.what(), "robot.yaml:12:7: joints[3].home_deg: expected a number");
}

TEST(InputError, LongValuesAreElidedInTheMiddle) {
  EXPECT_EQ(elide("short"), "short");
  const std::string value = std::string(50, 'a') + std::string(1000, 'm') + std::string(50, 'z');
  const std::string out = elide(value);
  EXPECT_EQ(out, std::string(40, 'a') + "[... 1020 characters ...]" + std::string(40, 'z'));
  EXPECT_EQ(quote(value), '"' + out + '"');
  EXPECT_EQ(quote(std::string(80, 'x')), '"' + std::string(80, 'x') + '"');
}

TEST(InputError, SixtyMegabyteValueGivesAShortLine) {
  const std::string huge(60u << 20, 'x');
  // A message, a key and a file name built from it: every part of the line
  // is bounded, the parts themselves stay whole.
  const InputError built(Location{huge, 1, 1}, huge, "found " + quote(huge) + " and " + huge);
  EXPECT_LT(std::string(built.what()).size(), 2500u);
  EXPECT_EQ(built.key().size(), huge.size());
}

TEST(InputError, LongYamlValueAndKeyAreQuotedShort) {
  // yaml-cpp parses a 60 MB scalar in half a minute: 1 MB shows the same.
  const std::string big(1u << 20, 'x');
  const YamlNode doc = YamlNode::load_string("rate: " + big + "\n? " + big + "\n: 1\n", "t.yaml");
  try {
    (void)doc.at("rate").as_double();
    ADD_FAILURE() << "a string read as a number";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_LT(what.size(), 200u) << what.substr(0, 300);
    EXPECT_EQ(what.rfind("t.yaml:1:7: rate: expected a number, found \"xxx", 0), 0u)
        << what.substr(0, 300);
  }
  try {
    doc.allow_only({"rate"});
    ADD_FAILURE() << "an unknown key passed";
  } catch (const InputError& e) {
    EXPECT_LT(std::string(e.what()).size(), 200u) << std::string(e.what()).substr(0, 300);
  }
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

// A short list of plain values is shown as written, so that a swapped
// pair or a missing item can be seen; lists of maps and long lists are
// named, not printed.
TEST(YamlNode, AListFoundWhereAValueBelongsIsShownWhenShort) {
  const auto found = [](const std::string& text) {
    return error_of(text, [](const YamlNode& n) { (void)n.at("v").as_string(); });
  };
  EXPECT_EQ(found("v: [7, -4, -12, 4]\n"),
            "t.yaml:1:4: v: expected a string, found [7, -4, -12, 4]");
  EXPECT_EQ(found("v: []\n"), "t.yaml:1:4: v: expected a string, found []");
  EXPECT_EQ(found("v: [{a: 1}]\n"), "t.yaml:1:4: v: expected a string, found a list");
  EXPECT_EQ(found("v: [1, 2, 3, 4, 5, 6, 7, 8, 9]\n"),
            "t.yaml:1:4: v: expected a string, found a list of 9 items");
  EXPECT_EQ(found("v: [" + std::string(90, 'x') + "]\n"),
            "t.yaml:1:4: v: expected a string, found a list of 1 item");
}

// yaml-cpp reads the first document of a file and ignores the rest: a
// second one is refused where it begins, not silently dropped.
TEST(YamlNode, ASecondDocumentIsRefusedWhereItBegins) {
  const auto error = [](const std::string& text) { return error_of(text, [](const YamlNode&) {}); };
  EXPECT_EQ(error("name: a\n---\nname: b\n"),
            "t.yaml:2:1: a second YAML document: a configuration file holds one (remove the "
            "\"---\" and what follows, or merge it into the first)");
  EXPECT_EQ(error("---\nname: a\n...\n"), "no error");
}

// A quoted value may run over lines in YAML; in a configuration that means a
// missing closing quote, which swallowed the keys below it ("loop: required
// key is missing"). It is named where the value opens.
TEST(YamlNode, AQuotedValueWithoutItsClosingQuoteIsRefusedWhereItOpens) {
  const auto error = [](const std::string& text) { return error_of(text, [](const YamlNode&) {}); };
  EXPECT_EQ(error("name: \"head\nloop: {rate_hz: 100}\nnote: \"x\"\n"),
            "t.yaml:1:7: the quoted value runs on to line 3 (its closing \" missing?): write it "
            "on one line");
  EXPECT_EQ(error("a: 1\nname: 'head\nloop: 2 # it's\n"),
            "t.yaml:2:7: the quoted value runs on to line 3 (its closing ' missing?): write it on "
            "one line");
  EXPECT_EQ(error("a: [1, \"b]\n"), "t.yaml:1:8: the quoted value has no closing \"");
  // After a byte order mark and a name in two-byte UTF-8, still its place.
  EXPECT_EQ(error("\xEF\xBB\xBFn: Zo\xC3\xAB\nname: \"head\nx: \"\n"),
            "t.yaml:2:7: the quoted value runs on to line 3 (its closing \" missing?): write it "
            "on one line");
  // A long value folded over lines (as PyYAML writes one at 80 columns),
  // escaped and doubled quotes inside a value on one line, a block scalar
  // over lines: loaded.
  EXPECT_EQ(error("note: 'a long note that says: the figure\n  nods twice'\nb: \"x\n  y\"\n"),
            "no error");
  EXPECT_EQ(error("a: \"say \\\"hi\\\"\"\nb: 'it''s'\nc: |\n  two\n  lines\n"), "no error");
}

// YAML is UTF-8 text: a Latin-1 byte, a broken sequence or a control
// character (a binary file) is named at its line and column before parsing.
TEST(YamlNode, BytesThatAreNotUtf8TextAreRefusedWhereTheyAre) {
  const auto error = [](const std::string& text) { return error_of(text, [](const YamlNode&) {}); };
  EXPECT_EQ(error("a: 1\nname: Zo\xEB\n"),
            "t.yaml:2:9: not UTF-8 text (byte 0xEB): save the file as UTF-8");
  EXPECT_EQ(error("name: \xC0\xAF\n"),
            "t.yaml:1:7: not UTF-8 text (byte 0xC0): save the file as UTF-8");
  EXPECT_EQ(error("name: \xED\xA0\x80\n"),  // a UTF-16 surrogate
            "t.yaml:1:7: not UTF-8 text (byte 0xED): save the file as UTF-8");
  EXPECT_EQ(error("name: \xE2\x82\n"),
            "t.yaml:1:7: not UTF-8 text (byte 0xE2): save the file as UTF-8");
  EXPECT_EQ(error(std::string("name: a\0b\n", 10)),
            "t.yaml:1:8: control character 0x00 (a binary or damaged file?)");
  EXPECT_EQ(error("\x01\x02\x03"),
            "t.yaml:1:1: control character 0x01 (a binary or damaged file?)");
  // Characters past the first byte count as one column each.
  EXPECT_EQ(error("n\xC3\xA9: \xE2\x82\xAC\xF0\x9F\x90\xB4\xFF\n"),
            "t.yaml:1:7: not UTF-8 text (byte 0xFF): save the file as UTF-8");
  EXPECT_EQ(error("\xEF\xBB\xBFname: Zo\xC3\xAB \xF0\x9F\x90\xB4\r\nx: a\tb\n"), "no error");
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
