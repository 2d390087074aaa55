// The model file: save/load gives the same network outputs; corrupt,
// truncated, mismatched files are refused with one error naming the file
// and what differs.

#include "animrt/controllers/seqnet/model_file.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <fstream>
#include <iterator>

#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/network.hpp"
#include "animrt/learn/seqnet/shapes.hpp"
#include "net_test_util.hpp"

namespace animrt::seqnet {
namespace {

ModelFile mesh_model(int levels = 1) {
  torch::manual_seed(3);
  const MeshSequence sphere = make_icosphere(levels);
  ModelFile m;
  m.shape.kind = ModelKind::mesh;
  m.shape.vertex_count = sphere.vertex_count();
  m.shape.latent = 6;
  m.shape.hidden = 8;
  m.rest = sphere.frames.front();
  m.triangles = sphere.triangles;
  m.low.assign(static_cast<std::size_t>(m.shape.input_dims()), -1.0);
  m.high.assign(static_cast<std::size_t>(m.shape.input_dims()), 2.0);
  m.seed = 11;
  m.iteration = 5;
  SeqNet net(m.shape, mesh_graph(m.shape.vertex_count, m.triangles));
  m.parameters = save_parameters(*net);
  return m;
}

ModelFile joint_model(std::vector<std::string> joints) {
  torch::manual_seed(4);
  ModelFile m;
  m.shape.kind = ModelKind::joints;
  m.shape.joint_count = static_cast<int>(joints.size());
  m.shape.dense_width = 5;
  m.shape.latent = 3;
  m.shape.hidden = 4;
  m.joint_names = std::move(joints);
  m.low.assign(m.joint_names.size(), -1.0);
  m.high.assign(m.joint_names.size(), 1.0);
  SeqNet net(m.shape, MeshGraph{});
  m.parameters = save_parameters(*net);
  return m;
}

std::vector<std::uint8_t> load_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void save_bytes(const std::string& path, const std::vector<std::uint8_t>& b) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

class ModelFileTest : public ::testing::Test {
 protected:
  void SetUp() override { torch::set_num_threads(1); }
};

TEST_F(ModelFileTest, SaveLoadRoundTripGivesIdenticalOutputs) {
  const ModelFile m = mesh_model();
  const std::string path = nettest::temp_path("round_trip.model");
  write_model_file(path, m);
  const ModelFile back = read_model_file(path);
  EXPECT_EQ(back.shape.vertex_count, m.shape.vertex_count);
  EXPECT_EQ(back.triangles, m.triangles);
  EXPECT_EQ(back.low, m.low);
  EXPECT_EQ(back.seed, 11U);
  EXPECT_EQ(back.iteration, 5U);
  EXPECT_TRUE(back.rest.isApprox(m.rest, 0.0));
  SeqNet a = network_for(m, "memory");
  SeqNet b = network_for(back, path);
  torch::NoGradGuard no_grad;
  torch::manual_seed(5);
  const torch::Tensor given = torch::rand({2, 3, m.shape.input_dims()});
  const torch::Tensor out_a = a->run(given, 6, a->initial_state(3, -1.0), false).frames;
  const torch::Tensor out_b = b->run(given, 6, b->initial_state(3, -1.0), false).frames;
  EXPECT_TRUE(torch::equal(out_a, out_b));
  // A net with other weights gives other outputs (the comparison can fail).
  torch::manual_seed(99);
  SeqNet c(m.shape, mesh_graph(m.shape.vertex_count, m.triangles));
  EXPECT_FALSE(torch::equal(out_a, c->run(given, 6, c->initial_state(3, -1.0), false).frames));
}

TEST_F(ModelFileTest, PlacementNodesRoundTripAndOlderFilesLoadWithoutThem) {
  ModelFile m = mesh_model(0);
  m.shape.placement_nodes = 2;
  m.low.assign(static_cast<std::size_t>(m.shape.input_dims()), -1.0);
  m.high.assign(static_cast<std::size_t>(m.shape.input_dims()), 2.0);
  m.parameters = save_parameters(*SeqNet(m.shape, mesh_graph(m.shape.vertex_count, m.triangles)));
  const std::string path = nettest::temp_path("placement.model");
  write_model_file(path, m);
  const ModelFile back = read_model_file(path);
  EXPECT_EQ(back.version, 3U);
  EXPECT_EQ(back.shape.placement_nodes, 2);
  EXPECT_EQ(back.shape.input_dims(), 9 * (12 + 2));
  EXPECT_NO_THROW(network_for(back, path));
  // A version-2 file (an older build's) has no placement nodes: it loads
  // with none and is written back byte for byte.
  ModelFile old = mesh_model(0);
  old.version = 2;
  const std::string old_path = nettest::temp_path("version2.model");
  write_model_file(old_path, old);
  const ModelFile old_back = read_model_file(old_path);
  EXPECT_EQ(old_back.version, 2U);
  EXPECT_EQ(old_back.shape.placement_nodes, 0);
  EXPECT_EQ(model_file_bytes(old_back), load_bytes(old_path));
  EXPECT_NO_THROW(network_for(old_back, old_path));
}

TEST_F(ModelFileTest, JointModelRoundTripKeepsTheJointNames) {
  const ModelFile m = joint_model({"hip", "knee", "ankle"});
  const std::string path = nettest::temp_path("joints.model");
  write_model_file(path, m);
  const ModelFile back = read_model_file(path);
  EXPECT_EQ(back.joint_names, m.joint_names);
  EXPECT_NO_THROW(check_model_joints(back, path, {"hip", "knee", "ankle"}));
}

TEST_F(ModelFileTest, CorruptFileIsRefusedByItsChecksum) {
  const std::string path = nettest::temp_path("corrupt.model");
  write_model_file(path, mesh_model());
  std::vector<std::uint8_t> b = load_bytes(path);
  b[b.size() - 100] ^= 0x40;  // inside the last parameter's values
  save_bytes(path, b);
  const std::string e = error_of([&] { read_model_file(path); });
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("checksum"), std::string::npos) << e;
}

TEST_F(ModelFileTest, TruncatedFileIsRefusedAtEveryLength) {
  const std::string path = nettest::temp_path("truncated.model");
  write_model_file(path, joint_model({"a", "b"}));
  const std::vector<std::uint8_t> full = load_bytes(path);
  for (std::size_t keep : {std::size_t{0}, std::size_t{5}, std::size_t{12}, std::size_t{60},
                           full.size() / 2, full.size() - 5, full.size() - 1}) {
    save_bytes(path, std::vector<std::uint8_t>(full.begin(), full.begin() + keep));
    const std::string e = error_of([&] { read_model_file(path); });
    EXPECT_NE(e.find(path), std::string::npos) << keep << ": " << e;
    EXPECT_NE(e.find("truncated"), std::string::npos) << keep << ": " << e;
  }
}

TEST_F(ModelFileTest, OtherMagicOrVersionIsRefused) {
  const std::string path = nettest::temp_path("version.model");
  write_model_file(path, joint_model({"a"}));
  std::vector<std::uint8_t> b = load_bytes(path);
  b[8] = 9;  // version
  save_bytes(path, b);
  EXPECT_NE(
      error_of([&] { read_model_file(path); }).find("version 9, this build reads versions 1 to 3"),
      std::string::npos);
  b[0] = 'X';
  save_bytes(path, b);
  EXPECT_NE(error_of([&] { read_model_file(path); }).find("not an animrt sequence model"),
            std::string::npos);
}

TEST_F(ModelFileTest, ModelOfAnotherMeshIsRefused) {
  const ModelFile m = mesh_model(1);  // 42 vertices
  const MeshSequence other = make_icosphere(2);
  std::string e =
      error_of([&] { check_model_mesh(m, "m.model", other.vertex_count(), other.triangles); });
  EXPECT_NE(e.find("m.model"), std::string::npos) << e;
  EXPECT_NE(e.find("trained on a mesh of 42 vertices, the data has 162"), std::string::npos) << e;
  // Same vertex count, other connectivity.
  auto triangles = m.triangles;
  std::swap(triangles[0][1], triangles[0][2]);
  e = error_of([&] { check_model_mesh(m, "m.model", 42, triangles); });
  EXPECT_NE(e.find("another connectivity"), std::string::npos) << e;
  EXPECT_NO_THROW(check_model_mesh(m, "m.model", 42, m.triangles));
  e = error_of([&] { check_model_joints(m, "m.model", {"hip"}); });
  EXPECT_NE(e.find("a mesh model (42 vertices)"), std::string::npos) << e;
}

TEST_F(ModelFileTest, ModelOfAnotherJointSetIsRefused) {
  const ModelFile m = joint_model({"hip", "knee", "ankle"});
  std::string e = error_of([&] { check_model_joints(m, "j.model", {"hip", "knee", "toe"}); });
  EXPECT_NE(e.find("j.model"), std::string::npos) << e;
  EXPECT_NE(e.find("the data lacks ankle; the model lacks toe"), std::string::npos) << e;
  e = error_of([&] { check_model_joints(m, "j.model", {"knee", "hip", "ankle"}); });
  EXPECT_NE(e.find("same joints in another order"), std::string::npos) << e;
  e = error_of([&] { check_model_mesh(m, "j.model", 42, {}); });
  EXPECT_NE(e.find("a joint-space model (3 joints)"), std::string::npos) << e;
}

TEST_F(ModelFileTest, ParametersOfAnotherShapeAreRefusedByName) {
  ModelFile m = joint_model({"hip", "knee"});
  m.shape.hidden = 5;  // the stored arrays are for 4 hidden units
  const std::string e = error_of([&] { network_for(m, "shape.model"); });
  EXPECT_NE(e.find("shape.model"), std::string::npos) << e;
  EXPECT_NE(e.find("parameter "), std::string::npos) << e;
  EXPECT_NE(e.find("the network needs"), std::string::npos) << e;
}

TEST_F(ModelFileTest, InconsistentMappingIsRefused) {
  ModelFile m = joint_model({"hip", "knee"});
  m.low.push_back(0.0);
  m.high.push_back(0.0);
  const std::string path = nettest::temp_path("mapping.model");
  write_model_file(path, m);
  const std::string e = error_of([&] { read_model_file(path); });
  EXPECT_NE(e.find("mapping: 3 dimensions, the shape has 2"), std::string::npos) << e;
}

}  // namespace
}  // namespace animrt::seqnet
