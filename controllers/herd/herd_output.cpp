#include "animrt/controllers/herd/herd_output.hpp"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "herd_groups.hpp"

namespace animrt::herd {
namespace {

const char* const kPalette[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd",
                                "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};

const char* group_colour(int g) {
  return kPalette[static_cast<std::size_t>(g) % std::size(kPalette)];
}

std::string box_polygon(const Box& b, double (*sx)(double, const Rect&),
                        double (*sy)(double, const Rect&), const Rect& r) {
  const Vec2 ax = heading_vector(b.yaw_rad);
  const Vec2 ay{-ax.y, ax.x};
  std::string pts;
  for (const auto& [u, v] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const Vec2 p = b.center + ax * (u * b.size.x / 2) + ay * (v * b.size.y / 2);
    pts += fmt::format("{:.3f},{:.3f} ", sx(p.x, r), sy(p.y, r));
  }
  return pts;
}

constexpr double kPixelsPerMetre = 25.0;
double to_x(double x, const Rect& r) { return (x - r.xmin) * kPixelsPerMetre; }
double to_y(double y, const Rect& r) { return (r.ymax - y) * kPixelsPerMetre; }  // y up on screen

std::string xml_text(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

std::string path_data(const std::vector<Vec2>& points, const Rect& r) {
  std::string d;
  for (const Vec2& p : points) {
    d += fmt::format("{}{:.2f},{:.2f} ", d.empty() ? "M" : "L", to_x(p.x, r), to_y(p.y, r));
  }
  return d;
}

// The longest of 1, 2, 5, 10, 20, ... m that fits a fifth of the width.
double scale_length(double width_m) {
  double len = 1.0;
  for (double m = 1.0; m <= width_m / 5; m *= 10) {
    for (double f : {1.0, 2.0, 5.0}) {
      if (f * m <= width_m / 5) len = f * m;
    }
  }
  return len;
}

void write_scale_bar(std::ostream& out, const Rect& r) {
  const double len = scale_length(r.xmax - r.xmin);
  const double h = (r.ymax - r.ymin) * kPixelsPerMetre, x0 = 10, y0 = h - 12;
  const double x1 = x0 + len * kPixelsPerMetre;
  out << fmt::format(
      "<g class=\"scale\"><path d=\"M{0:.1f},{1:.1f} V{2:.1f} H{3:.1f} V{1:.1f}\" "
      "fill=\"none\" stroke=\"#000\" stroke-width=\"2\"/><text x=\"{4:.1f}\" y=\"{5:.1f}\" "
      "font-family=\"sans-serif\" font-size=\"11\" text-anchor=\"middle\">{6} m</text></g>\n",
      x0, y0 - 5, y0, x1, (x0 + x1) / 2, y0 - 4, len);
}

void write_legend(std::ostream& out, const HerdScene& scene, bool has_leader) {
  const double row = 15, x = 8, y = 8;
  const std::size_t n = scene.groups.size() + 1 + (has_leader ? 1 : 0);
  out << fmt::format(
      "<g class=\"legend\" font-family=\"sans-serif\" font-size=\"11\"><rect x=\"{}\" "
      "y=\"{}\" width=\"230\" height=\"{:.0f}\" fill=\"#fff\" fill-opacity=\"0.85\" "
      "stroke=\"#999\"/>\n",
      x, y, row * static_cast<double>(n) + 6);
  double ty = y + row;
  for (std::size_t g = 0; g < scene.groups.size(); ++g, ty += row) {
    const GroupSpec& spec = scene.groups[g];
    const char* kind = spec.kind == GroupKind::crowd   ? "crowd"
                       : spec.kind == GroupKind::unity ? "unity flock"
                                                       : "reynolds flock";
    out << fmt::format(
        "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"5\" fill=\"{}\"/><text x=\"{:.1f}\" "
        "y=\"{:.1f}\">{} ({}, {} figures)</text>\n",
        x + 12, ty - 4, group_colour(static_cast<int>(g)), x + 24, ty, xml_text(spec.name), kind,
        spec.count);
  }
  out << fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"7\" height=\"7\" fill=\"none\" "
      "stroke=\"#000\"/><text x=\"{:.1f}\" y=\"{:.1f}\">start, trail, end; ring: target</text>\n",
      x + 8.5, ty - 7.5, x + 24, ty);
  if (has_leader) {
    ty += row;
    out << fmt::format(
        "<path d=\"M{:.1f},{:.1f} h14\" stroke=\"#000\" stroke-width=\"2\" "
        "stroke-dasharray=\"5 3\"/><text x=\"{:.1f}\" y=\"{:.1f}\">leader's path</text>\n",
        x + 5, ty - 4, x + 24, ty);
  }
  out << "</g>\n";
}

}  // namespace

void write_csv_header(std::ostream& out) {
  out << "time_s,agent,group,x_m,y_m,heading_rad,speed_mps,turn_rps\n";
}

void write_csv_rows(std::ostream& out, const Herd& herd) {
  const auto agents = herd.agents();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const Agent& a = agents[i];
    out << fmt::format("{:.3f},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f}\n", herd.time(),
                       herd.agent_name(static_cast<int>(i)),
                       herd.scene().groups[static_cast<std::size_t>(a.group)].name, a.position.x,
                       a.position.y, a.heading, a.speed, a.turn);
  }
}

void TrailRecorder::sample(const Herd& herd) {
  const auto agents = herd.agents();
  trails_.resize(agents.size());
  for (std::size_t i = 0; i < agents.size(); ++i) trails_[i].push_back(agents[i].position);
  const std::size_t groups = herd.scene().groups.size();
  leader_trails_.resize(groups);
  for (std::size_t g = 0; g < groups; ++g) {
    if (const auto l = herd.leader(static_cast<int>(g))) leader_trails_[g].push_back(*l);
  }
}

std::string TrailRecorder::svg(const Herd& herd) const {
  const HerdScene& scene = herd.scene();
  const Rect& r = scene.bounds_m;
  std::ostringstream out;
  const double w = (r.xmax - r.xmin) * kPixelsPerMetre, h = (r.ymax - r.ymin) * kPixelsPerMetre;
  out << fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0f}\" height=\"{:.0f}\" viewBox=\"0 0 "
      "{:.0f} "
      "{:.0f}\">\n",
      w, h, w, h);
  out << fmt::format("<title>{} (top view, {:.0f} px per metre)</title>\n",
                     scene.name.empty() ? scene.file : scene.name, kPixelsPerMetre);
  out << fmt::format(
      "<rect x=\"0\" y=\"0\" width=\"{:.0f}\" height=\"{:.0f}\" fill=\"#f7f7f2\" "
      "stroke=\"#333\"/>\n",
      w, h);
  for (const Box& b : scene.walls) {
    out << "<polygon points=\"" << box_polygon(b, to_x, to_y, r) << "\" fill=\"#555\"/>\n";
  }
  for (const MovingObstacle& o : scene.moving_obstacles) {
    out << "<polygon points=\"" << box_polygon(o.footprint, to_x, to_y, r)
        << "\" fill=\"#999\" fill-opacity=\"0.5\" stroke=\"#555\" stroke-dasharray=\"4 3\"/>\n";
  }
  for (std::size_t i = 0; i < trails_.size(); ++i) {
    const int g = herd.agents()[i].group;
    std::string pts;
    for (const Vec2& p : trails_[i])
      pts += fmt::format("{:.2f},{:.2f} ", to_x(p.x, r), to_y(p.y, r));
    out << fmt::format(
        "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1\" "
        "stroke-opacity=\"0.6\"/>\n",
        pts, group_colour(g));
  }
  bool has_leader = false;
  for (std::size_t g = 0; g < leader_trails_.size(); ++g) {
    if (leader_trails_[g].empty()) continue;
    has_leader = true;
    out << fmt::format(
        "<path class=\"leader\" d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\" "
        "stroke-dasharray=\"5 3\"/>\n",
        path_data(leader_trails_[g], r), group_colour(static_cast<int>(g)));
  }
  for (std::size_t i = 0; i < trails_.size(); ++i) {
    if (trails_[i].empty()) continue;
    const Vec2 p = trails_[i].front();
    out << fmt::format(
        "<rect class=\"start\" x=\"{:.2f}\" y=\"{:.2f}\" width=\"5\" height=\"5\" "
        "fill=\"none\" stroke=\"{}\"/>\n",
        to_x(p.x, r) - 2.5, to_y(p.y, r) - 2.5, group_colour(herd.agents()[i].group));
  }
  for (std::size_t i = 0; i < herd.agents().size(); ++i) {
    const Agent& a = herd.agents()[i];
    out << fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"{:.2f}\" fill=\"{}\"/>\n",
                       to_x(a.position.x, r), to_y(a.position.y, r), a.radius * kPixelsPerMetre,
                       group_colour(a.group));
  }
  for (std::size_t g = 0; g < scene.groups.size(); ++g) {
    const GroupSpec& spec = scene.groups[g];
    if (!spec.target_m) continue;
    const Vec2 t = *spec.target_m;
    out << fmt::format(
        "<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"8\" fill=\"none\" stroke=\"{}\" "
        "stroke-width=\"3\"/>\n",
        to_x(t.x, r), to_y(t.y, r), group_colour(static_cast<int>(g)));
  }
  write_scale_bar(out, r);
  write_legend(out, scene, has_leader);
  out << "</svg>\n";
  return out.str();
}

std::string format_order(const GroupMetrics& g) {
  if (g.standing) return "standing";
  if (g.order_steps == 0) return "order n/a";
  return fmt::format("order {:.3f} mean / {:.3f} min", g.order_mean, g.order_min);
}

std::string format_metrics(const HerdMetrics& m) {
  // Whatever was not measured reads n/a, never a zero that looks measured.
  const std::string pair = m.has_pair
                               ? fmt::format("min pair distance {:.3f} m (clearance {:.3f} m)",
                                             m.min_pair_distance_m, m.min_clearance_m)
                               : std::string("min pair distance n/a");
  std::string s = fmt::format("herd: {:.1f} s, {} collisions, {}, {} contact stops, {} knots\n",
                              m.duration_s, m.collisions, pair, m.contact_stops, m.knots);
  for (const GroupMetrics& g : m.groups) {
    s += fmt::format("  {} ({}, {} figures): {} collisions, {}, speed {:.4f} m/s mean", g.name,
                     g.kind, g.agents, g.collisions, format_order(g), g.speed_mean_mps);
    if (g.leader_speed_mean_mps >= 0)
      s += fmt::format(" (leader {:.4f} m/s)", g.leader_speed_mean_mps);
    s += g.has_neighbour ? fmt::format(", nearest neighbour {:.2f} m", g.nearest_neighbour_mean_m)
                         : std::string(", nearest neighbour n/a");
    if (g.leader_distance_mean_m >= 0) {
      s += fmt::format(", leader {:.2f} m mean / {:.2f} m max", g.leader_distance_mean_m,
                       g.leader_distance_max_m);
    }
    if (g.arrivals > 0) {
      s += fmt::format(
          ", arrived {}/{}, time to goal {:.1f} s mean / {:.1f} s max ({:.2f} x straight-line "
          "time at most), path {:.2f} x straight mean / {:.2f} max, stuck {}",
          g.arrivals, g.agents, g.time_to_goal_mean_s, g.time_to_goal_max_s, g.time_ratio_max,
          g.path_ratio_mean, g.path_ratio_max, g.stuck);
    } else if (g.arrivals == 0) {
      s += fmt::format(", arrived 0/{}, time to goal n/a, path n/a, stuck {}", g.agents, g.stuck);
    }
    s += "\n";
  }
  return s;
}

}  // namespace animrt::herd
