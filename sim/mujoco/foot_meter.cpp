// The feet of a walk as the gait fitness counts them (see foot_meter.hpp).

#include "animrt/sim/mujoco/foot_meter.hpp"

#include <algorithm>
#include <cmath>

namespace animrt::sim {
namespace {

// A landing counts only after the foot was in the air for this fraction of
// a stride: a real swing. Contacts chatter when a foot lands, and a foot
// that bounces or stumbles touches down again within a tenth of a stride;
// counting those as strides made the stride length a fraction of what the
// walk covers per cycle (measured against speed / frequency in docs/evolve.md).
constexpr double kMinSwingStrides = 0.15;

}  // namespace

FootMeter::FootMeter(const MujocoModel& model, double timestep_s, double stride_frequency_hz)
    : geoms_(model.foot_geoms),
      foot_of_(static_cast<std::size_t>(model.model->ngeom), -1),
      feet_(model.foot_geoms.size()),
      contact_(model.foot_geoms.size(), 0),
      frequency_hz_(stride_frequency_hz),
      min_swing_steps_(
          std::max(1L, std::lround(kMinSwingStrides / stride_frequency_hz / timestep_s))) {
  for (std::size_t i = 0; i < geoms_.size(); ++i) {
    foot_of_[static_cast<std::size_t>(geoms_[i])] = static_cast<int>(i);
  }
}

void FootMeter::step(const mjData* d, double t_s) {
  ++steps_;
  std::fill(contact_.begin(), contact_.end(), 0);
  for (int c = 0; c < d->ncon; ++c) {
    for (int g : {d->contact[c].geom1, d->contact[c].geom2}) {
      const int foot = foot_of_[static_cast<std::size_t>(g)];
      if (foot >= 0) contact_[static_cast<std::size_t>(foot)] = 1;
    }
  }
  for (std::size_t i = 0; i < feet_.size(); ++i) {
    Foot& f = feet_[i];
    if (!contact_[i]) {
      ++f.air_steps;
      continue;
    }
    // A foot already down when measuring starts has not landed: only a foot
    // that was in the air counts.
    if (f.air_steps >= min_swing_steps_) {
      const double x = d->geom_xpos[3 * geoms_[i]];
      if (f.landings++ == 0) {
        f.first_t = t_s;
        f.first_x = x;
      }
      f.last_t = t_s;
      f.last_x = x;
    }
    f.air_steps = 0;
    ++f.contact_steps;
  }
}

double FootMeter::duty_factor() const {
  if (steps_ == 0 || feet_.empty()) return 0.0;
  double contact = 0.0;
  for (const Foot& f : feet_) contact += static_cast<double>(f.contact_steps);
  return contact / (static_cast<double>(feet_.size()) * static_cast<double>(steps_));
}

// A foot that bounces or stumbles lands more than once a stride; counting
// each landing as a stride would shorten it.
double FootMeter::stride_length_m() const {
  double advance = 0.0, strides = 0.0;
  for (const Foot& f : feet_) {
    if (f.landings < 2) continue;
    const double periods = std::round((f.last_t - f.first_t) * frequency_hz_);
    if (periods < 1) continue;
    advance += f.last_x - f.first_x;
    strides += periods;
  }
  return strides > 0 ? advance / strides : 0.0;
}

}  // namespace animrt::sim
