#include "animrt/runtime/ltc_receiver.hpp"

#include <ltc.h>
#include <time.h>

#include <cmath>
#include <optional>

#include "animrt/controllers/head/alsa_audio.hpp"
#include "animrt/controllers/head/audio.hpp"

namespace animrt {
namespace {

constexpr int kBlocksPerSecond = 100;
constexpr int kDecoderQueue = 32;

timespec ltc_at(std::int64_t ns) {
  return {static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

std::int64_t ltc_now_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

struct LtcReceiver::Input {
  int sample_rate = 48000;
  std::optional<head::AlsaCapture> capture;
  head::Audio file;
  std::size_t played = 0;  // samples taken so far
  std::int64_t start_ns = 0;
  LTCDecoder* decoder = nullptr;
  ~Input() {
    if (decoder) ltc_decoder_free(decoder);
  }
};

LtcReceiver::LtcReceiver(const std::string& input, double fps, double freewheel_s,
                         std::vector<TimecodeCue> cues, Handler handler)
    : input_(std::make_unique<Input>()),
      fps_(fps),
      chase_(fps, freewheel_s, std::move(cues)),
      handler_(std::move(handler)) {
  constexpr std::string_view kAlsa = "alsa:";
  if (input.rfind(kAlsa, 0) == 0) {
    input_->capture.emplace(input.substr(kAlsa.size()), input_->sample_rate);
  } else {
    input_->file = head::load_audio(input);
    input_->sample_rate = input_->file.sample_rate;
  }
  input_->decoder = ltc_decoder_create(static_cast<int>(input_->sample_rate / fps), kDecoderQueue);
  thread_ = std::thread([this] { run(); });
}

LtcReceiver::~LtcReceiver() {
  running_.store(false);
  if (thread_.joinable()) thread_.join();
}

void LtcReceiver::run() {
  Input& in = *input_;
  const std::size_t block = static_cast<std::size_t>(in.sample_rate / kBlocksPerSecond);
  std::vector<float> samples(block, 0.0f);
  if (!in.capture) {
    while (running_.load() && !begun_.load(std::memory_order_acquire)) {
      const timespec pause{0, 10'000'000};
      ::nanosleep(&pause, nullptr);
    }
    in.start_ns = ltc_now_ns();
  }
  while (running_.load()) {
    if (in.capture) {
      in.capture->read(samples);
    } else {
      // The file as a capture device would deliver it: a block once its
      // last sample is due on the monotonic clock; silence after its end.
      const std::int64_t due =
          in.start_ns + static_cast<std::int64_t>((in.played + block) * 1e9 / in.sample_rate);
      const timespec at = ltc_at(due);
      ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr);
      for (std::size_t i = 0; i < block; ++i) {
        const std::size_t k = in.played + i;
        samples[i] = k < in.file.samples.size() ? in.file.samples[k] : 0.0f;
      }
    }
    decode(samples.data(), block);
  }
}

void LtcReceiver::decode(const float* samples, std::size_t count) {
  Input& in = *input_;
  ltc_decoder_write_float(in.decoder, const_cast<float*>(samples), count,
                          static_cast<ltc_off_t>(in.played));
  in.played += count;
  LTCFrameExt frame{};
  while (ltc_decoder_read(in.decoder, &frame) > 0) {
    SMPTETimecode time{};
    ltc_frame_to_time(&time, &frame.ltc, 0);
    // A time no clock shows (hour 24, second 60, a frame number at or past
    // the rate) is noise or a misset generator: counted, never chased.
    if (time.hours > 23 || time.mins > 59 || time.secs > 59 || time.frame >= std::ceil(fps_)) {
      malformed_.fetch_add(1);
      continue;
    }
    const double tc = time.hours * 3600.0 + time.mins * 60.0 + time.secs + time.frame / fps_;
    // From its start: the decoder reports the end of the last frame before
    // a silence only when the signal comes back.
    const double start_s = static_cast<double>(frame.off_start) / in.sample_rate;
    chase_.frame(tc, start_s + 1.0 / fps_);
  }
  const int cue = chase_.advance(static_cast<double>(in.played) / in.sample_rate);
  frames_.store(chase_.frames());
  jumps_.store(chase_.jumps());
  dropouts_.store(chase_.dropouts());
  losses_.store(chase_.losses());
  if (cue >= 0) {
    asked_.fetch_add(1);
    handler_(cue, chase_.cue_offset());
  }
}

}  // namespace animrt
