#pragma once
// A synthetic audiovisual corpus for the head-motion learner (the paper's
// motion-capture database is not public). It generates data and knows
// nothing of the learner: utterances are spoken by espeak-ng (several
// voices, rates, pitch contours and emphasis) and the head motion is made
// from each utterance's own prosody by a documented stochastic model, so the
// speech-motion coupling is real but known (docs/head.md, "Corpus").
//
// Output folder: NAME.wav (espeak-ng's 22050 Hz mono), NAME.csv (Euler
// angles at 120 Hz: time_s, yaw_deg, pitch_deg, roll_deg), and corpus.txt
// describing every utterance (speaker, voice, rate, text, motion style).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace animrt::learn::head_corpus {

// Per-speaker motion style (degrees).
struct SpeakerStyle {
  std::string voice;   // espeak-ng voice, e.g. "en-us+m3"
  int pitch = 50;      // espeak-ng -p (0..99)
  int rate_wpm = 160;  // espeak-ng -s
  double rest_yaw = 0, rest_pitch = 0, rest_roll = 0;
  double nod_deg = 10.0;          // peak nod at a pitch accent
  double f0_pitch_deg = 1.2;      // head up per semitone above the speaker's median F0
  double f0_roll_deg = 0.6;       // roll per semitone
  double energy_pitch_deg = 4.0;  // head up at full loudness
  double sway_deg = 3.0;          // yaw sway amplitude at full loudness
  double sway_hz = 0.35;
  double drift_deg = 1.0;  // std of the slow random drift
};

struct CorpusOptions {
  int utterances = 40;
  int speakers = 4;  // styles drawn from a fixed list, cycled
  std::uint64_t seed = 1;
  double pose_rate_hz = 120.0;
  std::string espeak = "espeak-ng";  // program name or path
  std::function<void(const std::string&)> log;
};

// Prosody the motion model reads (its own analysis, independent of the
// learner's features): per 10 ms frame, F0 in Hz (0 unvoiced) and RMS energy.
struct GeneratorProsody {
  double frame_rate_hz = 100.0;
  std::vector<double> f0_hz, energy;
};
GeneratorProsody analyse_prosody(const std::vector<float>& samples, int sample_rate);

struct Motion {
  std::vector<double> times, yaw, pitch, roll;
  std::vector<double> accent_times;  // where the model placed nods
};
// The stochastic head-motion model applied to one utterance's prosody.
Motion head_motion(const GeneratorProsody& prosody, const SpeakerStyle& style, double duration_s,
                   double pose_rate_hz, std::uint64_t seed);

const std::vector<SpeakerStyle>& speaker_styles();

// Generates the corpus into `dir` (created if needed). Throws
// std::runtime_error when espeak-ng cannot be run.
void generate_corpus(const std::string& dir, const CorpusOptions& options);

// Speaks `ssml` with espeak-ng into a WAV file.
void speak_to_wav(const std::string& espeak, const std::string& voice, int pitch, int rate_wpm,
                  const std::string& ssml, const std::string& wav_path);

}  // namespace animrt::learn::head_corpus
