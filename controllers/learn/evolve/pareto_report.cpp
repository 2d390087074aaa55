// Output of a Pareto run (see pareto_report.hpp).

#include "animrt/learn/evolve/pareto_report.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "animrt/core/plot_axis.hpp"
#include "text_output.hpp"

namespace animrt::evolve {

std::string format_pareto_progress(const ParetoGeneration& g, int generations) {
  const double rate = g.seconds > 0 ? g.evaluations / g.seconds : 0.0;
  std::ostringstream o;
  o << "gen " << g.generation << "/" << generations << "  front " << g.front_size;
  if (g.front_size > 0) {
    o << "  best speed err " << fmt("%.3f", g.best_speed_error) << "  energy "
      << fmt("%.3f", g.best_energy) << "  tilt " << fmt("%.1f", g.best_tilt_deg) << " deg";
  }
  o << "  invalid " << g.invalid << "  fell " << g.fell << "  " << g.evaluations << " evals  "
    << fmt("%.1f", rate) << " evals/s";
  return o.str();
}

void write_pareto_history_csv(const std::vector<ParetoGeneration>& history,
                              const std::string& path) {
  auto out = open_out(path);
  out << "generation,front_size,best_speed_error,best_energy,best_tilt_deg,invalid,fell,"
         "evaluations,seconds\n";
  for (const auto& g : history) {
    out << g.generation << ',' << g.front_size << ',' << fmt("%.6g", g.best_speed_error) << ','
        << fmt("%.6g", g.best_energy) << ',' << fmt("%.6g", g.best_tilt_deg) << ',' << g.invalid
        << ',' << g.fell << ',' << g.evaluations << ',' << fmt("%.4f", g.seconds) << '\n';
  }
  close_out(out, path);
}

void write_pareto_front_csv(const std::vector<ParetoMember>& front,
                            const std::vector<std::string>& gait_files, const std::string& path) {
  auto out = open_out(path);
  out << "member,speed_error,energy,tilt_deg,speed_m_s,stride_m,duty_factor,energy_j_per_cycle,"
         "gait\n";
  for (std::size_t i = 0; i < front.size(); ++i) {
    const auto& o = front[i].objectives;
    const auto& m = front[i].individual.measures;
    out << i + 1 << ',' << fmt("%.6g", o[0]) << ',' << fmt("%.6g", o[1]) << ',' << fmt("%.6g", o[2])
        << ',' << fmt("%.6g", m.speed) << ',' << fmt("%.6g", m.stride_length) << ','
        << fmt("%.6g", m.duty_factor) << ',' << fmt("%.6g", m.energy_per_cycle) << ','
        << (i < gait_files.size() ? gait_files[i] : "") << '\n';
  }
  close_out(out, path);
}

void write_pareto_front_svg(const std::vector<ParetoMember>& front, const std::string& title,
                            const std::string& path) {
  constexpr double kW = 640, kH = 420, kL = 70, kR = 120, kT = 40, kB = 50;
  double x_hi = 1e-9, y_hi = 1e-9, t_lo = 1e300, t_hi = -1e300;
  for (const auto& p : front) {
    x_hi = std::max(x_hi, p.objectives[0]);
    y_hi = std::max(y_hi, p.objectives[1]);
    t_lo = std::min(t_lo, p.objectives[2]);
    t_hi = std::max(t_hi, p.objectives[2]);
  }
  const PlotAxis x_axis = nice_axis(0.0, x_hi), y_axis = nice_axis(0.0, y_hi);
  x_hi = x_axis.hi;
  y_hi = y_axis.hi;
  const auto x = [&](double v) { return kL + (kW - kL - kR) * v / x_hi; };
  const auto y = [&](double v) { return kH - kB - (kH - kT - kB) * v / y_hi; };
  // Tilt from blue (steady) to red (the most tilt on the front).
  const auto colour = [&](double t) {
    const double u = t_hi > t_lo ? (t - t_lo) / (t_hi - t_lo) : 0.0;
    char buf[16];
    std::snprintf(buf, sizeof buf, "#%02x40%02x", static_cast<int>(40 + 200 * u),
                  static_cast<int>(240 - 200 * u));
    return std::string(buf);
  };
  auto out = open_out(path);
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kW << "\" height=\"" << kH
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << kW / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">" << title
      << ": Pareto front (" << front.size() << " gaits)</text>\n"
      << "<line x1=\"" << kL << "\" x2=\"" << kL << "\" y1=\"" << kT << "\" y2=\"" << kH - kB
      << "\" stroke=\"black\"/>\n<line x1=\"" << kL << "\" x2=\"" << kW - kR << "\" y1=\""
      << kH - kB << "\" y2=\"" << kH - kB << "\" stroke=\"black\"/>\n";
  for (double vx : x_axis.ticks()) {
    out << "<text x=\"" << x(vx) << "\" y=\"" << kH - kB + 16 << "\" text-anchor=\"middle\">"
        << tick_label(vx, x_axis.step) << "</text>\n";
  }
  for (double vy : y_axis.ticks()) {
    out << "<text x=\"" << kL - 6 << "\" y=\"" << y(vy) + 4 << "\" text-anchor=\"end\">"
        << tick_label(vy, y_axis.step) << "</text>\n";
  }
  out << "<text x=\"" << (kL + kW - kR) / 2 << "\" y=\"" << kH - 12
      << "\" text-anchor=\"middle\">speed error |v - v*| / v*</text>\n"
      << "<text x=\"16\" y=\"" << (kT + kH - kB) / 2 << "\" transform=\"rotate(-90 16 "
      << (kT + kH - kB) / 2 << ")\" text-anchor=\"middle\">cost of transport E / (m g L*)</text>\n";
  // Every marker first, so no label covers one; then the labels where
  // they fit (a crowded point keeps its tooltip only).
  LabelPlacer labels;
  for (const auto& p : front) {
    const double cx = x(p.objectives[0]), cy = y(p.objectives[1]);
    labels.reserve({cx - 5, cy - 5, cx + 5, cy + 5});
  }
  for (std::size_t i = 0; i < front.size(); ++i) {
    const auto& o = front[i].objectives;
    out << "<circle cx=\"" << x(o[0]) << "\" cy=\"" << y(o[1]) << "\" r=\"5\" fill=\""
        << colour(o[2]) << "\"><title>gait " << i + 1 << ": tilt " << fmt("%.1f", o[2])
        << " deg</title></circle>\n";
    const std::string text = std::to_string(i + 1);
    double lx = 0, ly = 0;
    if (labels.place(x(o[0]), y(o[1]), text.size(), 10, lx, ly)) {
      out << "<text x=\"" << lx << "\" y=\"" << ly << "\" font-size=\"10\">" << text << "</text>\n";
    }
  }
  out << "<text x=\"" << kW - kR + 10 << "\" y=\"" << kT + 10 << "\">tilt (deg)</text>\n"
      << "<circle cx=\"" << kW - kR + 16 << "\" cy=\"" << kT + 28 << "\" r=\"5\" fill=\""
      << colour(t_lo) << "\"/><text x=\"" << kW - kR + 26 << "\" y=\"" << kT + 32 << "\">"
      << fmt("%.1f", front.empty() ? 0.0 : t_lo) << "</text>\n"
      << "<circle cx=\"" << kW - kR + 16 << "\" cy=\"" << kT + 48 << "\" r=\"5\" fill=\""
      << colour(t_hi) << "\"/><text x=\"" << kW - kR + 26 << "\" y=\"" << kT + 52 << "\">"
      << fmt("%.1f", front.empty() ? 0.0 : t_hi) << "</text>\n</svg>\n";
  close_out(out, path);
}

}  // namespace animrt::evolve
