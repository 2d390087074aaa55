#pragma once
// A small numeric CSV reader shared by the pose loaders: header row of names,
// then rows of numbers; every error names file, line, column and header key.

#include <string>
#include <vector>

namespace animrt::head {

struct CsvTable {
  std::string file;
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::vector<int> lines;  // file line of each row (1-based)
  // Index of a column, or -1.
  int column(const std::string& name) const;
  // Index of a column; InputError when missing.
  int require(const std::string& name) const;
};

CsvTable read_csv_table(const std::string& path);

}  // namespace animrt::head
