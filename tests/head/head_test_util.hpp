#pragma once
// Helpers for the head tests: temp folders, tones, a tiny generated corpus.

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/learn/head_corpus/generator.hpp"

namespace animrt::head::test {

inline std::string temp_dir(const std::string& tag) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("animrt_head_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

// A harmonic tone (fundamental plus two weaker harmonics), like a vowel.
inline Audio tone(double f0, double seconds, int rate = 16000, double amplitude = 0.3) {
  Audio a;
  a.sample_rate = rate;
  const auto n = static_cast<std::size_t>(seconds * rate);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate;
    const double w = 2 * std::numbers::pi * f0 * t;
    a.samples.push_back(static_cast<float>(
        amplitude * (std::sin(w) + 0.5 * std::sin(2 * w) + 0.25 * std::sin(3 * w)) / 1.75));
  }
  return a;
}

inline Audio silence(double seconds, int rate = 16000) {
  Audio a;
  a.sample_rate = rate;
  a.samples.assign(static_cast<std::size_t>(seconds * rate), 0.0f);
  return a;
}

inline Audio concat(const Audio& a, const Audio& b) {
  Audio out = a;
  out.samples.insert(out.samples.end(), b.samples.begin(), b.samples.end());
  return out;
}

// A handful of short espeak-ng utterances with generated head motion, made
// once per test binary.
inline const std::string& tiny_corpus() {
  static const std::string dir = [] {
    const std::string d = temp_dir("corpus");
    learn::head_corpus::CorpusOptions o;
    o.utterances = 10;
    o.speakers = 1;
    o.seed = 7;
    learn::head_corpus::generate_corpus(d, o);
    return d;
  }();
  return dir;
}

}  // namespace animrt::head::test
