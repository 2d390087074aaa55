#include "animrt/controllers/herd/spatial_grid.hpp"

#include <algorithm>
#include <stdexcept>

namespace animrt::herd {

namespace {

// Table of at least 2n buckets, a power of two.
std::size_t table_size(std::size_t n) {
  std::size_t t = 16;
  while (t < 2 * n) t *= 2;
  return t;
}

std::int64_t coord(double v) {
  const double lim = static_cast<double>(kGridCoordLimit);
  return static_cast<std::int64_t>(std::floor(std::clamp(v, -lim, lim)));
}

// The most cells a dense layout of n points may have: a few times the
// hashed table, so that the table's array holds either.
std::size_t dense_cells(std::size_t n) { return 8 * table_size(n); }

}  // namespace

void SpatialGrid::reserve(std::size_t n) {
  pos_.reserve(n);
  cell_idx_.reserve(n);
  sorted_.reserve(n);
  sorted_cell_.reserve(n);
  sorted_pos_.reserve(n);
  start_.reserve(dense_cells(n) + 1);
}

SpatialGrid::Cell SpatialGrid::cell_of(Vec2 p) const {
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) return {kGridCoordLimit + 1, kGridCoordLimit + 1};
  return {coord(p.x / cell_), coord(p.y / cell_)};
}

std::size_t SpatialGrid::bucket_of(Cell c) const {
  // Two large odd multipliers mix the coordinates; the table size is a
  // power of two, so the high bits are folded down before masking.
  std::uint64_t h = static_cast<std::uint64_t>(c.x) * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(c.y) * 0xC2B2AE3D27D4EB4Full;
  h ^= h >> 29;
  return static_cast<std::size_t>(h) & mask_;
}

void SpatialGrid::build(std::span<const Vec2> points, double cell_size) {
  if (!(cell_size > 0.0) || !std::isfinite(cell_size))
    throw std::invalid_argument("SpatialGrid: cell size must be positive and finite");
  cell_ = cell_size;
  pos_.assign(points.begin(), points.end());
  sort_into_buckets();
}

void SpatialGrid::build(std::span<const Agent> agents, double cell_size) {
  if (!(cell_size > 0.0) || !std::isfinite(cell_size))
    throw std::invalid_argument("SpatialGrid: cell size must be positive and finite");
  cell_ = cell_size;
  pos_.resize(agents.size());
  for (std::size_t i = 0; i < agents.size(); ++i) pos_[i] = agents[i].position;
  sort_into_buckets();
}

void SpatialGrid::sort_into_buckets() {
  const std::size_t n = pos_.size();
  const std::size_t t = table_size(n);
  mask_ = t - 1;
  cell_idx_.resize(n);
  // Either layout fits the arrays of the other: switching allocates nothing.
  if (start_.capacity() < dense_cells(n) + 1) start_.reserve(dense_cells(n) + 1);
  if (sorted_cell_.capacity() < n) sorted_cell_.reserve(n);
  for (std::size_t i = 0; i < n; ++i) cell_idx_[i] = cell_of(pos_[i]);
  dense_ = false;
  if (n > 0) {
    Cell lo = cell_idx_[0], hi = lo;
    for (const Cell& c : cell_idx_) {
      lo = {std::min(lo.x, c.x), std::min(lo.y, c.y)};
      hi = {std::max(hi.x, c.x), std::max(hi.y, c.y)};
    }
    // Differences of coordinates within +-(kGridCoordLimit + 1) fit in 64 bits.
    const double cells =
        (static_cast<double>(hi.x - lo.x) + 1.0) * (static_cast<double>(hi.y - lo.y) + 1.0);
    dense_ = cells <= static_cast<double>(dense_cells(n));
    if (dense_) {
      xmin_ = lo.x;
      ymin_ = lo.y;
      width_ = hi.x - lo.x + 1;
      height_ = hi.y - lo.y + 1;
    }
  }
  if (dense_) {
    sort_by(static_cast<std::size_t>(width_ * height_), [&](Cell c) {
      return static_cast<std::size_t>((c.y - ymin_) * width_ + (c.x - xmin_));
    });
  } else {
    sort_by(t, [&](Cell c) { return bucket_of(c); });
  }
}

// A stable counting sort of the points into `slots` slots (the dense
// layout's cells, or the hashed layout's buckets, which also keep each
// point's cell, since several cells share a bucket): a slot lists its
// points in index order.
template <class SlotOf>
void SpatialGrid::sort_by(std::size_t slots, SlotOf slot_of) {
  const std::size_t n = pos_.size();
  start_.assign(slots + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++start_[slot_of(cell_idx_[i]) + 1];
  for (std::size_t b = 0; b < slots; ++b) start_[b + 1] += start_[b];
  sorted_.resize(n);
  sorted_pos_.resize(n);
  if (!dense_) sorted_cell_.resize(n);
  // start_[b] walks forward while slot b fills, ending where slot b+1
  // began, so it is shifted back afterwards.
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = start_[slot_of(cell_idx_[i])]++;
    sorted_[k] = static_cast<int>(i);
    sorted_pos_[k] = pos_[i];
    if (!dense_) sorted_cell_[k] = cell_idx_[i];
  }
  for (std::size_t b = slots; b > 0; --b) start_[b] = start_[b - 1];
  start_[0] = 0;
}

std::size_t SpatialGrid::query(Vec2 p, double r, std::vector<int>& out) const {
  out.clear();
  for_each_within(p, r, [&](int j, double) { out.push_back(j); });
  return out.size();
}

std::size_t SpatialGrid::query_near(int i, double r, std::vector<int>& out) const {
  out.clear();
  for_each_near(i, r, [&](int j, double) { out.push_back(j); });
  return out.size();
}

}  // namespace animrt::herd
