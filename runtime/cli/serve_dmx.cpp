#include "serve_dmx.hpp"

#include <iostream>

namespace animrt::cli {
namespace {

// A channel's value asks for the cue with that `dmx` value; a value other
// than 0 that no cue has is counted in `no_cue`.
auto cue_selector(CueRequests& requests, const std::vector<int>& values,
                  std::atomic<std::uint64_t>& no_cue) {
  return [&requests, values, &no_cue](int value) {
    bool asked = false;
    for (std::size_t c = 0; c < values.size(); ++c) {
      if (values[c] != value) continue;
      requests.cue(static_cast<int>(c));
      asked = true;
    }
    if (!asked && value != 0) no_cue.fetch_add(1, std::memory_order_relaxed);
  };
}

std::function<void(std::span<const std::uint8_t>)> frame_sink(DmxJointInputs* inputs) {
  if (inputs == nullptr) return {};
  return [inputs](std::span<const std::uint8_t> data) { inputs->frame(data); };
}

void print_listening(const char* what, const std::string& host, int port, const DmxSection& s) {
  std::cout << what << ": listening on " << host << ':' << port << " for universe " << s.universe;
  if (s.channel > 0) std::cout << ", channel " << s.channel;
  if (!s.joints.empty()) std::cout << ", " << s.joints.size() << " joint(s)";
  std::cout << '\n' << std::flush;
}

void print_joints(std::ostream& out, const char* what, const DmxJointInputs* inputs,
                  const DmxJointSource* source) {
  if (inputs == nullptr) return;
  out << what << " joints: " << inputs->frames() << " frames, " << source->losses()
      << " times lost (held, then eased back)\n";
}

}  // namespace

void add_dmx_options(CLI::App* cmd, DmxArgs& args) {
  cmd->add_option("--artnet-bind", args.artnet_bind,
                  "address Art-Net listens on (loopback unless another is given)");
  cmd->add_option("--artnet-port", args.artnet_port, "UDP port for Art-Net (0: a free one)")
      ->check(CLI::Range(0, 65535));
  cmd->add_flag("--no-artnet", args.no_artnet, "take no Art-Net triggers");
  cmd->add_option("--sacn-bind", args.sacn_bind,
                  "address sACN (E1.31) listens on (loopback unless another is given)");
  cmd->add_option("--sacn-port", args.sacn_port, "UDP port for sACN (0: a free one)")
      ->check(CLI::Range(0, 65535));
  cmd->add_flag("--sacn-multicast", args.sacn_multicast,
                "also join the universe's multicast group 239.255.hi.lo on the bind "
                "address's interface");
  cmd->add_flag("--no-sacn", args.no_sacn, "take no sACN triggers");
}

ServeDmx::ServeDmx(const DmxArgs& args, const LoadedCues& loaded, CueRequests& requests,
                   std::unique_ptr<MotionSource>& motion, const std::vector<JointSpec>& joints) {
  if (loaded.artnet.present && !args.no_artnet) {
    drive_joints(artnet_joints_, loaded.artnet, motion, joints);
    artnet_ = std::make_unique<ArtNetReceiver>(
        args.artnet_bind, args.artnet_port, loaded.artnet.universe, loaded.artnet.channel,
        cue_selector(requests, loaded.dmx_values, artnet_no_cue_),
        frame_sink(artnet_joints_.joints.get()));
    print_listening("artnet", args.artnet_bind, artnet_->port(), loaded.artnet);
  }
  if (loaded.sacn.present && !args.no_sacn) {
    drive_joints(sacn_joints_, loaded.sacn, motion, joints);
    sacn_ = std::make_unique<SacnReceiver>(args.sacn_bind, args.sacn_port, args.sacn_multicast,
                                           loaded.sacn.universe, loaded.sacn.channel,
                                           cue_selector(requests, loaded.dmx_values, sacn_no_cue_),
                                           frame_sink(sacn_joints_.joints.get()));
    print_listening("sacn", args.sacn_bind, sacn_->port(), loaded.sacn);
    if (args.sacn_multicast) {
      std::cout << "sacn: joined " << SacnReceiver::group(loaded.sacn.universe) << '\n'
                << std::flush;
    }
  }
}

void ServeDmx::drive_joints(Input& input, const DmxSection& section,
                            std::unique_ptr<MotionSource>& motion,
                            const std::vector<JointSpec>& joints) {
  if (section.joints.empty()) return;
  input.joints = std::make_unique<DmxJointInputs>(section.joints);
  auto source =
      std::make_unique<DmxJointSource>(std::move(motion), *input.joints, joints, section.hold_s);
  input.source = source.get();
  motion = std::move(source);
}

void ServeDmx::report(std::ostream& out) const {
  if (artnet_) {
    out << "artnet: " << artnet_->packets() << " packets, " << artnet_->frames()
        << " frames of the cue universe, " << artnet_->malformed() << " malformed, "
        << artnet_->out_of_sequence() << " out of sequence, " << artnet_->ignored() << " ignored, "
        << artnet_no_cue_.load() << " values asking for no cue\n";
  }
  if (sacn_) {
    out << "sacn: " << sacn_->packets() << " packets, " << sacn_->frames() << " frames output, "
        << sacn_->malformed() << " malformed, " << sacn_->out_of_sequence() << " out of sequence, "
        << sacn_->ignored() << " ignored, " << sacn_no_cue_.load() << " values asking for no cue\n";
  }
  print_joints(out, "artnet", artnet_joints_.joints.get(), artnet_joints_.source);
  print_joints(out, "sacn", sacn_joints_.joints.get(), sacn_joints_.source);
}

}  // namespace animrt::cli
