// animrt-tools steers a run by a herd itself (see run_herd.hpp).

#include "run_herd.hpp"

#include <spdlog/spdlog.h>

#include "animrt/runtime/embodied_herd.hpp"
#include "animrt/sim/mujoco/mujoco_physics.hpp"

namespace animrt::cli {
namespace {

class EmbodiedRunHerd final : public RunHerd {
 public:
  explicit EmbodiedRunHerd(std::unique_ptr<EmbodiedHerd> herd) : herd_(std::move(herd)) {}
  void start(Nanos t0) override { herd_->start(t0); }
  void stop() override { herd_->stop(); }
  std::string report() const override { return herd_->report(); }

 private:
  std::unique_ptr<EmbodiedHerd> herd_;
};

}  // namespace

void run_herd_here(const std::string&) {}

std::unique_ptr<RunHerd> join_run_herd(const std::string& scene, const std::string& agent,
                                       const Figure& figure, const SimulatedBackend& simulated,
                                       RunControls& controls) {
  if (scene.empty()) return nullptr;
  const sim::MujocoJointPhysics* physics = simulated.mujoco_physics();
  EmbodiedHerd::MeasuredTrack measured;
  if (physics) {
    measured = [physics] {
      const sim::TorsoPose p = physics->torso_pose();
      return EmbodiedHerd::Track{p.x_m, p.y_m, p.yaw_rad};
    };
  }
  auto herd =
      std::make_unique<EmbodiedHerd>(scene, agent, figure.clock(), controls, std::move(measured));
  spdlog::info("herd: {} steers the robot as agent {}", scene, agent);
  return std::make_unique<EmbodiedRunHerd>(std::move(herd));
}

}  // namespace animrt::cli
