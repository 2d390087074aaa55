#include "animrt/controllers/herd/cell_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace animrt::herd {
namespace {

// The grid stores cell numbers as short: beyond that it wraps them.
constexpr int kCellLimit = std::numeric_limits<short>::max();
// Larger boards than this many cells per item fall back to the grid.
constexpr std::size_t kCellsPerItem = 64;

}  // namespace

void CellIndex::begin(float cell_size) {
  inv_cell_ = 1.0f / cell_size;
  exact_ = true;
  items_.clear();
}

int CellIndex::cell(float v) const { return static_cast<int>(std::floor(v * inv_cell_)); }

void CellIndex::add(int id, float minx, float miny, float maxx, float maxy) {
  const Item it{id, cell(minx), cell(miny), cell(maxx), cell(maxy)};
  for (const int c : {it.x0, it.y0, it.x1, it.y1}) {
    if (c < -kCellLimit || c > kCellLimit) exact_ = false;
  }
  if (static_cast<std::size_t>(id) >= slot_.size()) slot_.resize(static_cast<std::size_t>(id) + 1);
  slot_[static_cast<std::size_t>(id)] = static_cast<int>(items_.size());
  items_.push_back(it);
}

void CellIndex::finish() {
  width_ = height_ = 0;
  sorted_.clear();
  if (items_.empty() || !exact_) return;
  int xmax = items_[0].x0, ymax = items_[0].y0;
  xmin_ = xmax;
  ymin_ = ymax;
  span_x_ = span_y_ = 0;
  for (const Item& it : items_) {
    xmin_ = std::min(xmin_, it.x0);
    ymin_ = std::min(ymin_, it.y0);
    xmax = std::max(xmax, it.x0);
    ymax = std::max(ymax, it.y0);
    span_x_ = std::max(span_x_, it.x1 - it.x0);
    span_y_ = std::max(span_y_, it.y1 - it.y0);
  }
  width_ = xmax - xmin_ + 1;
  height_ = ymax - ymin_ + 1;
  const auto cells = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  if (cells > kCellsPerItem * items_.size() + 4096) {
    exact_ = false;
    return;
  }
  // Counting sort by first cell; ids stay in insertion order within a cell.
  start_.assign(cells + 1, 0);
  const auto at = [&](const Item& it) {
    return static_cast<std::size_t>(it.y0 - ymin_) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(it.x0 - xmin_);
  };
  for (const Item& it : items_) ++start_[at(it) + 1];
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  sorted_.resize(items_.size());
  std::vector<std::uint32_t>& fill = start_;  // shifted back below
  for (const Item& it : items_) sorted_[fill[at(it)]++] = it;
  for (std::size_t c = cells; c > 0; --c) start_[c] = start_[c - 1];
  start_[0] = 0;
}

bool CellIndex::query(float minx, float miny, float maxx, float maxy, std::size_t cap,
                      std::vector<int>& out) const {
  out.clear();
  if (!exact_) return false;
  if (sorted_.empty()) return true;
  const int qx0 = cell(minx), qy0 = cell(miny), qx1 = cell(maxx), qy1 = cell(maxy);
  // An item meets the box when its span does: its first cell lies up to
  // its width before the box.
  const int xa = std::max(qx0 - span_x_, xmin_), xb = std::min(qx1, xmin_ + width_ - 1);
  const int ya = std::max(qy0 - span_y_, ymin_), yb = std::min(qy1, ymin_ + height_ - 1);
  if (xa > xb) return true;
  for (int y = ya; y <= yb; ++y) {
    const std::size_t row = static_cast<std::size_t>(y - ymin_) * static_cast<std::size_t>(width_);
    const std::uint32_t from = start_[row + static_cast<std::size_t>(xa - xmin_)];
    const std::uint32_t to = start_[row + static_cast<std::size_t>(xb - xmin_) + 1];
    for (std::uint32_t k = from; k < to; ++k) {
      const Item& it = sorted_[k];
      if (it.x1 >= qx0 && it.y1 >= qy0) out.push_back(it.id);
    }
  }
  if (out.size() > cap) keep_first(qx0, qy0, cap, out);
  return true;
}

void CellIndex::keep_first(int qx0, int qy0, std::size_t cap, std::vector<int>& out) const {
  // The grid reads the box's cells row by row and each cell's items newest
  // first, and stops at the cap: an item counts at its first cell in the
  // box, and within a cell the later id comes first.
  order_.clear();
  for (const int id : out) {
    const Item& it = items_[static_cast<std::size_t>(slot_[static_cast<std::size_t>(id)])];
    const auto ey = static_cast<std::uint64_t>(std::max(it.y0, qy0) - ymin_ + 1);
    const auto ex = static_cast<std::uint64_t>(std::max(it.x0, qx0) - xmin_ + 1);
    order_.push_back(ey << 42 | ex << 21 | (0x1FFFFF - static_cast<std::uint64_t>(id)));
  }
  std::nth_element(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(cap), order_.end());
  out.resize(cap);
  for (std::size_t k = 0; k < cap; ++k) out[k] = 0x1FFFFF - static_cast<int>(order_[k] & 0x1FFFFF);
}

}  // namespace animrt::herd
