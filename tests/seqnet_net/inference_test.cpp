// The plain C++ forward pass against the libtorch network: the latent mean
// and whole chains (forward from +s0, backward from -s0, from drawn states,
// with one and with several given frames) agree to 1e-5 per entry, for
// randomly initialised and for briefly trained models of both kinds; bad
// parameter sets are refused naming the parameter.

#include "animrt/controllers/seqnet/inference.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <sstream>

#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/network.hpp"
#include "animrt/learn/seqnet/shapes.hpp"
#include "animrt/learn/seqnet/training.hpp"
#include "net_test_util.hpp"

namespace animrt::seqnet {
namespace {

ModelFile random_mesh_model(int channels, int placement_nodes = 0) {
  torch::manual_seed(21);
  const MeshSequence bar = make_bar(4, 6, 4.0);  // caps: vertex degrees 3 to 6
  ModelFile m;
  m.shape.kind = ModelKind::mesh;
  m.shape.vertex_count = bar.vertex_count();
  m.shape.placement_nodes = placement_nodes;
  m.shape.channels = channels;
  m.shape.latent = 7;
  m.shape.hidden = 10;
  m.shape.window = 12;
  m.rest = bar.frames.front();
  m.triangles = bar.triangles;
  m.low.assign(static_cast<std::size_t>(m.shape.input_dims()), -1.0);
  m.high.assign(static_cast<std::size_t>(m.shape.input_dims()), 1.0);
  SeqNet net(m.shape, mesh_graph(m.shape.vertex_count, m.triangles));
  m.parameters = save_parameters(*net);
  return m;
}

ModelFile random_joint_model() {
  torch::manual_seed(22);
  ModelFile m;
  m.shape.kind = ModelKind::joints;
  m.shape.joint_count = 5;
  m.shape.dense_width = 6;
  m.shape.latent = 4;
  m.shape.hidden = 9;
  m.shape.window = 12;
  m.joint_names = {"a", "b", "c", "d", "e"};
  m.low.assign(5, -1.0);
  m.high.assign(5, 1.0);
  SeqNet net(m.shape, MeshGraph{});
  m.parameters = save_parameters(*net);
  return m;
}

ModelFile trained(const std::vector<std::string>& data, const std::string& name) {
  TrainOptions o = nettest::tiny_options(data.front(), name);
  o.data = data;
  o.iterations = 15;
  o.batch = 2;
  o.hidden = 12;
  std::ostringstream log;
  train(o, log);
  return read_model_file(o.out);
}

LstmState to_torch(const LstmCellState& s) {
  auto t = [](const Eigen::MatrixXf& m) {
    // hidden x layers -> [layers, 1, hidden]
    return torch::from_blob(const_cast<float*>(m.data()), {m.cols(), 1, m.rows()}, torch::kFloat32)
        .clone();
  };
  return {t(s.h), t(s.c)};
}

Eigen::MatrixXf to_eigen(const torch::Tensor& frames) {  // [n, 1, D] -> D x n
  const torch::Tensor c = frames.squeeze(1).contiguous();
  return Eigen::Map<const Eigen::MatrixXf>(c.data_ptr<float>(), c.size(1), c.size(0));
}

torch::Tensor to_torch(const Eigen::MatrixXf& given) {  // D x u -> [u, 1, D]
  return torch::from_blob(const_cast<float*>(given.data()), {given.cols(), 1, given.rows()},
                          torch::kFloat32)
      .clone();
}

// Largest entry difference, relative to the entry's size where it is above 1.
double worst(const Eigen::MatrixXf& a, const Eigen::MatrixXf& b) {
  return ((a - b).array().abs() / b.array().abs().max(1.0F)).maxCoeff();
}

void expect_same_chains(const ModelFile& model) {
  torch::set_num_threads(1);
  torch::manual_seed(5);
  SeqNet net = network_for(model, "model");
  net->eval();
  torch::NoGradGuard no_grad;
  SeqNetInference plain(model, "model");
  const int d = plain.dims();
  const int n = model.shape.window;
  const Eigen::MatrixXf given = to_eigen((torch::rand({3, 1, d}) * 1.9 - 0.95));

  // The latent mean of one frame.
  const Eigen::VectorXf x0 = given.col(0);
  const torch::Tensor mu = net->encode(to_torch(Eigen::MatrixXf(x0)).squeeze(0)).first;
  const torch::Tensor mu_flat = mu.flatten().contiguous();
  const Eigen::VectorXf mu_torch =
      Eigen::Map<const Eigen::VectorXf>(mu_flat.data_ptr<float>(), mu_flat.numel());
  EXPECT_LT(worst(plain.encode(x0), mu_torch), 1e-5);

  std::mt19937_64 rng(9);
  const LstmCellState drawn = plain.random_state(1.0, rng);
  EXPECT_GT((drawn.h.array() - static_cast<float>(model.shape.s0)).abs().maxCoeff(), 1e-3);
  struct Case {
    const char* name;
    int given;
    LstmCellState state;
  };
  const std::vector<Case> cases = {{"forward from +s0", 1, plain.initial_state(1.0)},
                                   {"backward from -s0", 1, plain.initial_state(-1.0)},
                                   {"drawn state", 1, drawn},
                                   {"three given frames", 3, plain.initial_state(1.0)}};
  for (const Case& c : cases) {
    const Eigen::MatrixXf start = given.leftCols(c.given);
    const Chain t = net->run(to_torch(start), n, to_torch(c.state), false);
    const Eigen::MatrixXf expected = to_eigen(t.frames);
    const Eigen::MatrixXf got = plain.run(start, n, c.state);
    ASSERT_EQ(got.cols(), n);
    EXPECT_LT(worst(got, expected), 1e-5) << c.name;
    // The chain moves: a wrong step could not pass by standing still.
    EXPECT_GT((expected.col(n - 1) - expected.col(0)).norm(), 1e-3) << c.name;
  }
}

TEST(SeqInference, MeshModelEqualsTheTorchNetwork) { expect_same_chains(random_mesh_model(6)); }

TEST(SeqInference, MeshModelWithNineChannelsEqualsTheTorchNetwork) {
  expect_same_chains(random_mesh_model(9));
}

// The placement nodes run through both networks as vertices without
// neighbours, and the dense layers mix them in.
TEST(SeqInference, MeshModelWithPlacementNodesEqualsTheTorchNetwork) {
  expect_same_chains(random_mesh_model(6, 2));
}

TEST(SeqInference, JointModelEqualsTheTorchNetwork) { expect_same_chains(random_joint_model()); }

TEST(SeqInference, TrainedJointModelEqualsTheTorchNetwork) {
  expect_same_chains(
      trained({nettest::write_joint_csv("infer_walk.csv", 60)}, "infer_joint.model"));
}

TEST(SeqInference, TrainedMeshModelEqualsTheTorchNetwork) {
  expect_same_chains(
      trained({nettest::write_bar_features("infer_bar.features", 4, 6, 40)}, "infer_bar.model"));
}

std::string error_of(const ModelFile& m) {
  try {
    SeqNetInference plain(m, "m.model");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SeqInference, MissingExtraOrMisshapenParametersAreRefused) {
  const ModelFile good = random_joint_model();
  EXPECT_EQ(error_of(good), "no error");
  ModelFile m = good;
  std::erase_if(m.parameters, [](const NamedArray& a) { return a.name == "lstm.bias_hh_l1"; });
  EXPECT_NE(error_of(m).find("m.model: parameter lstm.bias_hh_l1: missing from the file"),
            std::string::npos)
      << error_of(m);
  m = good;
  m.parameters.push_back(NamedArray{"extra.weight", {1}, {0.0F}});
  EXPECT_NE(error_of(m).find("parameter extra.weight: not a parameter of this network"),
            std::string::npos)
      << error_of(m);
  m = good;
  for (NamedArray& a : m.parameters) {
    if (a.name == "decoder.4.weight") a.shape = {a.shape[1], a.shape[0]};
  }
  EXPECT_NE(error_of(m).find("parameter decoder.4.weight: shape 6x5, the network needs 5x6"),
            std::string::npos)
      << error_of(m);
}

}  // namespace
}  // namespace animrt::seqnet
