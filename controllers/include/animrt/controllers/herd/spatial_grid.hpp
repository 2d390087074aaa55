#pragma once
// Neighbour search on the ground plane: a uniform grid of square cells,
// hashed into a fixed table so that any position (however far out) has a
// cell and memory depends only on the number of points. Points that span
// few cells (at most 8 per table bucket) are laid out as a dense array of
// cells instead, row by row, so that a query reads each row of its cells
// as one run without hashing; the results are the same either way.
//
// build() sorts the points into the table by counting sort (stable, so a
// cell lists its points in index order) and reuses its arrays: once it has
// seen n points, later builds of at most n points do not allocate.
// Queries visit the cells that overlap the query disc in row-major order and
// report each point within the radius (distance <= r) exactly once, so the
// order of the results depends only on the positions, the cell size and the
// radius.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

class SpatialGrid {
 public:
  // Space for n points (build() of at most n points will not allocate).
  void reserve(std::size_t n);

  // Sorts the points (or the agents' positions) into cells of side
  // `cell_size` (> 0; the query radius is the natural choice).
  void build(std::span<const Vec2> points, double cell_size);
  void build(std::span<const Agent> agents, double cell_size);

  std::size_t size() const { return pos_.size(); }
  double cell_size() const { return cell_; }
  Vec2 position(int i) const { return pos_[static_cast<std::size_t>(i)]; }

  // Calls f(j, d2) for every point j with |p_j - p| <= r, d2 = |p_j - p|^2.
  template <class F>
  void for_each_within(Vec2 p, double r, F&& f) const {
    visit_within(p, r, [&](int j, double d2) {
      f(j, d2);
      return false;
    });
  }

  // Whether any point lies within r of p (the query of for_each_within,
  // stopping at the first point it finds).
  bool any_within(Vec2 p, double r) const {
    return visit_within(p, r, [](int, double) { return true; });
  }

  // As for_each_within around point i's position, leaving i itself out.
  template <class F>
  void for_each_near(int i, double r, F&& f) const {
    for_each_within(pos_[static_cast<std::size_t>(i)], r, [&](int j, double d2) {
      if (j != i) f(j, d2);
    });
  }

  // The indices within r of p, in query order, into `out` (cleared first;
  // does not allocate while out.capacity() suffices). Returns out.size().
  std::size_t query(Vec2 p, double r, std::vector<int>& out) const;
  // The indices within r of point i, leaving i out.
  std::size_t query_near(int i, double r, std::vector<int>& out) const;

 private:
  struct Cell {
    std::int64_t x = 0, y = 0;
    friend bool operator==(Cell, Cell) = default;
  };
  Cell cell_of(Vec2 p) const;
  std::size_t bucket_of(Cell c) const;
  void sort_into_buckets();
  template <class SlotOf>
  void sort_by(std::size_t slots, SlotOf slot_of);
  // Calls f(j, d2) for the points within r of p, in query order, until f
  // returns true; returns whether it did.
  template <class F>
  bool visit_within(Vec2 p, double r, F&& f) const;

  double cell_ = 1.0;
  std::size_t mask_ = 0;              // table size - 1 (a power of two)
  bool dense_ = false;                // cells laid out row by row, not hashed
  std::int64_t xmin_ = 0, ymin_ = 0;  // dense: the first cell
  std::int64_t width_ = 0, height_ = 0;
  std::vector<Vec2> pos_;             // input order
  std::vector<Cell> cell_idx_;        // input order
  std::vector<std::uint32_t> start_;  // bucket or cell b: sorted_[start_[b], start_[b+1])
  std::vector<int> sorted_;           // point indices, grouped by bucket or cell
  std::vector<Cell> sorted_cell_;     // their cells (hashed layout)
  std::vector<Vec2> sorted_pos_;      // their positions
};

// Cells farther out than this are folded onto the border (positions beyond
// ~1e12 cell sizes are not ground-plane positions anyway); non-finite
// positions sit in one cell of their own and match no query.
inline constexpr std::int64_t kGridCoordLimit = std::int64_t{1} << 40;

template <class F>
bool SpatialGrid::visit_within(Vec2 p, double r, F&& f) const {
  if (pos_.empty() || !(r >= 0.0) || !std::isfinite(p.x) || !std::isfinite(p.y)) return false;
  const double r2 = r * r;
  // Widened by a hair so that rounding in p +- r never drops a border cell.
  const double w = r * (1.0 + 1e-12) + 1e-12 * (std::abs(p.x) + std::abs(p.y));
  const Cell lo = cell_of({p.x - w, p.y - w});
  const Cell hi = cell_of({p.x + w, p.y + w});
  const double span_cells =
      (static_cast<double>(hi.x - lo.x) + 1.0) * (static_cast<double>(hi.y - lo.y) + 1.0);
  if (span_cells > static_cast<double>(pos_.size())) {
    // The disc covers more cells than there are points: a scan is cheaper.
    for (std::size_t j = 0; j < pos_.size(); ++j) {
      const double d2 = norm2(pos_[j] - p);
      if (d2 <= r2 && f(static_cast<int>(j), d2)) return true;
    }
    return false;
  }
  if (dense_) {
    // The same cells in the same order: each row's cells lie side by side.
    const std::int64_t xa = std::max(lo.x, xmin_), xb = std::min(hi.x, xmin_ + width_ - 1);
    const std::int64_t ya = std::max(lo.y, ymin_), yb = std::min(hi.y, ymin_ + height_ - 1);
    if (xa > xb) return false;
    for (std::int64_t cy = ya; cy <= yb; ++cy) {
      const auto row = static_cast<std::size_t>((cy - ymin_) * width_);
      const std::uint32_t to = start_[row + static_cast<std::size_t>(xb - xmin_) + 1];
      for (std::uint32_t k = start_[row + static_cast<std::size_t>(xa - xmin_)]; k < to; ++k) {
        const double d2 = norm2(sorted_pos_[k] - p);
        if (d2 <= r2 && f(sorted_[k], d2)) return true;
      }
    }
    return false;
  }
  for (std::int64_t cy = lo.y; cy <= hi.y; ++cy) {
    for (std::int64_t cx = lo.x; cx <= hi.x; ++cx) {
      const Cell c{cx, cy};
      const std::size_t b = bucket_of(c);
      for (std::uint32_t k = start_[b]; k < start_[b + 1]; ++k) {
        if (!(sorted_cell_[k] == c)) continue;  // another cell hashed here
        const double d2 = norm2(sorted_pos_[k] - p);
        if (d2 <= r2 && f(sorted_[k], d2)) return true;
      }
    }
  }
  return false;
}

}  // namespace animrt::herd
