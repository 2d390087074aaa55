#include "animrt/core/yaml_doc.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <streambuf>
#include <string_view>

#include "animrt/core/input_file.hpp"

namespace animrt {
namespace {

std::string join_path(const std::string& parent, std::string_view key) {
  if (parent.empty()) return std::string(key);
  return parent + "." + std::string(key);
}

Location location_of(const std::string& file, const YAML::Mark& mark) {
  if (mark.is_null()) return Location{file, 0, 0};
  return Location{file, mark.line + 1, mark.column + 1};
}

// Where a quoted scalar that starts at `open` (its quote) ends, or npos.
std::size_t closing_quote(const std::string& text, std::size_t open) {
  const char quote = text[open];
  for (std::size_t i = open + 1; i < text.size(); ++i) {
    if (quote == '"' && text[i] == '\\') {
      ++i;  // an escape: the next character is not the end
    } else if (text[i] == quote) {
      if (quote == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
        ++i;  // '' is a quote inside a single-quoted value
      } else {
        return i;
      }
    }
  }
  return std::string::npos;
}

// Whether `line` reads as a key: "name:" or "- name:", indented or not, with
// a blank or the line's end after the colon.
bool reads_as_key(std::string_view line) {
  std::size_t i = line.find_first_not_of(" \t");
  if (i == std::string_view::npos) return false;
  if (line[i] == '-') {
    const std::size_t item = line.find_first_not_of(' ', i + 1);
    if (item == i + 1 || item == std::string_view::npos) return false;
    i = item;
  }
  const auto letter = [](char c) {
    return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
  };
  if (!letter(line[i])) return false;
  while (i < line.size() && (letter(line[i]) || std::isdigit(static_cast<unsigned char>(line[i])) ||
                             line[i] == '.' || line[i] == '-')) {
    ++i;
  }
  if (i == line.size() || line[i] != ':') return false;
  ++i;
  return i == line.size() || line[i] == ' ' || line[i] == '\t' || line[i] == '\r';
}

// Walks the first document as the parser meets it, before any tree exists:
// stops at the first node past the limit, and at a quoted value that runs on
// over lines that read as keys. YAML lets a quoted value go on to the lines
// below (a tool may fold a long one); one that takes in keys has lost its
// closing quote, and the file would otherwise load as something else (the
// keys swallowed, then reported missing).
class DocumentChecks : public YAML::EventHandler {
 public:
  DocumentChecks(const std::string& file, const std::string& text) : file_(file), text_(text) {}
  // Where the last document it met began.
  const YAML::Mark& document_start() const { return document_; }

  void OnDocumentStart(const YAML::Mark& mark) override { document_ = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { count(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { count(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    count(mark);
    check_quoted(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    count(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    count(mark);
  }
  void OnMapEnd() override {}

 private:
  void count(const YAML::Mark& mark) {
    if (++nodes_ <= kMaxYamlNodes) return;
    throw InputError(location_of(file_, mark), "",
                     "more than " + std::to_string(kMaxYamlNodes) +
                         " YAML nodes (values, lists and maps); a configuration needs far fewer");
  }

  void check_quoted(const YAML::Mark& mark) const {
    // The mark counts bytes after a byte order mark.
    const std::size_t bom = text_.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    const auto open = static_cast<std::size_t>(mark.pos) + bom;
    if (mark.pos < 0 || open >= text_.size() || (text_[open] != '"' && text_[open] != '\'')) return;
    const std::size_t close = closing_quote(text_, open);
    const auto end = close == std::string::npos ? text_.end() : text_.begin() + close;
    const auto lines = std::count(text_.begin() + open, end, '\n');
    if (lines == 0) return;
    // A value folded over lines by a tool that writes YAML (PyYAML wraps at
    // 80 columns) is text; one that runs over keys has lost its quote.
    if (close != std::string::npos && !swallows_a_key(open, close)) return;
    const std::string quote = text_[open] == '"' ? "\"" : "'";
    throw InputError(location_of(file_, mark), "",
                     close == std::string::npos
                         ? "the quoted value has no closing " + quote
                         : "the quoted value runs on to line " +
                               std::to_string(mark.line + 1 + lines) + " (its closing " + quote +
                               " missing?): write it on one line");
  }

  // Whether a line after the first of text_[open, close) reads as a key.
  bool swallows_a_key(std::size_t open, std::size_t close) const {
    for (std::size_t at = text_.find('\n', open); at < close; at = text_.find('\n', at + 1)) {
      const std::size_t stop = std::min(close, text_.find('\n', at + 1));
      if (reads_as_key(std::string_view(text_).substr(at + 1, stop - at - 1))) return true;
    }
    return false;
  }

  const std::string& file_;
  const std::string& text_;
  std::size_t nodes_ = 0;
  YAML::Mark document_;
};

// Reads a string in place, without the copy an istringstream makes.
class TextBuffer : public std::streambuf {
 public:
  explicit TextBuffer(const std::string& text) {
    char* begin = const_cast<char*>(text.data());
    setg(begin, begin, begin + text.size());
  }
};

// YAML is UTF-8 text without control characters other than tab, LF and CR
// (a BOM at the start is allowed). yaml-cpp takes any bytes, so a Latin-1
// name or a binary file used to load or fail as something else; this names
// the first byte that breaks the rule, at its line and column.
void check_text(const std::string& text, const std::string& file) {
  int line = 1, column = 1;
  const auto hex = [](unsigned char byte) {
    char digits[8];
    std::snprintf(digits, sizeof digits, "0x%02X", byte);
    return std::string(digits);
  };
  const auto fail = [&](const std::string& message) {
    throw InputError(Location{file, line, column}, "", message);
  };
  std::size_t i = 0;
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;
  while (i < text.size()) {
    const auto byte = static_cast<unsigned char>(text[i]);
    std::size_t length = 1;
    std::uint32_t code = byte;
    if (byte >= 0x80) {
      length = byte >= 0xC2 && byte <= 0xDF   ? 2
               : byte >= 0xE0 && byte <= 0xEF ? 3
               : byte >= 0xF0 && byte <= 0xF4 ? 4
                                              : 0;
      bool valid = length > 0 && i + length <= text.size();
      code = length == 2 ? byte & 0x1Fu : length == 3 ? byte & 0x0Fu : byte & 0x07u;
      for (std::size_t k = 1; valid && k < length; ++k) {
        const auto next = static_cast<unsigned char>(text[i + k]);
        valid = (next & 0xC0) == 0x80;
        code = (code << 6) | (next & 0x3Fu);
      }
      // Overlong forms, UTF-16 surrogates and code points past U+10FFFF.
      valid = valid && !(length == 3 && code < 0x800) && !(length == 4 && code < 0x10000) &&
              !(code >= 0xD800 && code <= 0xDFFF) && code <= 0x10FFFF;
      if (!valid) fail("not UTF-8 text (byte " + hex(byte) + "): save the file as UTF-8");
    } else if (byte < 0x20 && byte != '\t' && byte != '\n' && byte != '\r') {
      fail("control character " + hex(byte) + " (a binary or damaged file?)");
    }
    if (byte == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
    i += length;
  }
}

}  // namespace

YamlNode::YamlNode(std::shared_ptr<const std::string> file, YAML::Node node, std::string path,
                   YAML::Mark mark)
    : file_(std::move(file)), node_(std::move(node)), path_(std::move(path)), mark_(mark) {}

YamlNode YamlNode::load_file(const std::string& path) {
  return load_string(read_input_file(path, kMaxYamlFileBytes), path);
}

YamlNode YamlNode::load_string(const std::string& text, const std::string& file_name) {
  auto file = std::make_shared<const std::string>(file_name);
  if (text.size() > kMaxYamlFileBytes) {
    throw InputError(Location{file_name, 0, 0}, "",
                     "is " + std::to_string(text.size()) + " bytes, more than the " +
                         std::to_string(kMaxYamlFileBytes >> 20) + " MiB limit");
  }
  check_text(text, file_name);
  YAML::Node root;
  try {
    TextBuffer buffer(text);
    std::istream in(&buffer);
    YAML::Parser parser(in);
    DocumentChecks checks(file_name, text);
    parser.HandleNextDocument(checks);
    // yaml-cpp's Load reads the first document and ignores the rest.
    if (parser.HandleNextDocument(checks)) {
      throw InputError(location_of(file_name, checks.document_start()), "",
                       "a second YAML document: a configuration file holds one (remove the "
                       "\"---\" and what follows, or merge it into the first)");
    }
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(location_of(file_name, e.mark), "", "YAML syntax error: " + e.msg);
  }
  if (!root || root.IsNull()) throw InputError(Location{file_name, 0, 0}, "", "file is empty");
  return YamlNode(file, root, "", root.Mark());
}

Location YamlNode::location() const {
  YAML::Mark mark = mark_;
  // An empty value carries the mark of the next token: keep the key's.
  if (node_ && !node_.IsNull() && !node_.Mark().is_null()) mark = node_.Mark();
  return location_of(*file_, mark);
}

void YamlNode::fail(const std::string& message) const {
  throw InputError(location(), path_, message);
}

YamlNode YamlNode::child(const YAML::Node& node, std::string path) const {
  return YamlNode(file_, node, std::move(path), node.Mark().is_null() ? mark_ : node.Mark());
}

std::string YamlNode::describe() const {
  if (!node_ || node_.IsNull()) return "nothing";
  if (node_.IsMap()) return "a map";
  if (node_.IsSequence()) {
    // A short list of plain values is shown, so that a wrong order or
    // count can be seen in the message ("found [7, -4, -12, 4]").
    constexpr std::size_t kShownItems = 8, kShownChars = 80;
    const std::size_t n = node_.size();
    const std::string counted = "a list of " + std::to_string(n) + (n == 1 ? " item" : " items");
    if (n > kShownItems) return counted;
    std::string text = "[";
    for (std::size_t i = 0; i < n; ++i) {
      if (!node_[i].IsScalar()) return "a list";
      text += (i > 0 ? ", " : "") + node_[i].Scalar();
    }
    return text.size() < kShownChars ? text + "]" : counted;
  }
  return quote(node_.Scalar());
}

bool YamlNode::has(std::string_view key) const {
  return node_.IsMap() && node_[std::string(key)].IsDefined();
}

std::optional<YamlNode> YamlNode::find(std::string_view key) const {
  if (!node_.IsMap()) fail("expected a map, found " + describe());
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key) {
      YAML::Node value = it->second;
      YAML::Mark mark = value.Mark().is_null() || value.IsNull() ? it->first.Mark() : value.Mark();
      return YamlNode(file_, value, join_path(path_, key), mark);
    }
  }
  return std::nullopt;
}

YamlNode YamlNode::at(std::string_view key) const {
  auto found = find(key);
  if (!found) throw InputError(location(), join_path(path_, key), "required key is missing");
  return *found;
}

void YamlNode::allow_only(std::initializer_list<std::string_view> keys) const {
  allow_only(std::span<const std::string_view>(keys.begin(), keys.size()));
}

void YamlNode::allow_only(std::span<const std::string_view> keys) const {
  if (!node_.IsMap()) fail("expected a map, found " + describe());
  std::set<std::string> seen;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string key =
        it->first.IsScalar() ? it->first.Scalar() : std::string("<complex key>");
    bool known = false;
    for (auto k : keys) known = known || (k == key);
    Location where = location_of(*file_, it->first.Mark());
    if (!known) {
      std::string expected;
      for (auto k : keys) expected += (expected.empty() ? "" : ", ") + std::string(k);
      throw InputError(where, join_path(path_, key),
                       "unknown key (expected one of: " + expected + ")");
    }
    if (!seen.insert(key).second) throw InputError(where, join_path(path_, key), "duplicate key");
  }
}

std::vector<std::pair<std::string, YamlNode>> YamlNode::entries() const {
  if (!node_.IsMap()) fail("expected a map, found " + describe());
  std::vector<std::pair<std::string, YamlNode>> out;
  std::set<std::string> seen;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    if (!it->first.IsScalar()) {
      throw InputError(location_of(*file_, it->first.Mark()), path_, "keys must be plain names");
    }
    const std::string key = it->first.Scalar();
    if (!seen.insert(key).second) {
      throw InputError(location_of(*file_, it->first.Mark()), join_path(path_, key),
                       "duplicate key");
    }
    YAML::Mark mark = it->second.IsNull() ? it->first.Mark() : it->second.Mark();
    out.emplace_back(key, YamlNode(file_, it->second, join_path(path_, key), mark));
  }
  return out;
}

std::vector<YamlNode> YamlNode::items() const {
  if (!node_.IsSequence()) fail("expected a list, found " + describe());
  std::vector<YamlNode> out;
  std::size_t index = 0;
  for (auto it = node_.begin(); it != node_.end(); ++it, ++index) {
    out.push_back(child(*it, path_ + "[" + std::to_string(index) + "]"));
  }
  return out;
}

std::string YamlNode::as_string() const {
  if (!node_.IsScalar()) fail("expected a string, found " + describe());
  return node_.Scalar();
}

double YamlNode::as_double() const {
  if (!node_.IsScalar()) fail("expected a number, found " + describe());
  const std::string& s = node_.Scalar();
  double value = 0.0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) {
    fail("expected a number, found " + describe());
  }
  if (!std::isfinite(value)) fail("expected a finite number, found " + describe());
  return value;
}

std::int64_t YamlNode::as_int() const {
  if (!node_.IsScalar()) fail("expected an integer, found " + describe());
  const std::string& s = node_.Scalar();
  std::int64_t value = 0;
  const char* begin = s.data();
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    begin += 2;
    base = 16;
  }
  auto [end, ec] = std::from_chars(begin, s.data() + s.size(), value, base);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) {
    fail("expected an integer, found " + describe());
  }
  return value;
}

bool YamlNode::as_bool() const {
  if (!node_.IsScalar()) fail("expected true or false, found " + describe());
  const std::string& s = node_.Scalar();
  if (s == "true") return true;
  if (s == "false") return false;
  fail("expected true or false, found " + describe());
}

double YamlNode::as_double_in(double lo, double hi) const {
  double value = as_double();
  if (value < lo || value > hi) {
    std::ostringstream msg;
    msg << "expected a number from " << lo << " to " << hi << ", found " << describe();
    fail(msg.str());
  }
  return value;
}

std::int64_t YamlNode::as_int_in(std::int64_t lo, std::int64_t hi) const {
  std::int64_t value = as_int();
  if (value < lo || value > hi) {
    fail("expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi) +
         ", found " + describe());
  }
  return value;
}

double YamlNode::as_positive_double() const {
  double value = as_double();
  if (!(value > 0.0)) fail("expected a positive number, found " + describe());
  return value;
}

double YamlNode::get_double(std::string_view key, double fallback) const {
  auto found = find(key);
  return found ? found->as_double() : fallback;
}

std::string YamlNode::get_string(std::string_view key, const std::string& fallback) const {
  auto found = find(key);
  return found ? found->as_string() : fallback;
}

bool YamlNode::get_bool(std::string_view key, bool fallback) const {
  auto found = find(key);
  return found ? found->as_bool() : fallback;
}

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace animrt
