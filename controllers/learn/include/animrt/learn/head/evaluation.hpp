#pragma once
// Objective measures of synthesized head motion against the original, and
// the runner for the paper's eight HMM configurations (its Table 1).

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "animrt/controllers/head/model.hpp"
#include "animrt/learn/head/corpus.hpp"
#include "animrt/learn/head/trainer.hpp"

namespace animrt::head {

// Mean over frames of the Euclidean distance between Euler-angle vectors
// (degrees); both N x 3.
double mean_euclidean_deg(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// First (largest) canonical correlation between the columns of X (N x p) and
// Y (N x q). Directions without variance are ignored; 0 when either side has
// none at all.
double first_canonical_correlation(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y);

struct Score {
  double mean = 0, std = 0;
};

struct Evaluation {
  Score distance_deg;  // per utterance mean distance, then mean and std over utterances
  Score cca;
  Score baseline_distance_deg;  // always the training mean pose
  // The mean pose through the same output stage (plus the model's seeded
  // noise, without which a constant has no correlation to measure).
  Score baseline_cca;
  int utterances = 0;
};

// Synthesizes every test utterance from its features and compares with its
// original poses at the output times. `baseline_pose` (yaw, pitch, roll)
// is the constant pose of the baseline.
Evaluation evaluate(const HeadModel& model, const std::vector<PreparedUtterance>& test,
                    const Eigen::Vector3d& baseline_pose);

// Mean pose of prepared utterances (all frames).
Eigen::Vector3d mean_pose(const std::vector<PreparedUtterance>& utterances);

struct TableConfig {
  int clusters, states, mixtures;
  Topology topology;
  // The paper's numbers for this row.
  double paper_distance_mean, paper_distance_std, paper_cca_mean, paper_cca_std;
};
// The eight rows of the paper's Table 1.
const std::vector<TableConfig>& paper_table();

struct TableRow {
  TableConfig config;
  Evaluation result;
};

std::vector<TableRow> run_table(const std::vector<PreparedUtterance>& train,
                                const std::vector<PreparedUtterance>& test,
                                const FeatureConfig& features, const TrainOptions& base,
                                const std::function<void(const TableRow&)>& on_row = {});

std::string format_table(const std::vector<TableRow>& rows);

}  // namespace animrt::head
