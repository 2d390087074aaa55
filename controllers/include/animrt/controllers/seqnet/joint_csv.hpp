#pragma once
// Joint-angle CSVs of the sequence network (training data, initial frames
// and keys, generated and completed frames): a header row, then one row per
// frame. Every column but time_s and the corpus's torso_x, torso_y, torso_z
// and torso_yaw is a joint, so the corpus's NAME.csv files work as they are.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace animrt::seqnet {

bool is_joint_column(const std::string& name);

struct JointCsv {
  std::vector<std::string> joints;         // joint columns, in file order
  std::vector<std::vector<double>> rows;   // per row, the joint columns' values
  std::vector<int> lines;                  // per row, its line in the file
};

// Throws InputError naming file, line, column and key for a file that
// cannot be read, a row with another number of cells, a cell that is not a
// finite number, or a header without joint columns. Lines starting with #
// and empty lines are skipped.
JointCsv read_joint_csv(const std::string& file);

// Frames (joints x frames) as a CSV with the joints as header; every number
// in the shortest form that reads back to the same double. Throws
// std::runtime_error when the file cannot be written.
void write_joint_csv(const std::string& file, const std::vector<std::string>& joints,
                     const Eigen::MatrixXd& frames);

}  // namespace animrt::seqnet
