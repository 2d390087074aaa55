#include "animrt/controllers/cues/transition_worker.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include "animrt/controllers/seqnet/inference.hpp"

namespace animrt {

seqnet::CompletionOptions TransitionWorker::completion_options() {
  seqnet::CompletionOptions options;
  options.retries = 0;
  options.blend = true;
  return options;
}

TransitionWorker::TransitionWorker(const std::vector<Model>& models, int dims, int capacity,
                                   int buffers)
    : models_(models), dims_(dims), capacity_(capacity) {
  for (const Model& m : models_)
    nets_.push_back(std::make_unique<seqnet::SeqNetInference>(*m.file, m.path));
  values_.assign(
      static_cast<std::size_t>(buffers),
      std::vector<double>(static_cast<std::size_t>(dims) * static_cast<std::size_t>(capacity)));
  ok_.assign(static_cast<std::size_t>(buffers), 0);
  from_.assign(static_cast<std::size_t>(dims), 0.0);
  to_.assign(static_cast<std::size_t>(dims), 0.0);
  thread_ = std::thread([this] { run(); });
}

TransitionWorker::~TransitionWorker() {
  quit_.store(true, std::memory_order_release);
  posted_.fetch_add(1, std::memory_order_release);  // wakes the worker
  posted_.notify_one();
  thread_.join();
}

std::uint64_t TransitionWorker::post(int model, int frames, int buffer) {
  job_model_ = model;
  job_frames_ = frames;
  job_buffer_ = buffer;
  const std::uint64_t job = posted_.load(std::memory_order_relaxed) + 1;
  posted_.store(job, std::memory_order_release);
  posted_.notify_one();  // a futex wake: it does not block
  return job;
}

bool TransitionWorker::wait(std::uint64_t job, std::chrono::nanoseconds limit) const {
  const auto until = std::chrono::steady_clock::now() + limit;
  for (;;) {
    if (job == 0 ? idle() : finished(job)) return true;
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
}

void TransitionWorker::run() {
  std::uint64_t seen = 0;
  for (;;) {
    posted_.wait(seen, std::memory_order_acquire);
    if (quit_.load(std::memory_order_acquire)) return;
    seen = posted_.load(std::memory_order_acquire);
    const auto begin = std::chrono::steady_clock::now();
    compute(job_model_, job_frames_, job_buffer_);
    if (const std::int64_t delay = delay_ns_.load(std::memory_order_relaxed); delay > 0) {
      std::this_thread::sleep_until(begin + std::chrono::nanoseconds(delay));
    }
    const std::int64_t took = (std::chrono::steady_clock::now() - begin).count();
    last_ns_.store(took, std::memory_order_relaxed);
    if (took > max_ns_.load(std::memory_order_relaxed))
      max_ns_.store(took, std::memory_order_relaxed);
    done_.store(seen, std::memory_order_release);
  }
}

// The model's completion between the two keys, `frames` - 1 frames between;
// anything not finite (or an error) makes the in-between unusable.
void TransitionWorker::compute(int model, int frames, int buffer) {
  const auto b = static_cast<std::size_t>(buffer);
  ok_[b] = 0;
  seqnet::SeqNetInference& net = *nets_[static_cast<std::size_t>(model)];
  const int dims = net.dims();
  if (frames < 2 || frames + 1 > capacity_ || dims > dims_) return;
  try {
    seqnet::FrameMatrix keys(dims, 2);
    for (int j = 0; j < dims; ++j) {
      keys(j, 0) = from_[static_cast<std::size_t>(j)];
      keys(j, 1) = to_[static_cast<std::size_t>(j)];
    }
    const seqnet::Completion done = net.complete(keys, {frames - 1}, completion_options());
    bool finite = true;
    for (int f = 0; f <= frames; ++f) {
      for (int j = 0; j < dims; ++j) {
        const double v = done.frames(j, f);
        finite = finite && std::isfinite(v);
        values_[b][static_cast<std::size_t>(f) * static_cast<std::size_t>(dims_) +
                   static_cast<std::size_t>(j)] = v;
      }
    }
    ok_[b] = finite ? 1 : 0;
  } catch (const std::exception&) {
    ok_[b] = 0;
  }
}

}  // namespace animrt
