#include "animrt/controllers/seqnet/joint_csv.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::seqnet {
namespace {

[[noreturn]] void fail(const std::string& file, int line, int column, const std::string& key,
                       const std::string& message) {
  throw InputError(Location{file, line, column}, key, message);
}

}  // namespace

bool is_joint_column(const std::string& name) {
  // The corpus's pose of the body, not joints; a joint may be named
  // torso_lean (the animatronic's is).
  for (const char* pose : {"time_s", "torso_x", "torso_y", "torso_z", "torso_yaw"}) {
    if (name == pose) return false;
  }
  return true;
}

JointCsv read_joint_csv(const std::string& file) {
  const std::string text = read_input_file(file);
  JointCsv t;
  std::vector<std::string> names;
  std::vector<std::size_t> use;
  std::string line;
  int number = 0;
  // A spreadsheet's "CSV UTF-8" starts with a byte order mark: not part of
  // the first column's name.
  for (std::size_t at = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0; at < text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    line.assign(text, at, end - at);
    at = end + 1;
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::vector<int> columns;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      // Blanks round a cell (", " between cells) are no part of it.
      std::size_t from = start, to = comma == std::string::npos ? line.size() : comma;
      while (from < to && (line[from] == ' ' || line[from] == '\t')) ++from;
      while (to > from && (line[to - 1] == ' ' || line[to - 1] == '\t')) --to;
      cells.push_back(line.substr(from, to - from));
      columns.push_back(static_cast<int>(from) + 1);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (names.empty()) {
      names = cells;
      for (std::size_t c = 0; c < names.size(); ++c) {
        if (is_joint_column(names[c])) {
          use.push_back(c);
          t.joints.push_back(names[c]);
        }
      }
      if (t.joints.empty()) fail(file, number, 1, "", "no joint columns (only time_s and torso_*)");
      continue;
    }
    if (cells.size() != names.size()) {
      fail(file, number, 1, "",
           std::to_string(cells.size()) + " columns, the header has " +
               std::to_string(names.size()));
    }
    std::vector<double> row;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      std::size_t used = 0;
      double v = 0;
      try {
        v = std::stod(cells[c], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != cells[c].size() || !std::isfinite(v)) {
        fail(file, number, columns[c], names[c], quote(cells[c]) + " is not a finite number");
      }
      row.push_back(v);
    }
    std::vector<double> joints;
    for (std::size_t c : use) joints.push_back(row[c]);
    t.rows.push_back(std::move(joints));
    t.lines.push_back(number);
  }
  if (names.empty()) fail(file, 0, 0, "", "empty file: no header line");
  return t;
}

void write_joint_csv(const std::string& file, const std::vector<std::string>& joints,
                     const Eigen::MatrixXd& frames) {
  std::string text;
  for (std::size_t j = 0; j < joints.size(); ++j) text += (j == 0 ? "" : ",") + joints[j];
  text += '\n';
  char buf[32];
  for (Eigen::Index f = 0; f < frames.cols(); ++f) {
    for (Eigen::Index j = 0; j < frames.rows(); ++j) {
      const auto r = std::to_chars(buf, buf + sizeof buf, frames(j, f));
      if (j > 0) text += ',';
      text.append(buf, r.ptr);
    }
    text += '\n';
  }
  std::ofstream out(file, std::ios::trunc);
  out << text;
  if (!out) throw std::runtime_error(file + ": cannot write");
}

}  // namespace animrt::seqnet
