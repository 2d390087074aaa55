// The gait expression language: evaluation of compiled curves against the
// same formulas compiled as C++ (compare the pairs: compiled / native is the
// interpreter's overhead), and parse + compile time (what the evolver pays
// per phenotype).

#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/core/joint.hpp"

namespace {

using animrt::Expression;
using animrt::kPi;

const char* const kSeed = "6.97 + 7.7*sin(1*2*PI*t + -1.07) + 2.56*sin(2*2*PI*t + 2.97)";

double seed_native(double t) {
  return 6.97 + 7.7 * std::sin(1 * 2 * kPi * t + -1.07) + 2.56 * std::sin(2 * 2 * kPi * t + 2.97);
}

// A phenotype of the seed-concatenating grammar: the seed plus 20 appended
// sin/cos terms of the grammar's amplitude and frequency ranges.
struct Term {
  char op;  // '+' or '-'
  double amp;
  int freq;
  bool is_sin;
};
constexpr Term kTerms[20] = {
    {'+', 0.25, 1, true}, {'-', 1.5, 2, false},  {'+', 0.4, 3, true},  {'+', 0.05, 5, false},
    {'-', 3.0, 4, true},  {'+', 12.5, 1, false}, {'-', 0.1, 7, true},  {'+', 2.2, 3, false},
    {'+', 0.75, 6, true}, {'-', 6.25, 2, true},  {'+', 0.9, 8, false}, {'-', 1.1, 4, false},
    {'+', 19.5, 1, true}, {'-', 0.35, 5, true},  {'+', 3.6, 3, true},  {'-', 0.15, 6, false},
    {'+', 4.0, 2, false}, {'-', 0.6, 8, true},   {'+', 2.7, 4, true},  {'-', 0.95, 7, false},
};

std::string long_text() {
  std::string s = kSeed;
  for (const Term& term : kTerms) {
    s += std::string(" ") + term.op + " " + std::to_string(term.amp) + "*" +
         (term.is_sin ? "sin(" : "cos(") + std::to_string(term.freq) + "*2*PI*t)";
  }
  return s;
}

double long_native(double t) {
  double v = seed_native(t);
  for (const Term& term : kTerms) {
    const double x = term.freq * 2 * kPi * t;
    const double y = term.amp * (term.is_sin ? std::sin(x) : std::cos(x));
    v = term.op == '+' ? v + y : v - y;
  }
  return v;
}

// Times march through a few strides so that sin/cos see varied arguments.
constexpr double kStep = 0.001;

void BM_SeedCompiled(benchmark::State& state) {
  const Expression e = Expression::compile(kSeed);
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(e.eval(t));
    t = t > 4.0 ? 0.0 : t + kStep;
  }
}
BENCHMARK(BM_SeedCompiled);

void BM_SeedNative(benchmark::State& state) {
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(seed_native(t));
    t = t > 4.0 ? 0.0 : t + kStep;
  }
}
BENCHMARK(BM_SeedNative);

void BM_Long20Compiled(benchmark::State& state) {
  const Expression e = Expression::compile(long_text());
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(e.eval(t));
    t = t > 4.0 ? 0.0 : t + kStep;
  }
}
BENCHMARK(BM_Long20Compiled);

void BM_Long20Native(benchmark::State& state) {
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(long_native(t));
    t = t > 4.0 ? 0.0 : t + kStep;
  }
}
BENCHMARK(BM_Long20Native);

void BM_ParseCompileSeed(benchmark::State& state) {
  const std::string text = kSeed;
  for (auto _ : state) benchmark::DoNotOptimize(Expression::compile(text));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(text.size()));
}
BENCHMARK(BM_ParseCompileSeed);

void BM_ParseCompileLong20(benchmark::State& state) {
  const std::string text = long_text();
  for (auto _ : state) benchmark::DoNotOptimize(Expression::compile(text));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(text.size()));
}
BENCHMARK(BM_ParseCompileLong20);

}  // namespace

BENCHMARK_MAIN();
