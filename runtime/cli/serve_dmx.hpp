#pragma once
// `animrt serve`'s DMX inputs: Art-Net and sACN receivers whose channel
// selects cues, and the joints their channels drive (docs/show_control.md).

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "animrt/controllers/cues/dmx_joints.hpp"
#include "animrt/runtime/artnet_receiver.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/sacn_receiver.hpp"

namespace animrt::cli {

struct DmxArgs {
  std::string artnet_bind = "127.0.0.1";
  int artnet_port = kArtNetPort;
  bool no_artnet = false;
  std::string sacn_bind = "127.0.0.1";
  int sacn_port = kSacnPort;
  bool sacn_multicast = false;
  bool no_sacn = false;
};

void add_dmx_options(CLI::App* cmd, DmxArgs& args);

class ServeDmx {
 public:
  // Starts the receivers the cue file asks for, and puts the joints they
  // drive on top of `motion` (before the figure takes it).
  ServeDmx(const DmxArgs& args, const LoadedCues& loaded, CueRequests& requests,
           std::unique_ptr<MotionSource>& motion, const std::vector<JointSpec>& joints);
  // What the receivers took, for the run's report.
  void report(std::ostream& out) const;

 private:
  struct Input {
    std::unique_ptr<DmxJointInputs> joints;
    const DmxJointSource* source = nullptr;
  };
  void drive_joints(Input& input, const DmxSection& section, std::unique_ptr<MotionSource>& motion,
                    const std::vector<JointSpec>& joints);

  Input artnet_joints_, sacn_joints_;
  // Values of the cue channel that no cue has (a desk patched wrong).
  std::atomic<std::uint64_t> artnet_no_cue_{0}, sacn_no_cue_{0};
  std::unique_ptr<ArtNetReceiver> artnet_;  // after the inputs: their threads stop first
  std::unique_ptr<SacnReceiver> sacn_;
};

}  // namespace animrt::cli
