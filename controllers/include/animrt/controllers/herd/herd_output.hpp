#pragma once
// What a herd run leaves behind: the CSV of every agent at every output
// step, a top view (SVG: bounds, walls, obstacles, targets, trails coloured
// by group) and the summary.

#include <ostream>
#include <string>
#include <vector>

#include "animrt/controllers/herd/herd.hpp"

namespace animrt::herd {

// time_s,agent,group,x_m,y_m,heading_rad,speed_mps,turn_rps
void write_csv_header(std::ostream& out);
void write_csv_rows(std::ostream& out, const Herd& herd);

// Positions of every agent at every output step, for the top view.
class TrailRecorder {
 public:
  void sample(const Herd& herd);
  // The top view as SVG text: walls, obstacles, each figure's trail from a start mark
  // (a square) to where it stands, targets (rings), each leader's path
  // (dashed), a legend of the groups and a scale bar.
  std::string svg(const Herd& herd) const;

 private:
  std::vector<std::vector<Vec2>> trails_;         // per agent
  std::vector<std::vector<Vec2>> leader_trails_;  // per group (empty without a leader)
};

// A group's order as printed: "standing" for a flock that does not keep up
// with its leader, "order n/a" when it was never measured.
std::string format_order(const GroupMetrics& g);

// The summary as text lines (printed at the end of a run).
std::string format_metrics(const HerdMetrics& metrics);

}  // namespace animrt::herd
