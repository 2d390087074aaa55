#pragma once
// Learned in-betweens for the cue player, computed off the real-time cycle.
//
// The cycle hands one job at a time to a worker thread: the present pose
// and the next cue's pose (in the model's joint order), the model, how many
// frames. The worker runs the sequence network's completion between the two
// (plain C++ inference, controllers/seqnet/inference.hpp) and writes the
// frames into one of a fixed set of buffers allocated before the run. The
// two sides meet through two sequence numbers: the cycle writes a job only
// while the worker is idle and never blocks on it; it polls for the result
// each cycle. There is one job slot, so a burst of triggers can never queue
// more than one computation.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace animrt {
namespace seqnet {
struct ModelFile;
class SeqNetInference;
struct CompletionOptions;
}  // namespace seqnet

class TransitionWorker {
 public:
  struct Model {
    std::shared_ptr<const seqnet::ModelFile> file;
    std::string path;
  };
  // `dims`: the most joints of any model; `capacity`: the most frames
  // (columns, both keys included) of one in-between; `buffers`: how many
  // in-betweens can be held at once (played, and one being computed).
  TransitionWorker(const std::vector<Model>& models, int dims, int capacity, int buffers);
  ~TransitionWorker();
  // The completion's options: the first try alone (no retries from random
  // states: each would cost as much again), its chains blended, so the
  // work per in-between is one forward and one backward chain.
  static seqnet::CompletionOptions completion_options();

  TransitionWorker(const TransitionWorker&) = delete;
  TransitionWorker& operator=(const TransitionWorker&) = delete;

  // The cycle (one thread). A job may be written only while idle().
  bool idle() const {
    return done_.load(std::memory_order_acquire) == posted_.load(std::memory_order_relaxed);
  }
  // The keys of the next job, in the model's joint order (dims() each).
  std::span<double> from() { return from_; }
  std::span<double> to() { return to_; }
  // Complete `frames` + 1 columns (the keys at both ends) into `buffer`.
  // Returns the job's sequence number.
  std::uint64_t post(int model, int frames, int buffer);
  // The job has finished; ok() says whether its frames are usable (all finite).
  bool finished(std::uint64_t job) const { return done_.load(std::memory_order_acquire) >= job; }
  bool ok(int buffer) const { return ok_[static_cast<std::size_t>(buffer)] != 0; }
  // Frame `f` (0..frames) of a finished job's buffer, joint `j` in model order.
  double frame(int buffer, int f, int j) const {
    return values_[static_cast<std::size_t>(buffer)]
                  [static_cast<std::size_t>(f) * static_cast<std::size_t>(dims_) +
                   static_cast<std::size_t>(j)];
  }
  int dims() const { return dims_; }
  // Jobs posted so far.
  std::uint64_t jobs() const { return posted_.load(std::memory_order_relaxed); }
  int capacity() const { return capacity_; }
  int buffers() const { return static_cast<int>(values_.size()); }

  // Lockstep (not the real-time cycle): wait up to `limit` of wall time for
  // the job to finish, or for the worker to become idle (job 0).
  bool wait(std::uint64_t job, std::chrono::nanoseconds limit) const;

  // Any thread: the wall time of the last and of the slowest completion.
  std::chrono::nanoseconds last_compute() const {
    return std::chrono::nanoseconds(last_ns_.load(std::memory_order_relaxed));
  }
  std::chrono::nanoseconds max_compute() const {
    return std::chrono::nanoseconds(max_ns_.load(std::memory_order_relaxed));
  }
  // Tests: every completion takes at least this long (a slow model).
  void set_delay(std::chrono::nanoseconds delay) {
    delay_ns_.store(delay.count(), std::memory_order_relaxed);
  }

 private:
  void run();
  void compute(int model, int frames, int buffer);

  std::vector<std::unique_ptr<seqnet::SeqNetInference>> nets_;
  std::vector<Model> models_;
  int dims_;
  int capacity_;
  std::vector<std::vector<double>> values_;
  std::vector<char> ok_;
  std::vector<double> from_, to_;
  // The job: written by the cycle while idle, read by the worker after post.
  int job_model_ = 0, job_frames_ = 0, job_buffer_ = 0;
  std::atomic<std::uint64_t> posted_{0};
  std::atomic<std::uint64_t> done_{0};
  std::atomic<bool> quit_{false};
  std::atomic<std::int64_t> last_ns_{0}, max_ns_{0}, delay_ns_{0};
  std::thread thread_;
};

}  // namespace animrt
