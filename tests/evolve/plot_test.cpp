// The Pareto front's SVG plot: axis ticks at round numbers, point labels
// that never overlap one another.

#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "animrt/learn/evolve/pareto_report.hpp"
#include "support/files.hpp"

namespace animrt::evolve {
namespace {

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
    const std::regex tick(std::string(R"(<text x="[^"]*" y="[^"]*" text-anchor=")") + anchor +
                          R"(">([-0-9.e]+)</text>)");
    for (std::sregex_iterator it(svg.begin(), svg.end(), tick), end; it != end; ++it) {
      ticks.push_back(std::stod((*it)[1]));
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
  const std::regex label(
      R"re(<text x="([-0-9.e]+)" y="([-0-9.e]+)" font-size="10">(\d+)</text>)re");
  for (std::sregex_iterator it(svg.begin(), svg.end(), label), end; it != end; ++it) {
    const double x = std::stod((*it)[1]), y = std::stod((*it)[2]);
    const double w = 6.0 * static_cast<double>((*it)[3].length());
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
