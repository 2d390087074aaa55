#include "animrt/controllers/cues/pose_source.hpp"

namespace animrt {
namespace {

class PoseSource final : public MotionSource {
 public:
  explicit PoseSource(std::vector<std::pair<int, double>> pose) : pose_(std::move(pose)) {
    for (const auto& [joint, value] : pose_) driven_.push_back(joint);
  }
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double /*t*/, std::span<double> targets) const override {
    for (const auto& [joint, value] : pose_) {
      if (static_cast<std::size_t>(joint) < targets.size()) {
        targets[static_cast<std::size_t>(joint)] = value;
      }
    }
  }

 private:
  std::vector<std::pair<int, double>> pose_;
  std::vector<int> driven_;
};

}  // namespace

std::unique_ptr<MotionSource> make_pose_source(std::vector<std::pair<int, double>> pose) {
  return std::make_unique<PoseSource>(std::move(pose));
}

}  // namespace animrt
