// What a steerable gait walks when commanded (see walk_response.hpp).

#include "animrt/controllers/gait/walk_response.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

MotionCommand lerp(const MotionCommand& a, const MotionCommand& b, double u) {
  return {a.speed_m_s + u * (b.speed_m_s - a.speed_m_s),
          a.turn_rad_s + u * (b.turn_rad_s - a.turn_rad_s)};
}

// Candidates per axis in each pass of command_for's search.
constexpr int kSearchSteps = 4;
constexpr int kSearchPasses = 5;
// Nodes per axis of the precomputed grid the search starts from.
constexpr int kGridNodes = 17;

}  // namespace

WalkResponse::WalkResponse(const GaitSteering& steering, const GaitCalibration* calibration)
    : steering_(steering), calibrated_(calibration != nullptr) {
  if (!calibration) return;
  // Every measured point, by commanded speed and then turn.
  std::vector<Level> all;
  for (const CalibrationPoint& p : calibration->points) {
    auto it = std::find_if(all.begin(), all.end(),
                           [&](const Level& l) { return l.speed == p.commanded.speed_m_s; });
    if (it == all.end()) {
      all.push_back(Level{p.commanded.speed_m_s, {}});
      it = all.end() - 1;
    }
    it->points.push_back(p);
  }
  std::sort(all.begin(), all.end(),
            [](const Level& a, const Level& b) { return a.speed < b.speed; });
  if (steering.turn_on_the_spot && !all.empty() && all.front().speed == 0.0) {
    // Turns on the spot, from standing (0, 0) outward on either side until
    // the first unusable one.
    std::vector<CalibrationPoint> spot;  // standing itself (turn 0) is no turn
    for (const CalibrationPoint& p : all.front().points)
      if (p.commanded.turn_rad_s != 0.0) spot.push_back(p);
    std::sort(spot.begin(), spot.end(), [](const auto& a, const auto& b) {
      return a.commanded.turn_rad_s < b.commanded.turn_rad_s;
    });
    const auto zero = std::partition_point(
        spot.begin(), spot.end(), [](const auto& p) { return p.commanded.turn_rad_s < 0.0; });
    auto lo = zero, hi = zero;
    while (lo != spot.begin() && (lo - 1)->usable) --lo;
    while (hi != spot.end() && hi->usable && hi->commanded.turn_rad_s > 0.0) ++hi;
    CalibrationPoint stand;
    stand.usable = true;
    spot_.points.assign(lo, zero);
    spot_.points.push_back(stand);
    spot_.points.insert(spot_.points.end(), zero, hi);
  }
  for (Level& l : all) {
    std::sort(l.points.begin(), l.points.end(), [](const auto& a, const auto& b) {
      return a.commanded.turn_rad_s < b.commanded.turn_rad_s;
    });
    // Keep the usable turns that reach the straight walk without crossing
    // an unusable one: a turn rate between two usable points is only
    // trusted when nothing measured between them failed.
    const auto straight = std::find_if(l.points.begin(), l.points.end(), [](const auto& p) {
      return p.commanded.turn_rad_s == 0.0 && p.usable;
    });
    if (straight == l.points.end()) {
      l.points.clear();
      continue;
    }
    auto lo = straight, hi = straight + 1;
    while (lo != l.points.begin() && (lo - 1)->usable) --lo;
    while (hi != l.points.end() && hi->usable) ++hi;
    l.points = std::vector<CalibrationPoint>(lo, hi);
  }
  // The longest run of speeds whose straight walk is usable (the faster
  // one on a tie): the herd interpolates between neighbouring speeds, so a
  // speed that failed in between must not be bridged.
  std::size_t best_begin = 0, best_len = 0;
  for (std::size_t i = 0; i < all.size();) {
    if (all[i].points.empty()) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < all.size() && !all[j].points.empty()) ++j;
    if (j - i >= best_len) {
      best_begin = i;
      best_len = j - i;
    }
    i = j;
  }
  levels_.assign(all.begin() + static_cast<std::ptrdiff_t>(best_begin),
                 all.begin() + static_cast<std::ptrdiff_t>(best_begin + best_len));
  // What every node of a grid over the usable commands achieves: a herd
  // asks command_for for every figure at every step, and starting its search
  // from the closest node keeps that cheap.
  if (levels_.empty()) return;
  for (int i = 0; i < kGridNodes; ++i) {
    const double v = min_speed() + (max_speed() - min_speed()) * i / (kGridNodes - 1);
    const double limit = max_turn(v);
    for (int k = 0; k < kGridNodes; ++k) {
      const MotionCommand c{v, limit * (2.0 * k / (kGridNodes - 1) - 1.0)};
      grid_.push_back({c, achieved(c)});
    }
  }
}

double WalkResponse::min_speed() const {
  if (!calibrated_) return steering_.min_speed_m_s();
  return levels_.empty() ? 0.0 : levels_.front().speed;
}

double WalkResponse::max_speed() const {
  if (!calibrated_) return steering_.max_speed_m_s();
  return levels_.empty() ? 0.0 : levels_.back().speed;
}

double WalkResponse::max_acceleration() const { return steering_.max_acceleration_m_s2; }

double WalkResponse::spot_turn() const {
  if (!steering_.turn_on_the_spot) return 0.0;
  if (!calibrated_) return steering_.max_turn_rad_s;
  return spot_.points.empty() ? 0.0 : level_max_turn(spot_);
}

MotionCommand WalkResponse::spot_achieved(double turn) const {
  const double limit = spot_turn();
  const double w = std::clamp(std::isfinite(turn) ? turn : 0.0, -limit, limit);
  if (!calibrated_ || w == 0.0) return {0.0, w};
  return level_achieved(spot_, w);
}

double WalkResponse::level_max_turn(const Level& level) const {
  // Either way: the smaller of the fastest usable left and right turns.
  double left = 0.0, right = 0.0;
  for (const auto& p : level.points) {
    left = std::max(left, p.commanded.turn_rad_s);
    right = std::max(right, -p.commanded.turn_rad_s);
  }
  return std::min({left, right, steering_.max_turn_rad_s});
}

double WalkResponse::max_turn(double speed) const {
  if (!(speed >= min_speed() && speed <= max_speed()) || max_speed() <= 0.0) return 0.0;
  if (!calibrated_) return steering_.max_turn_rad_s;
  for (std::size_t i = 0; i < levels_.size(); ++i) {
    if (levels_[i].speed == speed) return level_max_turn(levels_[i]);
    if (levels_[i].speed > speed) {
      return std::min(level_max_turn(levels_[i - 1]), level_max_turn(levels_[i]));
    }
  }
  return level_max_turn(levels_.back());
}

MotionCommand WalkResponse::clamp(const MotionCommand& c) const {
  const double v = c.speed_m_s;
  if (!std::isfinite(v) || v < min_speed() || max_speed() <= 0.0) return {0.0, 0.0};
  MotionCommand out;
  out.speed_m_s = std::min(v, max_speed());
  const double limit = max_turn(out.speed_m_s);
  const double w = std::isfinite(c.turn_rad_s) ? c.turn_rad_s : 0.0;
  out.turn_rad_s = std::clamp(w, -limit, limit);
  return out;
}

MotionCommand WalkResponse::level_achieved(const Level& level, double turn) const {
  const auto& pts = level.points;
  if (turn <= pts.front().commanded.turn_rad_s) return pts.front().achieved;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double w0 = pts[i - 1].commanded.turn_rad_s;
    const double w1 = pts[i].commanded.turn_rad_s;
    if (turn <= w1) return lerp(pts[i - 1].achieved, pts[i].achieved, (turn - w0) / (w1 - w0));
  }
  return pts.back().achieved;
}

MotionCommand WalkResponse::achieved(const MotionCommand& commanded) const {
  if (commanded.speed_m_s == 0.0 && commanded.turn_rad_s != 0.0 && spot_turn() > 0.0)
    return spot_achieved(commanded.turn_rad_s);
  const MotionCommand c = clamp(commanded);
  if (c.speed_m_s <= 0.0 || !calibrated_) return c;
  const double v = c.speed_m_s;
  for (std::size_t i = 0; i < levels_.size(); ++i) {
    if (levels_[i].speed < v) continue;
    if (levels_[i].speed == v || i == 0) return level_achieved(levels_[i], c.turn_rad_s);
    const Level& lo = levels_[i - 1];
    const Level& hi = levels_[i];
    return lerp(level_achieved(lo, c.turn_rad_s), level_achieved(hi, c.turn_rad_s),
                (v - lo.speed) / (hi.speed - lo.speed));
  }
  return level_achieved(levels_.back(), c.turn_rad_s);
}

MotionCommand WalkResponse::command_for(const MotionCommand& wanted) const {
  // Uncalibrated, the figure walks what it is told: the closest command is
  // the wanted one within the limits (a herd asks this for every figure at
  // every step, so skip the search).
  if (!calibrated_) {
    const MotionCommand c = clamp(wanted);
    if (c.speed_m_s > 0.0 || !(wanted.speed_m_s > 0.0)) return c;
    // Slower than the slowest walk: standing or the slowest walk, whichever is closer.
    return wanted.speed_m_s < 0.5 * min_speed() ? c : clamp({min_speed(), wanted.turn_rad_s});
  }
  // Turn error weighed as the speed of a foot at half the track.
  const double arm = 0.5 * steering_.track_width_m;
  const auto error = [&](const MotionCommand& c) {
    const MotionCommand a = achieved(c);
    const double dv = a.speed_m_s - wanted.speed_m_s;
    const double dw = (a.turn_rad_s - wanted.turn_rad_s) * arm;
    return dv * dv + dw * dw;
  };
  MotionCommand best{0.0, 0.0};
  double best_error = error(best);
  if (max_speed() <= 0.0 || !std::isfinite(wanted.speed_m_s) || !std::isfinite(wanted.turn_rad_s))
    return best;
  // The closest grid node, then a finer search around it.
  for (const auto& [c, a] : grid_) {
    const double dv = a.speed_m_s - wanted.speed_m_s;
    const double dw = (a.turn_rad_s - wanted.turn_rad_s) * arm;
    const double e = dv * dv + dw * dw;
    if (e < best_error) {
      best_error = e;
      best = c;
    }
  }
  if (best.speed_m_s <= 0.0) return best;
  const double grid_dv = (max_speed() - min_speed()) / (kGridNodes - 1);
  double v_lo = std::max(min_speed(), best.speed_m_s - grid_dv);
  double v_hi = std::min(max_speed(), best.speed_m_s + grid_dv);
  double w_span = 2.0 * steering_.max_turn_rad_s / (kGridNodes - 1);
  double w_mid = best.turn_rad_s;
  for (int pass = 0; pass < kSearchPasses; ++pass) {
    for (int i = 0; i <= kSearchSteps; ++i) {
      const double v = v_lo + (v_hi - v_lo) * i / kSearchSteps;
      const double limit = max_turn(v);
      for (int k = 0; k <= kSearchSteps; ++k) {
        const double w =
            std::clamp(w_mid - w_span + 2.0 * w_span * k / kSearchSteps, -limit, limit);
        const MotionCommand c{v, w};
        const double e = error(c);
        if (e < best_error) {
          best_error = e;
          best = clamp(c);
        }
      }
    }
    if (best.speed_m_s <= 0.0) break;
    const double dv = (v_hi - v_lo) / kSearchSteps;
    v_lo = std::max(min_speed(), best.speed_m_s - dv);
    v_hi = std::min(max_speed(), best.speed_m_s + dv);
    w_span = 2.0 * w_span / kSearchSteps;
    w_mid = best.turn_rad_s;
  }
  return best;
}

WalkResponse load_walk_response(const std::string& gait_path) {
  const GaitFile gait = load_gait_file(gait_path);
  if (!gait.steering) {
    throw InputError(
        Location{gait_path, 0, 0}, "steering",
        "gait '" + elide(gait.name) + "' has no steering section, so it cannot be steered");
  }
  const std::string cal_path = calibration_path_for(gait_path);
  std::error_code ec;
  if (std::filesystem::exists(cal_path, ec)) {
    const GaitCalibration cal = load_gait_calibration(cal_path);
    check_calibration_references(cal, cal_path, gait_path);
    WalkResponse walk(*gait.steering, &cal);
    // A table without one usable straight walk would make a figure that
    // stands: found here, not as "walks at most 0 m/s" in each scene.
    if (walk.max_speed() <= 0.0) {
      throw InputError(Location{cal_path, 0, 0}, "points",
                       "no speed whose straight walk is usable (every one fell or missed the "
                       "tolerance): calibrate the gait again (animrt gait calibrate)");
    }
    return walk;
  }
  return WalkResponse(*gait.steering);
}

}  // namespace animrt
