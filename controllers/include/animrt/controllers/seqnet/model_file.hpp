#pragma once
// The versioned model file of the sequence network (layout in
// docs/seqnet.md): the network's shape, what it was trained on (the mesh's
// vertex count, connectivity and template, or the joint names), the feature
// mapping, the parameters as named float arrays, and for a checkpoint the
// optimiser's state and the training position. A CRC-32 closes the file.
// Reading and writing need no libtorch (the fuzzers use them).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace animrt::seqnet {

constexpr char kModelFileMagic[8] = {'A', 'N', 'S', 'E', 'Q', 'N', 'N', '\n'};
// 2 added the held-out measurement, 3 the placement nodes; 1 and 2 are still read
constexpr std::uint32_t kModelFileVersion = 3;

enum class ModelKind : std::uint32_t { mesh = 1, joints = 2 };

const char* kind_name(ModelKind kind);

// The network's shape (docs/seqnet.md, "Network").
struct NetShape {
  ModelKind kind = ModelKind::mesh;
  int vertex_count = 0;  // mesh: V; input is 9 V numbers
  int joint_count = 0;   // joints: J; input is J numbers
  int conv_layers = 3;   // mesh convolution (encoder) and transpose (decoder) layers
  int channels = 9;      // mesh: channels of the hidden convolution layers
  int dense_width = 64;  // joints: width of the hidden dense layers
  int latent = 128;      // latent vector (VAE mean and log-variance)
  int hidden = 128;      // LSTM hidden units
  int lstm_layers = 3;
  int window = 32;  // frames per training sequence
  int stride = 1;   // 2: every other frame (slow motion)
  double s0 = 0.1;  // forward chain's initial state; the backward chain takes -s0
  // Mesh: nodes of 9 placement numbers after the vertices (placement_nodes.hpp);
  // 0 for a model of an older build, which knows nothing of translation.
  int placement_nodes = 0;

  // Vertices and placement nodes: the rows the mesh layers run over.
  int nodes() const { return vertex_count + placement_nodes; }
  int input_dims() const { return kind == ModelKind::mesh ? 9 * nodes() : joint_count; }
};

// A named float array: a parameter, or a piece of optimiser state.
struct NamedArray {
  std::string name;
  std::vector<std::int64_t> shape;
  std::vector<float> values;
};

struct ModelFile {
  // Written as read: a version-1 file (no held-out measurement) stays one.
  std::uint32_t version = kModelFileVersion;
  NetShape shape;
  // Mesh models: the template and its connectivity (the features are
  // deformations of this mesh).
  Eigen::Matrix3Xd rest;
  std::vector<std::array<int, 3>> triangles;
  // Joint models: the joints, in input order.
  std::vector<std::string> joint_names;
  // Feature mapping: input value = low + (x + 0.95) / 1.9 * (high - low)
  // per input dimension (mesh: the features' FeatureScale, vertex-major).
  std::vector<double> low;
  std::vector<double> high;
  // Training record.
  std::uint64_t seed = 0;
  std::uint32_t threads = 1;
  std::uint64_t iteration = 0;  // iterations trained
  // The last held-out measurement during training: completion of gaps of
  // `held_out_gap` frames by the network and by linear interpolation of the
  // keys, as fractions of the data's range; negative when never measured.
  double held_out_completion = -1.0;
  double held_out_interpolation = -1.0;
  int held_out_gap = 0;
  std::vector<NamedArray> parameters;
  std::vector<NamedArray> optimiser;  // empty in a final model; Adam moments in a checkpoint
};

// FNV-1a (64 bit) over the vertex count and every triangle's indices.
std::uint64_t connectivity_hash(int vertex_count, const std::vector<std::array<int, 3>>& triangles);

// Throws std::runtime_error when the file cannot be written.
void write_model_file(const std::string& file, const ModelFile& model);
std::vector<std::uint8_t> model_file_bytes(const ModelFile& model);

// Throws InputError naming the file and the part (header, shape, triangle N,
// joint N, mapping, parameter NAME, checksum) for a file that is truncated,
// corrupt, of another version or inconsistent.
ModelFile read_model_file(const std::string& file);
ModelFile parse_model_file(const std::vector<std::uint8_t>& bytes, const std::string& file);

// Throw InputError naming the model file and what differs when the model
// was trained on another mesh or another joint set (or is of the other kind).
void check_model_mesh(const ModelFile& model, const std::string& file, int vertex_count,
                      const std::vector<std::array<int, 3>>& triangles);
// One line warning that the model was never measured better than linear
// interpolation on held-out data (or never measured at all), naming the
// file; empty when it was.
std::string interpolation_warning(const ModelFile& model, const std::string& file);

void check_model_joints(const ModelFile& model, const std::string& file,
                        const std::vector<std::string>& joint_names);

}  // namespace animrt::seqnet
