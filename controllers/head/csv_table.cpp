#include "csv_table.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::head {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r");
    const auto e = cell.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

}  // namespace

int CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return static_cast<int>(i);
  }
  return -1;
}

int CsvTable::require(const std::string& name) const {
  const int c = column(name);
  if (c < 0) {
    std::string have;
    for (const auto& h : header) have += (have.empty() ? "" : ", ") + h;
    throw InputError(Location{file, 1, 1}, name,
                     "missing column " + quote(name) + " in the header (found: " + have + ")");
  }
  return c;
}

CsvTable read_csv_table(const std::string& path) {
  std::istringstream in(read_input_file(path));
  CsvTable table;
  table.file = path;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (table.header.empty()) {
      table.header = split(line);
      continue;
    }
    const auto cells = split(line);
    if (cells.size() != table.header.size()) {
      throw InputError(Location{path, line_no, 1}, "",
                       "expected " + std::to_string(table.header.size()) + " values, found " +
                           std::to_string(cells.size()));
    }
    std::vector<double> row(cells.size());
    int col = 1;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      char* end = nullptr;
      errno = 0;
      row[i] = std::strtod(cells[i].c_str(), &end);
      if (cells[i].empty() || *end != '\0' || errno != 0 || !std::isfinite(row[i])) {
        throw InputError(Location{path, line_no, col}, table.header[i],
                         "expected a number, found " + quote(cells[i]));
      }
      col += static_cast<int>(cells[i].size()) + 1;
    }
    table.rows.push_back(std::move(row));
    table.lines.push_back(line_no);
  }
  if (table.header.empty())
    throw InputError(Location{path, 0, 0}, "", "empty file, expected a CSV header row");
  if (table.rows.empty())
    throw InputError(Location{path, line_no, 0}, "", "no data rows after the header");
  return table;
}

}  // namespace animrt::head
