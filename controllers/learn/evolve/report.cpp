// CSV and SVG output of an evolve run (see report.hpp).

#include "animrt/learn/evolve/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "animrt/core/plot_axis.hpp"
#include "text_output.hpp"

namespace animrt::evolve {

std::string format_progress(const GenerationStats& s, int generations) {
  const double rate = s.seconds > 0 ? s.evaluations / s.seconds : 0.0;
  std::ostringstream o;
  o << "gen " << s.generation << "/" << generations << "  best " << fmt("%.2f", s.best) << "  avg "
    << fmt("%.2f", s.average) << " (sd " << fmt("%.2f", s.stddev) << ")  invalid " << s.invalid
    << "  fell " << s.fell << "  " << s.evaluations << " evals  " << fmt("%.1f", rate)
    << " evals/s";
  return o.str();
}

void write_history_csv(const std::vector<GenerationStats>& history, const std::string& path) {
  auto out = open_out(path);
  out << "generation,best,average,stddev,invalid,fell,evaluations,seconds,evals_per_s,"
         "best_speed,best_stride_length,best_duty_factor,best_energy_per_cycle\n";
  for (const auto& s : history) {
    const double rate = s.seconds > 0 ? s.evaluations / s.seconds : 0.0;
    out << s.generation << ',' << fmt("%.6g", s.best) << ',' << fmt("%.6g", s.average) << ','
        << fmt("%.6g", s.stddev) << ',' << s.invalid << ',' << s.fell << ',' << s.evaluations << ','
        << fmt("%.4f", s.seconds) << ',' << fmt("%.2f", rate) << ','
        << fmt("%.6g", s.best_measures.speed) << ',' << fmt("%.6g", s.best_measures.stride_length)
        << ',' << fmt("%.6g", s.best_measures.duty_factor) << ','
        << fmt("%.6g", s.best_measures.energy_per_cycle) << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

void write_history_svg(const std::vector<GenerationStats>& history, const std::string& title,
                       const std::string& path) {
  constexpr double kW = 640, kH = 400, kL = 70, kR = 20, kT = 40, kB = 50;
  double lo = 1e300, hi = 0;
  for (const auto& s : history) {
    lo = std::min(lo, std::max(s.best, 1e-3));
    hi = std::max(hi, std::max(s.average, s.best));
  }
  if (history.empty()) lo = hi = 1;
  const double llo = std::floor(std::log10(lo));
  const double lhi = std::max(llo + 1, std::ceil(std::log10(std::max(hi, lo))));
  const double gens =
      std::max(1.0, static_cast<double>(history.size() - (history.empty() ? 0 : 1)));
  const auto x = [&](double g) { return kL + (kW - kL - kR) * g / gens; };
  const auto y = [&](double v) {
    return kT + (kH - kT - kB) * (1 - (std::log10(std::max(v, 1e-3)) - llo) / (lhi - llo));
  };
  auto out = open_out(path);
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kW << "\" height=\"" << kH
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << kW / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">" << title
      << "</text>\n";
  for (double d = llo; d <= lhi + 1e-9; d += 1) {
    const double v = std::pow(10.0, d);
    out << "<line x1=\"" << kL << "\" x2=\"" << kW - kR << "\" y1=\"" << y(v) << "\" y2=\"" << y(v)
        << "\" stroke=\"#ddd\"/>\n<text x=\"" << kL - 6 << "\" y=\"" << y(v) + 4
        << "\" text-anchor=\"end\">" << fmt("%g", v) << "</text>\n";
  }
  out << "<line x1=\"" << kL << "\" x2=\"" << kL << "\" y1=\"" << kT << "\" y2=\"" << kH - kB
      << "\" stroke=\"black\"/>\n<line x1=\"" << kL << "\" x2=\"" << kW - kR << "\" y1=\""
      << kH - kB << "\" y2=\"" << kH - kB << "\" stroke=\"black\"/>\n";
  const int step = std::max(1, static_cast<int>(nice_number(std::max(1.0, gens / 8), true)));
  for (int g = 0; g <= static_cast<int>(gens); g += step) {
    out << "<text x=\"" << x(g) << "\" y=\"" << kH - kB + 18 << "\" text-anchor=\"middle\">" << g
        << "</text>\n";
  }
  out << "<text x=\"" << (kL + kW - kR) / 2 << "\" y=\"" << kH - 10
      << "\" text-anchor=\"middle\">generation</text>\n"
      << "<text x=\"16\" y=\"" << (kT + kH - kB) / 2 << "\" transform=\"rotate(-90 16 "
      << (kT + kH - kB) / 2 << ")\" text-anchor=\"middle\">fitness (lower is better)</text>\n";
  const auto line = [&](auto get, const char* colour, const char* label, int row) {
    out << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"2\" points=\"";
    for (const auto& s : history) out << x(s.generation) << ',' << y(get(s)) << ' ';
    out << "\"/>\n<text x=\"" << kW - kR - 110 << "\" y=\"" << kT + 14 * row << "\" fill=\""
        << colour << "\">" << label << "</text>\n";
  };
  line([](const GenerationStats& s) { return s.best; }, "#1f77b4", "best", 1);
  line([](const GenerationStats& s) { return s.average; }, "#d62728", "average", 2);
  out << "</svg>\n";
  if (!out) throw std::runtime_error("cannot write " + path);
}

}  // namespace animrt::evolve
