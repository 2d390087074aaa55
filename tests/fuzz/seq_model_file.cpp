// Sequence-network model files (controllers/seqnet/model_file.cpp): any
// bytes are refused with an InputError or parsed; a parsed file written
// again must parse to the same bytes. The plain inference either refuses a
// parsed file's parameters with an InputError or runs a step on it.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt::seqnet;
  const std::vector<std::uint8_t> bytes(data, data + size);
  ModelFile model;
  try {
    model = parse_model_file(bytes, "fuzz.model");
  } catch (const animrt::InputError&) {
    return 0;
  }
  const std::vector<std::uint8_t> again = model_file_bytes(model);
  if (again != bytes) std::abort();  // a valid file is written back byte for byte
  try {
    SeqNetInference net(model, "fuzz.model");
    Eigen::VectorXf x = Eigen::VectorXf::Zero(net.dims());
    LstmCellState state = net.initial_state(1.0);
    net.step(x, state);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
