// The CSV readers: joint-angle CSVs (controllers/seqnet/joint_csv.cpp), the
// head's tables (controllers/head/csv_table.cpp), Euler-angle and marker pose
// CSVs and BVH files (controllers/head/pose_io.cpp). The first byte picks the
// reader, the rest is the file; each refuses with an InputError or reads.

#include <cstddef>
#include <cstdint>

#include "../../controllers/head/csv_table.hpp"
#include "animrt/controllers/head/pose_io.hpp"
#include "animrt/controllers/seqnet/joint_csv.hpp"
#include "animrt/core/error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t* body = data + 1;
  const std::size_t length = size - 1;
  try {
    switch (data[0] % 5) {
      case 0:
        (void)animrt::seqnet::read_joint_csv(animrt::fuzz::write_input(body, length, "j.csv"));
        break;
      case 1:
        (void)animrt::head::read_csv_table(animrt::fuzz::write_input(body, length, "t.csv"));
        break;
      case 2:
        (void)animrt::head::load_euler_csv(animrt::fuzz::write_input(body, length, "e.csv"));
        break;
      case 3:
        (void)animrt::head::load_marker_csv(animrt::fuzz::write_input(body, length, "m.csv"));
        break;
      default:
        (void)animrt::head::load_bvh(animrt::fuzz::write_input(body, length, "p.bvh"));
        break;
    }
  } catch (const animrt::InputError&) {
  }
  return 0;
}
