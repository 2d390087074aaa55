#include "animrt/runtime/yaml_value_editor.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "animrt/core/input_file.hpp"

namespace animrt {
namespace {

std::string dotted(std::span<const std::string_view> path, std::size_t count) {
  std::string key;
  for (std::size_t i = 0; i < count && i < path.size(); ++i) {
    if (i > 0) key += '.';
    key += path[i];
  }
  return key;
}

Location at(const std::string& file, const YAML::Mark& mark) {
  if (mark.is_null()) return {file, 0, 0};
  return {file, mark.line + 1, mark.column + 1};
}

// The value at `key` of `map`, or an invalid node when absent.
YAML::Node child(const YAML::Node& map, std::string_view key) {
  for (auto it = map.begin(); it != map.end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key) return it->second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

// A plain scalar this editor writes: one line, nothing YAML would read as
// structure, a comment, a quote or another type's indicator.
bool plain_and_safe(std::string_view value) {
  if (value.empty() || value.front() == ' ' || value.back() == ' ') return false;
  if (std::string_view("-?:,[]{}#&*!|>'\"%@`").find(value.front()) != std::string_view::npos &&
      !(value.front() == '-' && value.size() > 1 && value[1] != ' ')) {
    return false;
  }
  for (char c : value) {
    if (c == '\n' || c == '\r' || c == '\t' || c == ',' || c == '[' || c == ']' || c == '{' ||
        c == '}' || c == '#' || c == '"' || c == '\'') {
      return false;
    }
  }
  return value.find(": ") == std::string_view::npos;
}

// End (one past) of the scalar that starts at `begin`; npos when it is not
// one this editor can delimit.
std::size_t scalar_end(const std::string& text, std::size_t begin, bool in_flow) {
  if (begin >= text.size()) return std::string::npos;
  const char first = text[begin];
  if (first == '"') {
    for (std::size_t i = begin + 1; i < text.size(); ++i) {
      if (text[i] == '\\') {
        ++i;
      } else if (text[i] == '\n') {
        return std::string::npos;
      } else if (text[i] == '"') {
        return i + 1;
      }
    }
    return std::string::npos;
  }
  if (first == '\'') {
    for (std::size_t i = begin + 1; i < text.size(); ++i) {
      if (text[i] == '\n') return std::string::npos;
      if (text[i] == '\'') {
        if (i + 1 < text.size() && text[i + 1] == '\'') {
          ++i;
          continue;
        }
        return i + 1;
      }
    }
    return std::string::npos;
  }
  if (std::string_view("!&*|>").find(first) != std::string_view::npos) return std::string::npos;
  std::size_t end = begin;
  while (end < text.size()) {
    const char c = text[end];
    if (c == '\n' || c == '\r') break;
    if (in_flow && (c == ',' || c == '}' || c == ']')) break;
    if (c == '#' && end > begin && (text[end - 1] == ' ' || text[end - 1] == '\t')) break;
    ++end;
  }
  while (end > begin && (text[end - 1] == ' ' || text[end - 1] == '\t')) --end;
  return end;
}

std::size_t line_start(const std::string& text, std::size_t pos) {
  const std::size_t nl = text.rfind('\n', pos == 0 ? 0 : pos - 1);
  return (pos == 0 || nl == std::string::npos) ? 0 : nl + 1;
}

// Where a new `key: value` goes in a block map whose keys stand at column
// `column`, the first of them on the line starting at `first_line`: after the
// map's last line of content (comments and blank lines that follow it belong
// to what comes next).
std::size_t block_map_end(const std::string& text, std::size_t first_line, int column) {
  std::size_t last_content_end = text.find('\n', first_line);
  if (last_content_end == std::string::npos) return text.size();
  std::size_t line = last_content_end + 1;
  while (line < text.size()) {
    std::size_t end = text.find('\n', line);
    if (end == std::string::npos) end = text.size();
    std::size_t indent = line;
    while (indent < end && text[indent] == ' ') ++indent;
    const bool blank = indent == end || text[indent] == '\r';
    const bool comment = !blank && text[indent] == '#';
    if (!blank && !comment) {
      const int col = static_cast<int>(indent - line);
      const std::string_view rest(text.data() + indent, end - indent);
      if (col < column) break;
      if (col == column && line == indent && (rest.starts_with("---") || rest.starts_with("..."))) {
        break;
      }
      last_content_end = end;
    }
    line = end + 1;
  }
  return last_content_end;
}

// The closing brace of the flow map that opens at `open`; npos if unclosed.
std::size_t flow_map_close(const std::string& text, std::size_t open) {
  int depth = 0;
  for (std::size_t i = open; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      const std::size_t end = scalar_end(text, i, true);
      if (end == std::string::npos) return std::string::npos;
      i = end - 1;
    } else if (c == '#' && i > 0 && (text[i - 1] == ' ' || text[i - 1] == '\n')) {
      i = text.find('\n', i);
      if (i == std::string::npos) return i;
    } else if (c == '{' || c == '[') {
      ++depth;
    } else if (c == '}' || c == ']') {
      if (--depth == 0) return c == '}' ? i : std::string::npos;
    }
  }
  return std::string::npos;
}

}  // namespace

YamlValueEditor::YamlValueEditor(std::string text, std::string file_name)
    : text_(std::move(text)), file_(std::move(file_name)) {}

void YamlValueEditor::set(std::span<const std::string_view> path, std::string_view value) {
  const std::string key = dotted(path, path.size());
  if (path.empty()) throw InputError({file_, 0, 0}, "", "no key given to edit");
  if (!plain_and_safe(value)) {
    throw InputError({file_, 0, 0}, key,
                     "cannot write " + quote(value) + ": not a one-line plain YAML scalar");
  }
  YAML::Node root;
  try {
    root = YAML::Load(text_);
  } catch (const YAML::Exception& e) {
    throw InputError(at(file_, e.mark), "", e.msg);
  }
  YAML::Node node = root;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    if (!node.IsMap()) {
      throw InputError(at(file_, node.Mark()), dotted(path, i), "expected a map");
    }
    YAML::Node next = child(node, path[i]);
    if (!next.IsDefined()) {
      throw InputError(at(file_, node.Mark()), dotted(path, i + 1),
                       "missing: only the last key of a path is added");
    }
    node = next;
  }
  if (!node.IsMap()) {
    throw InputError(at(file_, node.Mark()), dotted(path, path.size() - 1), "expected a map");
  }
  const bool flow = node.Style() == YAML::EmitterStyle::Flow;
  const YAML::Node target = child(node, path.back());
  if (target.IsDefined()) {
    if (!target.IsScalar()) {
      throw InputError(at(file_, target.Mark()), key,
                       "expected a single value, found a list or map");
    }
    const auto begin = static_cast<std::size_t>(target.Mark().pos);
    const std::size_t end = scalar_end(text_, begin, flow);
    // The bytes found must read back as the node's value: anything else
    // (a tag, a multi-line scalar) is not edited blindly.
    bool same = end != std::string::npos;
    if (same) {
      try {
        const YAML::Node back = YAML::Load("[" + text_.substr(begin, end - begin) + "]");
        same = back.IsSequence() && back.size() == 1 && back[0].IsScalar() &&
               back[0].Scalar() == target.Scalar();
      } catch (const YAML::Exception&) {
        same = false;
      }
    }
    if (!same) {
      throw InputError(at(file_, target.Mark()), key,
                       "cannot edit this value in place (write it as a one-line scalar)");
    }
    text_.replace(begin, end - begin, value);
    return;
  }
  const auto map_pos = static_cast<std::size_t>(node.Mark().pos);
  const std::string entry = std::string(path.back()) + ": " + std::string(value);
  if (flow) {
    const std::size_t close = flow_map_close(text_, map_pos);
    if (close == std::string::npos) {
      throw InputError(at(file_, node.Mark()), key,
                       "cannot find the end of this map to add the key");
    }
    std::size_t last = close;
    while (last > map_pos + 1 && (text_[last - 1] == ' ' || text_[last - 1] == '\n')) --last;
    const bool empty = last == map_pos + 1;
    text_.insert(last, empty ? entry : ", " + entry);
    return;
  }
  if (node.size() == 0 || node.Mark().is_null()) {
    throw InputError(at(file_, node.Mark()), key, "cannot add a key to this map in place");
  }
  const YAML::Mark first_key = node.begin()->first.Mark();
  const std::size_t insert = block_map_end(
      text_, line_start(text_, static_cast<std::size_t>(first_key.pos)), first_key.column);
  const std::string line = std::string(static_cast<std::size_t>(first_key.column), ' ') + entry;
  if (insert >= text_.size()) {
    if (!text_.empty() && text_.back() != '\n') text_ += '\n';
    text_ += line + '\n';
  } else {
    text_.insert(insert, "\n" + line);
  }
}

std::string read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, 0, 0}, "", std::string("cannot read: ") + std::strerror(errno));
  std::ostringstream all;
  all << in.rdbuf();
  return all.str();
}

void replace_file_contents(const std::string& path, const std::string& expected,
                           const std::string& text) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw InputError({path, 0, 0}, "", std::string("cannot write back: ") + std::strerror(errno));
  }
  // No write bit is read-only even for root: someone protected the file.
  if ((st.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0 || ::access(path.c_str(), W_OK) != 0) {
    throw InputError({path, 0, 0}, "", "is read-only; nothing was written");
  }
  if (read_whole_file(path) != expected) {
    throw InputError({path, 0, 0}, "",
                     "changed on disk since this command read it; nothing was written (run it "
                     "again on the new file)");
  }
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, st.st_mode & 07777);
  if (fd < 0) {
    throw InputError(
        {path, 0, 0}, "",
        "cannot write " + quote_path(tmp) + ": " + std::strerror(errno) + "; nothing was written");
  }
  int error = write_all(fd, text.data(), text.size());
  if (error == 0 && ::fchmod(fd, st.st_mode & 07777) != 0) error = errno;
  if (error == 0 && ::fsync(fd) != 0) error = errno;
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error == 0 && ::rename(tmp.c_str(), path.c_str()) != 0) error = errno;
  if (error != 0) {
    ::unlink(tmp.c_str());
    throw InputError(
        {path, 0, 0}, "",
        std::string("cannot write back: ") + std::strerror(error) + "; the file is unchanged");
  }
}

}  // namespace animrt
