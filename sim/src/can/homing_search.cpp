#include "animrt/sim/can/homing_search.hpp"

#include <cmath>

namespace animrt::sim {
namespace {

// A search with no switch on its way gives up after this many counts (a
// real axis would meet its hard stop long before).
constexpr double kMaxTravel = 1e9;
enum Event : int { kNone, kTarget, kNegativeLimit, kPositiveLimit, kTravel };

}  // namespace

HomingSearch::HomingSearch(int method, const Switches& switches, double start, double switch_speed,
                           double zero_speed, Nanos now)
    : sw_(switches),
      switch_speed_(switch_speed),
      zero_speed_(zero_speed),
      position_(start),
      time_(now) {
  const bool on_home = start >= sw_.home_from && start <= sw_.home_to;
  switch (method) {
    case 17:
      target_ = sw_.negative_limit;
      direction_ = start <= target_ ? 1 : -1;
      return;
    case 18:
      target_ = sw_.positive_limit;
      direction_ = start >= target_ ? -1 : 1;
      return;
    case 19:
    case 20:
      target_ = sw_.home_from;
      direction_ = on_home ? -1 : 1;
      return;
    case 21:
    case 22:
      target_ = sw_.home_to;
      direction_ = on_home ? 1 : -1;
      return;
    default:
      break;
  }
  // 23-30: the lower edge for 23, 24, 29, 30; the upper for 25-28.
  const bool lower = method <= 24 || method >= 29;
  target_ = lower ? sw_.home_from : sw_.home_to;
  turn_at_ = method <= 26 ? 1 : -1;
  direction_ = on_home ? (lower ? -1 : 1) : turn_at_;
}

double HomingSearch::next_event(double travel, int& kind) const {
  kind = kNone;
  double best = travel;
  const auto consider = [&](double distance, int what) {
    if (distance >= 0.0 && distance <= best && (kind == kNone || distance < best)) {
      best = distance;
      kind = what;
    }
  };
  // The home edge first: at equal distance it wins (17 / 18 home on a limit).
  consider(direction_ * (target_ - position_), kTarget);
  if (direction_ > 0) {
    consider(std::max(0.0, sw_.positive_limit - position_), kPositiveLimit);
  } else {
    consider(std::max(0.0, position_ - sw_.negative_limit), kNegativeLimit);
  }
  consider(kMaxTravel - travelled_, kTravel);
  return best;
}

void HomingSearch::advance(Nanos now) {
  while (phase_ == Phase::searching && now > time_) {
    const double speed = turned_ ? zero_speed_ : switch_speed_;
    if (!(speed > 0.0)) {
      phase_ = Phase::error;  // a drive asked to search at no speed
      return;
    }
    int kind = kNone;
    const double travel = speed * to_seconds(now - time_);
    const double d = next_event(travel, kind);
    position_ += direction_ * d;
    travelled_ += d;
    if (kind == kNone) {
      time_ = now;
      return;
    }
    time_ += static_cast<Nanos>(d / speed * 1e9);
    if (kind == kTarget) {
      position_ = target_;
      phase_ = Phase::attained;
    } else if (kind != kTravel && !turned_ && turn_at_ == direction_) {
      direction_ = -direction_;
      turned_ = true;
    } else {
      phase_ = Phase::error;  // a limit it does not use, or the far end
    }
  }
}

}  // namespace animrt::sim
