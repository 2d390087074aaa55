#pragma once
// The items of a Detour proximity grid (the crowd's, rebuilt at each crowd
// update) laid out by rows: the grid answers a box query by hashing each
// cell of the box and walking its bucket, which for a wide box cost more
// than the crowd update itself. Here each item's cell span is computed as
// the grid computes it (float arithmetic, floor of coordinate times the
// inverse cell size), and items are sorted by the row and column of their
// first cell, so a query reads one run of items per row. A query returns
// the same items as the grid's, its cap included.

#include <cstdint>
#include <vector>

namespace animrt::herd {

class CellIndex {
 public:
  // Starts afresh with the grid's cell size.
  void begin(float cell_size);
  // As dtProximityGrid::addItem.
  void add(int id, float minx, float miny, float maxx, float maxy);
  // Sorts the items added since begin(); queries read them after.
  void finish();
  // The ids dtProximityGrid::queryItems returns for the box with room for
  // `cap`, into `out` (in no particular order); false (and `out`
  // unspecified) when the index cannot answer exactly (cell numbers beyond
  // what the grid stores). Ids must have been added in increasing order.
  bool query(float minx, float miny, float maxx, float maxy, std::size_t cap,
             std::vector<int>& out) const;

 private:
  struct Item {
    int id;
    int x0, y0, x1, y1;  // cell span, inclusive
  };
  int cell(float v) const;
  void keep_first(int qx0, int qy0, std::size_t cap, std::vector<int>& out) const;

  float inv_cell_ = 1.0f;
  bool exact_ = true;
  std::vector<Item> items_, sorted_;
  int xmin_ = 0, ymin_ = 0, width_ = 0, height_ = 0;
  int span_x_ = 0, span_y_ = 0;       // widest item, in cells beyond its first
  std::vector<std::uint32_t> start_;  // per cell (row-major): first sorted item
  std::vector<int> slot_;             // per id: its item
  mutable std::vector<std::uint64_t> order_;
};

}  // namespace animrt::herd
