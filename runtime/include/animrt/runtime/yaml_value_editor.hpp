#pragma once
// Edits scalar values of a YAML file's text where they stand: the bytes of
// the value are replaced at their line and column and nothing else moves, so
// the comments, the layout and the style (flow or block) of a hand-written
// file survive. What a tool writes back into a robot file goes through here;
// a YAML rewrite through a tree would drop the comments.

#include <span>
#include <string>
#include <string_view>

#include "animrt/core/error.hpp"

namespace animrt {

class YamlValueEditor {
 public:
  // `file_name` names the text in errors.
  YamlValueEditor(std::string text, std::string file_name);

  // Sets the value at `path` (map keys from the root) to `value`, a plain
  // scalar (a number, a word). The value keeps its place; a key missing from
  // the last map is added to it (a flow map: before its closing brace; a
  // block map: a line after its last entry, at its keys' indentation). A
  // missing intermediate key, a value that is not a scalar, a scalar this
  // editor cannot delimit (multi-line, tagged, an alias) or a value that is
  // not a plain scalar is an InputError naming the file, line and key.
  void set(std::span<const std::string_view> path, std::string_view value);
  void set(std::initializer_list<std::string_view> path, std::string_view value) {
    set(std::span<const std::string_view>(path.begin(), path.size()), value);
  }

  const std::string& text() const { return text_; }

 private:
  std::string text_;
  std::string file_;
};

// Replaces `path` with `text` as one step: the text goes to PATH.tmp beside
// it (flushed, with the old file's permissions) and is renamed over it, so
// the file is never half-written. `expected` is what the file held when the
// edit began: a file that changed on disk since, or that is read-only, is an
// InputError of one line and the file is left alone.
void replace_file_contents(const std::string& path, const std::string& expected,
                           const std::string& text);

// The whole content of a file (InputError naming it when it cannot be read).
std::string read_whole_file(const std::string& path);

}  // namespace animrt
