// Mesh sequences (controllers/seqnet: OBJ, MD2, MD3, each optionally gzip):
// the first byte picks the format, the rest is the file. Any bytes are
// refused with an InputError or read; a gzip stream inflates only up to the
// input layer's limit.

#include <cstddef>
#include <cstdint>

#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/core/error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kNames[] = {"fuzz.obj", "fuzz.md2", "fuzz.md3"};
  const std::string path = animrt::fuzz::write_input(data + 1, size - 1, kNames[data[0] % 3]);
  try {
    (void)animrt::seqnet::read_mesh_sequence(path);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
