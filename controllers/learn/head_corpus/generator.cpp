// The corpus generator: espeak-ng speech and a stochastic head-motion model
// driven by the speech's prosody.

#include "animrt/learn/head_corpus/generator.hpp"

#include <aubio/aubio.h>
#include <sndfile.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <stdexcept>

#include "animrt/controllers/head/audio.hpp"

extern char** environ;

namespace animrt::learn::head_corpus {
namespace {

const char* const kSentences[] = {
    "The museum opens at nine and the tickets are sold at the door",
    "I never said that she took the money",
    "Could you bring the blue box from the kitchen please",
    "We walked along the river until the sun went down",
    "That is absolutely the best idea I have heard all week",
    "The robot turned its head and looked at the visitors",
    "Nobody expected the storm to arrive so early in the morning",
    "Please remember to close the windows before you leave",
    "He told me the train would be late again tonight",
    "What a wonderful surprise to see you here",
    "The old lighthouse stands on the rocks above the harbour",
    "If you listen carefully you can hear the waves",
    "She painted the fence green and the door bright red",
    "Honestly I think we should try a different approach",
    "Three small boats sailed past the island at noon",
    "Do you really believe that story about the dragon",
    "The children laughed when the puppet started to sing",
    "Turn left at the bakery and walk two more blocks",
    "My grandfather built this clock more than fifty years ago",
    "Wait a moment, I am not finished with my question",
};

std::string make_ssml(const std::string& sentence, std::mt19937_64& rng, std::string& described) {
  // Emphasis on one or two words; a raised or lowered pitch span.
  std::vector<std::string> words;
  std::string w;
  for (char c : sentence + " ") {
    if (c == ' ') {
      if (!w.empty()) words.push_back(w);
      w.clear();
    } else {
      w += c;
    }
  }
  std::uniform_int_distribution<std::size_t> pick(0, words.size() - 1);
  const std::size_t e1 = pick(rng), e2 = pick(rng);
  std::uniform_int_distribution<int> shift(-25, 35);
  const int contour = shift(rng);
  const std::size_t span_start = pick(rng);
  const std::size_t span_end = std::min(words.size(), span_start + 4);
  std::string out = "<speak>";
  described.clear();
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (i == span_start)
      out += "<prosody pitch=\"" + std::string(contour >= 0 ? "+" : "") + std::to_string(contour) +
             "%\">";
    const bool emph = i == e1 || i == e2;
    out += emph ? "<emphasis level=\"strong\">" + words[i] + "</emphasis>" : words[i];
    if (i + 1 == span_end) out += "</prosody>";
    out += ' ';
    described += emph ? "*" + words[i] + "* " : words[i] + " ";
  }
  out += "</speak>";
  described += "(pitch " + std::to_string(contour) + "% on words " +
               std::to_string(span_start + 1) + "-" + std::to_string(span_end) + ")";
  return out;
}

// Through the one audio loader: its frame count is checked against the
// file before anything is sized from it.
std::vector<float> read_wav(const std::string& path, int& rate) {
  head::Audio audio = head::load_audio(path, 0);
  rate = audio.sample_rate;
  return std::move(audio.samples);
}

// One-pole low-pass with time constant tau (seconds) at `rate`.
std::vector<double> lowpass(const std::vector<double>& x, double tau, double rate) {
  std::vector<double> y(x.size());
  const double a = 1.0 - std::exp(-1.0 / (tau * rate));
  double s = x.empty() ? 0.0 : x[0];
  for (std::size_t i = 0; i < x.size(); ++i) {
    s += a * (x[i] - s);
    y[i] = s;
  }
  return y;
}

}  // namespace

const std::vector<SpeakerStyle>& speaker_styles() {
  static const std::vector<SpeakerStyle> styles = {
      // voice, pitch, rate, rest y/p/r, nod, f0->pitch, f0->roll, energy->pitch, sway, sway_hz,
      // drift
      {"en-us+m3", 48, 160, 2.0, -1.0, 0.5, 10.0, 1.5, 0.8, 8.0, 3.2, 0.30, 1.0},
      {"en-gb+f3", 60, 170, -3.0, 1.0, -1.0, 8.0, 1.2, 1.0, 6.0, 2.4, 0.40, 0.8},
      {"en-us+m1", 45, 145, 0.0, 2.0, 1.5, 12.0, 1.8, 0.6, 9.0, 4.0, 0.25, 1.2},
      {"en-gb-scotland+f2", 55, 180, 4.0, -2.0, 0.0, 9.0, 1.0, 0.9, 7.0, 2.8, 0.45, 1.0},
  };
  return styles;
}

GeneratorProsody analyse_prosody(const std::vector<float>& samples, int sample_rate) {
  GeneratorProsody p;
  const auto hop = static_cast<uint_t>(sample_rate / 100);
  const uint_t win = 1024;
  aubio_pitch_t* pitch = new_aubio_pitch("yin", win, hop, static_cast<uint_t>(sample_rate));
  aubio_pitch_set_unit(pitch, "Hz");
  aubio_pitch_set_silence(pitch, -40.0f);
  fvec_t* in = new_fvec(hop);
  fvec_t* out = new_fvec(1);
  for (std::size_t start = 0; start + hop <= samples.size(); start += hop) {
    double sum = 0;
    for (uint_t i = 0; i < hop; ++i) {
      in->data[i] = samples[start + i];
      sum += static_cast<double>(samples[start + i]) * samples[start + i];
    }
    aubio_pitch_do(pitch, in, out);
    const double conf = aubio_pitch_get_confidence(pitch);
    const double hz = out->data[0];
    p.f0_hz.push_back(conf > 0.5 && hz > 60 && hz < 500 ? hz : 0.0);
    p.energy.push_back(std::sqrt(sum / hop));
  }
  del_fvec(in);
  del_fvec(out);
  del_aubio_pitch(pitch);
  // aubio reports a window late: shift back by half the window.
  const auto lag = static_cast<std::size_t>(std::lround(win / 2.0 / hop));
  if (p.f0_hz.size() > lag)
    p.f0_hz.erase(p.f0_hz.begin(), p.f0_hz.begin() + static_cast<std::ptrdiff_t>(lag));
  p.f0_hz.resize(p.energy.size(), 0.0);
  return p;
}

Motion head_motion(const GeneratorProsody& pr, const SpeakerStyle& st, double duration_s,
                   double pose_rate_hz, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double fr = pr.frame_rate_hz;
  const std::size_t n = pr.energy.size();

  // Semitones relative to the utterance's median voiced F0, held through gaps.
  std::vector<double> voiced;
  for (double f : pr.f0_hz) {
    if (f > 0) voiced.push_back(f);
  }
  double median = 150;
  if (!voiced.empty()) {
    std::nth_element(voiced.begin(),
                     voiced.begin() + static_cast<std::ptrdiff_t>(voiced.size() / 2), voiced.end());
    median = voiced[voiced.size() / 2];
  }
  // Frames more than 10 semitones from the median are the tracker's octave
  // errors, not intonation: treat them as unvoiced.
  std::vector<double> f0 = pr.f0_hz;
  for (double& f : f0) {
    if (f > 0 && std::abs(12.0 * std::log2(f / median)) > 10.0) f = 0.0;
  }
  std::vector<double> semis(n, 0.0), active(n, 0.0);
  double hold = 0;
  const double peak_energy = std::max(1e-6, *std::max_element(pr.energy.begin(), pr.energy.end()));
  std::vector<double> energy(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (f0[i] > 0) hold = 12.0 * std::log2(f0[i] / median);
    semis[i] = hold;
    energy[i] = pr.energy[i] / peak_energy;
    active[i] = energy[i] > 0.05 ? 1.0 : 0.0;
  }
  const std::vector<double> semis_lp = lowpass(semis, 0.12, fr);
  const std::vector<double> energy_lp = lowpass(energy, 0.15, fr);
  const std::vector<double> active_lp = lowpass(active, 0.3, fr);

  // Pitch accents: voiced F0 peaks at least 1.5 semitones above the minimum of
  // the preceding 250 ms, loud enough, 350 ms apart.
  Motion m;
  double last_accent = -1.0;
  const auto look = static_cast<std::size_t>(0.25 * fr);
  std::vector<std::pair<double, double>> accents;  // time, strength
  for (std::size_t i = look; i + 1 < n; ++i) {
    if (f0[i] <= 0 || semis[i] < semis[i - 1] || semis[i] < semis[i + 1]) continue;
    const double lo = *std::min_element(semis.begin() + static_cast<std::ptrdiff_t>(i - look),
                                        semis.begin() + static_cast<std::ptrdiff_t>(i));
    const double prominence = semis[i] - lo;
    const double t = static_cast<double>(i) / fr;
    if (prominence < 1.5 || energy[i] < 0.3 || t - last_accent < 0.35) continue;
    accents.push_back({t, std::min(prominence / 3.0, 2.0)});
    m.accent_times.push_back(t);
    last_accent = t;
  }
  std::vector<double> accent_gain;
  for (std::size_t a = 0; a < accents.size(); ++a)
    accent_gain.push_back(st.nod_deg * (1.0 + 0.25 * normal(rng)));

  // Slow drift: Ornstein-Uhlenbeck per axis (time constant 2 s).
  const double dt = 1.0 / pose_rate_hz;
  const double tau = 2.0;
  const double drift_step = st.drift_deg * std::sqrt(2.0 * dt / tau);
  double drift[3] = {0, 0, 0};
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  const double sway_phase = phase(rng);

  auto sample = [&](const std::vector<double>& v, double t) {
    if (v.empty()) return 0.0;
    const double x = std::clamp(t * fr, 0.0, static_cast<double>(v.size() - 1));
    const auto i = static_cast<std::size_t>(x);
    const std::size_t j = std::min(i + 1, v.size() - 1);
    return v[i] + (x - static_cast<double>(i)) * (v[j] - v[i]);
  };
  const auto frames = static_cast<std::size_t>(std::floor(duration_s * pose_rate_hz)) + 1;
  for (std::size_t k = 0; k < frames; ++k) {
    const double t = static_cast<double>(k) * dt;
    for (double& d : drift) d += -d * dt / tau + drift_step * normal(rng);
    const double act = sample(active_lp, t);
    const double s = sample(semis_lp, t) * act;
    const double e = sample(energy_lp, t);
    double nod = 0;
    for (std::size_t a = 0; a < accents.size(); ++a) {
      // A nod: a raised-cosine dip of 0.4 s, deepest 50 ms after the accent's
      // F0 peak (the head's nod lands on the accented syllable).
      const double u = (t - accents[a].first + 0.15) / 0.4;
      if (u > 0 && u < 1)
        nod += accent_gain[a] * accents[a].second * 0.5 * (1 - std::cos(2 * std::numbers::pi * u));
    }
    m.times.push_back(t);
    m.yaw.push_back(st.rest_yaw +
                    st.sway_deg * e * std::sin(2 * std::numbers::pi * st.sway_hz * t + sway_phase) +
                    drift[0]);
    m.pitch.push_back(st.rest_pitch - st.f0_pitch_deg * s - st.energy_pitch_deg * e + nod +
                      drift[1]);
    m.roll.push_back(st.rest_roll + st.f0_roll_deg * s + drift[2]);
  }
  return m;
}

void speak_to_wav(const std::string& espeak, const std::string& voice, int pitch, int rate_wpm,
                  const std::string& ssml, const std::string& wav_path) {
  std::vector<std::string> args = {
      espeak, "-m",     "-v", voice, "-p", std::to_string(pitch), "-s", std::to_string(rate_wpm),
      "-w",   wav_path, ssml};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, espeak.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    throw std::runtime_error("cannot run " + espeak + " (install espeak-ng)");
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error(espeak + " failed for voice " + voice);
  }
}

void generate_corpus(const std::string& dir, const CorpusOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  std::mt19937_64 rng(options.seed);
  const auto& styles = speaker_styles();
  const int n_speakers = std::clamp(options.speakers, 1, static_cast<int>(styles.size()));
  std::ofstream meta(fs::path(dir) / "corpus.txt");
  meta << "# animrt synthetic head-motion corpus: seed " << options.seed << ", "
       << options.utterances << " utterances, " << n_speakers << " speakers\n";
  std::uniform_int_distribution<int> rate_jitter(-15, 15), pitch_jitter(-8, 8);
  constexpr std::size_t kNumSentences = sizeof(kSentences) / sizeof(kSentences[0]);
  for (int u = 0; u < options.utterances; ++u) {
    const SpeakerStyle& st = styles[static_cast<std::size_t>(u % n_speakers)];
    char name[32];
    std::snprintf(name, sizeof name, "utt_%03d", u);
    const std::string wav = (fs::path(dir) / (std::string(name) + ".wav")).string();
    std::string described;
    const std::string ssml = make_ssml(kSentences[rng() % kNumSentences], rng, described);
    const int pitch = std::clamp(st.pitch + pitch_jitter(rng), 0, 99);
    const int rate = st.rate_wpm + rate_jitter(rng);
    speak_to_wav(options.espeak, st.voice, pitch, rate, ssml, wav);
    int sr = 0;
    const std::vector<float> samples = read_wav(wav, sr);
    const Motion m =
        head_motion(analyse_prosody(samples, sr), st, static_cast<double>(samples.size()) / sr,
                    options.pose_rate_hz, rng());
    std::FILE* f = std::fopen((fs::path(dir) / (std::string(name) + ".csv")).c_str(), "w");
    if (f == nullptr) throw std::runtime_error("cannot write into " + dir);
    std::fprintf(f, "time_s,yaw_deg,pitch_deg,roll_deg\n");
    for (std::size_t i = 0; i < m.times.size(); ++i) {
      std::fprintf(f, "%.6f,%.4f,%.4f,%.4f\n", m.times[i], m.yaw[i], m.pitch[i], m.roll[i]);
    }
    std::fclose(f);
    meta << name << " speaker " << (u % n_speakers) << " voice " << st.voice << " pitch " << pitch
         << " rate " << rate << " accents " << m.accent_times.size() << " text: " << described
         << '\n';
    if (options.log) options.log(std::string(name) + ": " + described);
  }
}

}  // namespace animrt::learn::head_corpus
