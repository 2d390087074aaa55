// The Pareto front's SVG plot: axis ticks at round numbers, point labels
// that never overlap one another.

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "animrt/learn/evolve/pareto_report.hpp"
#include "support/files.hpp"

namespace animrt::evolve {
namespace {

// One <text> element of the SVG: its attributes and its content.
struct SvgText {
  std::string tag;  // everything between "<text" and ">"
  std::string content;
  std::optional<std::string> attr(const std::string& name) const {
    const std::string key = " " + name + "=\"";
    const auto at = tag.find(key);
    if (at == std::string::npos) return std::nullopt;
    const auto from = at + key.size();
    return tag.substr(from, tag.find('"', from) - from);
  }
};

std::vector<SvgText> svg_texts(const std::string& svg) {
  std::vector<SvgText> texts;
  for (auto at = svg.find("<text "); at != std::string::npos; at = svg.find("<text ", at + 1)) {
    const auto close = svg.find('>', at);
    const auto end = svg.find("</text>", close);
    if (close == std::string::npos || end == std::string::npos) break;
    texts.push_back({svg.substr(at + 5, close - at - 5), svg.substr(close + 1, end - close - 1)});
  }
  return texts;
}

bool is_number(const std::string& s, bool digits_only) {
  if (s.empty()) return false;
  for (char c : s) {
    const bool digit = c >= '0' && c <= '9';
    if (!digit && (digits_only || (c != '-' && c != '.' && c != 'e'))) return false;
  }
  return true;
}

// 1, 2 or 5 times a power of ten.
bool round_step(double step) {
  const double f = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
  return std::abs(f - 1) < 1e-6 || std::abs(f - 2) < 1e-6 || std::abs(f - 5) < 1e-6;
}

TEST(ParetoPlot, RoundTicksAndLabelsThatDoNotOverlap) {
  // Objectives whose maxima are not round, and gaits on top of each other.
  std::vector<ParetoMember> front;
  const double points[][3] = {{0.012, 0.271, 1.0}, {0.013, 0.270, 2.0}, {0.0135, 0.2705, 3.0},
                              {1.7, 0.11, 4.0},    {4.52, 0.05, 5.0},   {4.5, 0.051, 6.0}};
  for (const auto& p : points) front.push_back({Individual{}, {p[0], p[1], p[2]}});
  const std::string path = ::testing::TempDir() + "animrt_pareto_plot.svg";
  write_pareto_front_svg(front, "test", path);
  const std::string svg = read_file(path);

  // Axis ticks: x along the bottom (text-anchor middle), y on the left (end).
  for (const char* anchor : {"middle", "end"}) {
    std::vector<double> ticks;
    for (const SvgText& t : svg_texts(svg)) {
      if (t.attr("text-anchor") == anchor && is_number(t.content, false)) {
        ticks.push_back(std::stod(t.content));
      }
    }
    ASSERT_GE(ticks.size(), 3u) << anchor;
    const double step = ticks[1] - ticks[0];
    EXPECT_TRUE(round_step(step)) << anchor << " step " << step;
    for (std::size_t i = 0; i < ticks.size(); ++i) {
      EXPECT_NEAR(ticks[i], ticks[0] + step * static_cast<double>(i), step * 1e-6) << anchor;
      const double k = ticks[i] / step;
      EXPECT_NEAR(k, std::round(k), 1e-6) << anchor << " tick " << ticks[i];
    }
  }

  // Point labels (10 px, about 6 px a character): no two boxes overlap.
  struct Box {
    double x0, y0, x1, y1;
  };
  std::vector<Box> labels;
  for (const SvgText& t : svg_texts(svg)) {
    if (t.attr("font-size") != "10" || !is_number(t.content, true)) continue;
    const double x = std::stod(t.attr("x").value_or("0")), y = std::stod(t.attr("y").value_or("0"));
    const double w = 6.0 * static_cast<double>(t.content.size());
    labels.push_back({x, y - 10, x + w, y});
  }
  EXPECT_GE(labels.size(), 3u);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    for (std::size_t j = i + 1; j < labels.size(); ++j) {
      const Box& a = labels[i];
      const Box& b = labels[j];
      EXPECT_FALSE(a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1)
          << "labels " << i << " and " << j << " overlap";
    }
  }
}

}  // namespace
}  // namespace animrt::evolve
