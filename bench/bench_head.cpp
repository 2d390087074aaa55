// Head motion: synthesis speed (real-time factor), streaming latency and
// memory, for the bundled model and a minute of speech (the bundled
// utterance repeated).
//
// `bench_head offline` runs only the offline path (model and file reading,
// analysis at 22.05 and 24 kHz, decoding, smoothing) and prints the
// process's CPU time per second of audio, so `/usr/bin/time` and `perf`
// see that path alone on a loaded machine where wall time misleads.

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>

#include "animrt/controllers/head/model.hpp"
#include "animrt/controllers/head/streaming.hpp"
#include "animrt/controllers/head/synthesis.hpp"

using namespace animrt::head;

static long max_rss_kb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

// Streams `audio` in 10 ms blocks; prints speed and latency in audio time.
static void stream_case(const char* name, const HeadModel& model, const Audio& audio,
                        const StreamOptions& so) {
  using clk = std::chrono::steady_clock;
  StreamingSynthesizer s(model, so);
  std::vector<StreamPose> out;
  const std::size_t block = static_cast<std::size_t>(audio.sample_rate / 100);
  double max_lag = 0, sum_lag = 0, max_block_ms = 0;
  std::size_t n = 0;
  const auto t0 = clk::now();
  for (std::size_t i = 0; i < audio.samples.size(); i += block) {
    const std::size_t before = out.size();
    const auto b0 = clk::now();
    s.push(
        std::span<const float>(audio.samples.data() + i, std::min(block, audio.samples.size() - i)),
        out);
    max_block_ms =
        std::max(max_block_ms, std::chrono::duration<double, std::milli>(clk::now() - b0).count());
    for (std::size_t j = before; j < out.size(); ++j) {
      const double lag = s.audio_time_s() - out[j].t;  // audio heard minus pose time
      max_lag = std::max(max_lag, lag);
      sum_lag += lag;
      ++n;
    }
  }
  s.finish(out);
  const double stream_s = std::chrono::duration<double>(clk::now() - t0).count();
  std::printf("%s:\n  %.3f s  real-time factor %.4f; worst block (10 ms of audio) %.2f ms\n", name,
              stream_s, stream_s / 60.0, max_block_ms);
  std::printf("  latency (audio pushed - pose time): mean %.3f s, max %.3f s, bound %.3f s\n",
              sum_lag / static_cast<double>(n), max_lag, s.worst_case_latency_s());
}

// User plus system CPU of this (single-threaded) process, in seconds.
static double cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// The bundled utterance repeated to one minute.
static Audio one_minute(const Audio& one) {
  Audio minute;
  minute.sample_rate = one.sample_rate;
  while (minute.duration_s() < 60.0)
    minute.samples.insert(minute.samples.end(), one.samples.begin(), one.samples.end());
  minute.samples.resize(static_cast<std::size_t>(60.0 * minute.sample_rate));
  return minute;
}

// The offline path alone, `rounds` times, timed by CPU.
static int offline_only(const std::string& src, int rounds) {
  const double c0 = cpu_s();
  const HeadModel model = load_model(src + "/configs/head/model.txt");
  const Audio minute = one_minute(load_audio(src + "/configs/head/utterance.wav"));
  const double c_load = cpu_s();
  const Audio minute24 = resample(minute, model.features.sample_rate);
  double at22 = 0, at24 = 0;
  std::size_t poses = 0;
  for (int r = 0; r < rounds; ++r) {
    double c = cpu_s();
    poses += synthesize(model, minute).size();
    at22 += cpu_s() - c;
    c = cpu_s();
    poses += synthesize(model, minute24).size();
    at24 += cpu_s() - c;
  }
  std::printf("offline only, %d rounds of 60 s at %d Hz and at %d Hz (%zu poses)\n", rounds,
              minute.sample_rate, minute24.sample_rate, poses);
  std::printf("  model and file reading: %.3f s CPU\n", c_load - c0);
  std::printf("  %d Hz: %.4f s CPU per 60 s (%.0fx real time)\n", minute.sample_rate, at22 / rounds,
              60.0 * rounds / at22);
  std::printf("  %d Hz: %.4f s CPU per 60 s (%.0fx real time)\n", minute24.sample_rate,
              at24 / rounds, 60.0 * rounds / at24);
  return 0;
}

int main(int argc, char** argv) {
  const std::string src = ANIMRT_SOURCE_DIR;
  if (argc > 1 && std::strcmp(argv[1], "offline") == 0)
    return offline_only(src, argc > 2 ? std::max(1, std::atoi(argv[2])) : 5);
  const long rss0 = max_rss_kb();
  const HeadModel model = load_model(src + "/configs/head/model.txt");
  const long rss_model = max_rss_kb();
  const Audio minute = one_minute(load_audio(src + "/configs/head/utterance.wav"));

  using clk = std::chrono::steady_clock;
  auto t0 = clk::now();
  const PoseTrack offline = synthesize(model, minute);
  const double offline_s = std::chrono::duration<double>(clk::now() - t0).count();
  // Where a 22.05 kHz file's time goes: the resampling alone, with the
  // converter the analysis uses and with the medium-quality one.
  t0 = clk::now();
  const Audio minute24 = resample(minute, model.features.sample_rate);
  const double resample_s = std::chrono::duration<double>(clk::now() - t0).count();
  t0 = clk::now();
  (void)resample(minute, model.features.sample_rate, ResampleQuality::medium);
  const double resample_medium_s = std::chrono::duration<double>(clk::now() - t0).count();
  // At the model's own rate (24 kHz): the analysis without resampling.
  t0 = clk::now();
  const PoseTrack offline24 = synthesize(model, minute24);
  const double offline24_s = std::chrono::duration<double>(clk::now() - t0).count();
  const long rss_offline = max_rss_kb();

  std::printf("head synthesis, 60 s of speech, model K=%d S=%d M=%d %s\n", model.clusters(),
              model.states, model.mixtures, topology_name(model.topology));
  std::printf("offline:   %.3f s  real-time factor %.4f (%.0fx faster than real time), %zu poses\n",
              offline_s, offline_s / 60.0, 60.0 / offline_s, offline.size());
  std::printf("offline, 24 kHz input: %.3f s  (%.0fx faster than real time), %zu poses\n",
              offline24_s, 60.0 / offline24_s, offline24.size());
  std::printf(
      "resampling 60 s from %d Hz: %.3f s (polyphase, as the analysis does), %.3f s "
      "(medium-quality sinc)\n",
      minute.sample_rate, resample_s, resample_medium_s);
  StreamOptions squad;
  squad.input_rate = minute.sample_rate;
  stream_case("streaming (SQUAD, decoder lag 0.2 s, gap fill 0.15 s)", model, minute, squad);
  StreamOptions live = squad;
  live.causal = true;
  live.decoder_lag_s = 0.07;
  live.max_gap_s = 0.0;
  stream_case("streaming (causal, decoder lag 0.07 s, no gap fill)", model, minute, live);
  std::printf("memory (max RSS): start %ld KiB, +model %ld KiB, +60 s offline synthesis %ld KiB\n",
              rss0, rss_model - rss0, rss_offline - rss_model);
  return 0;
}
