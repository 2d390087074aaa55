// The head motion section of a robot file (motion: {type: head, ...}); the
// input is the motion node, paths resolve from <work>/robots/.

#include <cstddef>
#include <cstdint>

#include "animrt/controllers/head/head_source.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt;
  const std::string robot = fuzz::work_dir() + "/robots/fuzz_head.yaml";
  try {
    const YamlNode motion = YamlNode::load_string(fuzz::as_text(data, size), robot);
    (void)head::parse_head_motion(motion, robot);
  } catch (const InputError&) {
  }
  return 0;
}
