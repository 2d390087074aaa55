#include "animrt/learn/head/trainer.hpp"

#include <algorithm>
#include <stdexcept>

#include "animrt/controllers/head/synthesis.hpp"
#include "animrt/learn/head/bigram_training.hpp"
#include "animrt/learn/head/hmm_training.hpp"
#include "animrt/learn/head/lbg.hpp"

namespace animrt::head {
namespace {

// Per axis, the shrink factor in [0, 1] with the smallest squared error
// between the decoded output poses and the original poses, over a 4-fold
// cross-validation of the training utterances: each quarter is decoded by a
// model trained on the other three. Least squares per axis gives
// sum(y d) / sum(d d), with y the original and d the cluster mean, both
// relative to the mean pose.
Eigen::Vector3d choose_shrink(const std::vector<PreparedUtterance>& train,
                              const FeatureConfig& config, const TrainOptions& options) {
  constexpr int kFolds = 4;
  if (train.size() < static_cast<std::size_t>(kFolds)) return Eigen::Vector3d::Ones();
  Eigen::Vector3d yd = Eigen::Vector3d::Zero(), dd = Eigen::Vector3d::Zero();
  for (int fold = 0; fold < kFolds; ++fold) {
    std::vector<PreparedUtterance> fit, check;
    for (std::size_t i = 0; i < train.size(); ++i)
      (static_cast<int>(i % kFolds) == fold ? check : fit).push_back(train[i]);
    TrainOptions o = options;
    o.shrink = 1.0;
    o.log = nullptr;
    const HeadModel inner = train_model(fit, config, o);
    for (const auto& u : check) {
      const std::vector<int> clusters = decode_track(inner, u.track);
      const auto n =
          std::min<Eigen::Index>(static_cast<Eigen::Index>(clusters.size()), u.poses.rows());
      for (Eigen::Index t = 0; t < n; ++t) {
        const Eigen::Vector3d d =
            inner.codebook.means.row(clusters[static_cast<std::size_t>(t)]).transpose() -
            inner.pose_mean;
        const Eigen::Vector3d y = u.poses.row(t).transpose() - inner.pose_mean;
        yd += y.cwiseProduct(d);
        dd += d.cwiseProduct(d);
      }
    }
  }
  Eigen::Vector3d out;
  for (int a = 0; a < 3; ++a) out(a) = dd(a) > 0 ? std::clamp(yd(a) / dd(a), 0.0, 1.0) : 1.0;
  return out;
}

}  // namespace

HeadModel train_model(const std::vector<PreparedUtterance>& train, const FeatureConfig& config,
                      const TrainOptions& options) {
  if (train.empty()) throw std::invalid_argument("training needs at least one utterance");
  auto log = [&](const std::string& s) {
    if (options.log) options.log(s);
  };
  HeadModel model;
  model.features = config;
  model.states = options.states;
  model.mixtures = options.mixtures;
  model.topology = options.topology;
  model.decode = options.decode;
  model.smoothing = options.smoothing;

  Eigen::Index frames = 0;
  for (const auto& u : train) {
    frames += u.track.features.rows();
    model.training_utterances.push_back(u.name);
  }
  Eigen::MatrixXd all_features(frames, kFeatureDim), all_poses(frames, 3);
  Eigen::Index row = 0;
  for (const auto& u : train) {
    all_features.middleRows(row, u.track.features.rows()) = u.track.features;
    all_poses.middleRows(row, u.poses.rows()) = u.poses;
    row += u.track.features.rows();
  }
  if (frames < options.clusters)
    throw std::invalid_argument("training data has fewer frames than clusters");
  model.feature_mean = all_features.colwise().mean().transpose();
  model.feature_std = ((all_features.rowwise() - model.feature_mean.transpose())
                           .array()
                           .square()
                           .colwise()
                           .mean()
                           .sqrt())
                          .transpose()
                          .cwiseMax(1e-9);

  log("vector quantisation: " + std::to_string(frames) + " pose frames into " +
      std::to_string(options.clusters) + " clusters");
  model.codebook = train_lbg(all_poses, options.clusters, options.lbg);
  model.pose_mean = all_poses.colwise().mean().transpose();

  // The known segmentation: every frame's cluster, runs of one cluster as
  // that cluster's training sequences.
  std::vector<std::vector<int>> labels;
  std::vector<std::vector<Eigen::MatrixXd>> sequences(static_cast<std::size_t>(options.clusters));
  for (const auto& u : train) {
    const Eigen::MatrixXd obs = model.normalise(u.track.features);
    std::vector<int> l(static_cast<std::size_t>(obs.rows()));
    for (Eigen::Index t = 0; t < obs.rows(); ++t)
      l[static_cast<std::size_t>(t)] = model.codebook.nearest(u.poses.row(t).transpose());
    Eigen::Index start = 0;
    for (Eigen::Index t = 1; t <= obs.rows(); ++t) {
      if (t == obs.rows() || l[static_cast<std::size_t>(t)] != l[static_cast<std::size_t>(start)]) {
        sequences[static_cast<std::size_t>(l[static_cast<std::size_t>(start)])].push_back(
            obs.middleRows(start, t - start));
        start = t;
      }
    }
    labels.push_back(std::move(l));
  }

  HmmTrainOptions ho;
  ho.states = options.states;
  ho.mixtures = options.mixtures;
  ho.topology = options.topology;
  ho.max_iterations = options.iterations;
  ho.variance_floor = Eigen::VectorXd::Constant(kFeatureDim, options.variance_floor);
  for (int k = 0; k < options.clusters; ++k) {
    auto& seqs = sequences[static_cast<std::size_t>(k)];
    if (seqs.empty()) {
      // An empty cell (possible with duplicate poses): model it on everything,
      // the bigram will rarely choose it.
      seqs.push_back(model.normalise(all_features));
    }
    Hmm hmm = init_hmm(seqs, ho);
    baum_welch(hmm, seqs, ho);
    model.hmms.push_back(std::move(hmm));
  }
  log("trained " + std::to_string(options.clusters) + " HMMs (S=" + std::to_string(options.states) +
      ", M=" + std::to_string(options.mixtures) + ", " + topology_name(options.topology) + ")");
  model.bigram = train_bigram(labels, options.clusters, options.bigram_discount);
  if (options.shrink >= 0) {
    model.smoothing.shrink = Eigen::Vector3d::Constant(std::min(options.shrink, 1.0));
  } else {
    model.smoothing.shrink = choose_shrink(train, config, options);
    const Eigen::Vector3d& f = model.smoothing.shrink;
    log("output poses shrunk toward the mean pose by yaw " + std::to_string(f(0)) + ", pitch " +
        std::to_string(f(1)) + ", roll " + std::to_string(f(2)) +
        " (chosen by 4-fold cross-validation on the training utterances)");
  }
  return model;
}

}  // namespace animrt::head
