#pragma once
// The evolve run's dashboard (docs/dashboard.md, "An evolve run"): an HTTP
// server that shows a Grammatical Evolution run while it searches: best and
// average fitness, invalid and fallen individuals per generation, and the
// best gait found so far playing on the figure (its joint angles posed by
// forward kinematics, looping at real time). The search's thread publishes
// each generation (a copy, under a short lock); a sampler thread of the
// server poses the figure and streams the state. Its stop, with the token,
// ends the search after the generation being evaluated. The page's files,
// the token and the loopback rule are a run's.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "animrt/learn/evolve/search.hpp"
#include "animrt/runtime/figure_kinematics.hpp"

namespace animrt {

struct EvolveDashboardSetup {
  std::string host = "127.0.0.1";
  int port = 0;         // 0: a free one
  bool remote = false;  // allow a host that is not loopback
  double rate_hz = 30.0;
  std::string www_dir;
  std::string lib_dir = "/usr/share/javascript";
  // For /api/info.
  std::string name;  // the run's
  std::string run_file, grammar, model_file;
  int population = 0;
  int generations = 0;  // the last generation's number (0..generations are evaluated)
  std::uint64_t seed = 0;
  int workers = 0;
  // The joints the gaits drive (the model's actuated joints, in its order)
  // and the figure that poses them; without a figure no bodies are sent.
  std::vector<std::string> joints;
  FigureKinematics* figure = nullptr;
};

class EvolveDashboardServer {
 public:
  // Binds the port and starts serving. Throws std::runtime_error when the
  // address cannot be bound, std::invalid_argument for a host that is not
  // loopback without setup.remote, or a rate that is not positive.
  explicit EvolveDashboardServer(EvolveDashboardSetup setup);
  ~EvolveDashboardServer();  // stops
  EvolveDashboardServer(const EvolveDashboardServer&) = delete;
  EvolveDashboardServer& operator=(const EvolveDashboardServer&) = delete;

  int port() const;
  const std::string& token() const;
  std::string url() const;  // http://HOST:PORT/?token=TOKEN

  // From the search's thread after each generation (SearchHooks::generation):
  // the generation joins the curves; its best individual, when valid and
  // fitter than every earlier one, becomes the gait played. Copies what it
  // needs under a short lock and returns; it never waits for a client.
  void publish(const evolve::GenerationStats& stats, const evolve::Individual& best);
  // POST /api/stop arrived with the token (SearchHooks::stop).
  bool stop_requested() const;
  // The search is over (`stopped`: by the dashboard's stop): the last state
  // goes out with phase "ended", the streams end, the server stops
  // (idempotent). With `keep_serving` the server goes on serving that last
  // state until stop().
  void finish(bool stopped, bool keep_serving = false);
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace animrt
