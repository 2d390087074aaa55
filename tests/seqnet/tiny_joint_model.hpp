#pragma once
// A tiny joint-space sequence model built without training, every weight
// and bias set to one value, as the model writer stores it (valid CRC).

#include <string>
#include <vector>

#include "animrt/controllers/seqnet/model_file.hpp"

namespace animrt::seqnet::test {

// Joints hip and knee, one dense layer of 4, latent 3, one LSTM layer of 2
// hidden units, window 8; training range -1..1 rad per joint.
inline ModelFile tiny_joint_model(float weight) {
  ModelFile m;
  NetShape& s = m.shape;
  s.kind = ModelKind::joints;
  s.joint_count = 2;
  s.conv_layers = 1;
  s.dense_width = 4;
  s.latent = 3;
  s.hidden = 2;
  s.lstm_layers = 1;
  s.window = 8;
  m.joint_names = {"hip", "knee"};
  m.low = {-1.0, -1.0};
  m.high = {1.0, 1.0};
  const auto add = [&](const std::string& name, std::vector<std::int64_t> shape) {
    std::int64_t n = 1;
    for (auto d : shape) n *= d;
    m.parameters.push_back({name, shape, std::vector<float>(static_cast<std::size_t>(n), weight)});
  };
  add("encoder.0.weight", {4, 2});
  add("encoder.0.bias", {4});
  add("to_mu.weight", {3, 4});
  add("to_mu.bias", {3});
  add("to_logvar.weight", {3, 4});
  add("to_logvar.bias", {3});
  add("lstm.weight_ih_l0", {8, 3});
  add("lstm.weight_hh_l0", {8, 2});
  add("lstm.bias_ih_l0", {8});
  add("lstm.bias_hh_l0", {8});
  add("from_hidden.weight", {4, 2});
  add("from_hidden.bias", {4});
  add("decoder.0.weight", {2, 4});
  add("decoder.0.bias", {2});
  return m;
}

}  // namespace animrt::seqnet::test
