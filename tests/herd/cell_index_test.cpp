// The row index of the crowd's proximity grid against the grid itself:
// the same items for every box, the grid's cap (and which items it keeps
// under it) included.

#include "animrt/controllers/herd/cell_index.hpp"

#include <DetourProximityGrid.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

namespace animrt::herd {
namespace {

struct Boxes {
  std::vector<std::array<float, 4>> items;
};

// n items of half-size r: dense in a 6 m square (so caps are reached),
// sparse over a 40 m one, some on cell borders.
Boxes random_items(int n, float r, float cell, std::mt19937_64& rng) {
  std::uniform_real_distribution<float> dense(-3.0f, 3.0f), sparse(-20.0f, 20.0f);
  std::uniform_int_distribution<int> kind(0, 3), border(-10, 10);
  Boxes b;
  for (int i = 0; i < n; ++i) {
    const int k = kind(rng);
    float x = k == 0 ? sparse(rng) : dense(rng), y = k == 0 ? sparse(rng) : dense(rng);
    if (k == 3) x = static_cast<float>(border(rng)) * cell + r;
    b.items.push_back({x - r, y - r, x + r, y + r});
  }
  return b;
}

std::vector<int> sorted(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  return v;
}

TEST(CellIndex, ReturnsWhatTheProximityGridReturnsCapIncluded) {
  std::mt19937_64 rng(7);
  const float cell = 1.05f, r = 0.35f;
  int capped = 0;
  for (int round = 0; round < 20; ++round) {
    const Boxes b = random_items(300, r, cell, rng);
    dtProximityGrid grid;
    ASSERT_TRUE(grid.init(4 * 300, cell));
    CellIndex index;
    index.begin(cell);
    for (std::size_t i = 0; i < b.items.size(); ++i) {
      const auto& it = b.items[i];
      grid.addItem(static_cast<unsigned short>(i), it[0], it[1], it[2], it[3]);
      index.add(static_cast<int>(i), it[0], it[1], it[2], it[3]);
    }
    index.finish();
    std::uniform_real_distribution<float> at(-8.0f, 8.0f), half(0.2f, 4.0f);
    for (int q = 0; q < 200; ++q) {
      const float x = at(rng), y = at(rng), h = half(rng);
      for (const int cap : {8, 32, 64}) {
        std::array<unsigned short, 64> ids{};
        const int n = grid.queryItems(x - h, y - h, x + h, y + h, ids.data(), cap);
        if (n == cap) ++capped;
        std::vector<int> got;
        ASSERT_TRUE(index.query(x - h, y - h, x + h, y + h, static_cast<std::size_t>(cap), got));
        EXPECT_EQ(sorted(got), sorted(std::vector<int>(ids.begin(), ids.begin() + n)))
            << "box at " << x << ", " << y << " half " << h << " cap " << cap;
      }
    }
  }
  EXPECT_GT(capped, 100);  // the cap was put to the test
}

TEST(CellIndex, DeclinesCellsBeyondWhatTheGridStores) {
  CellIndex index;
  index.begin(1.0f);
  index.add(0, 40000.0f, 0.0f, 40000.5f, 0.5f);
  index.finish();
  std::vector<int> got;
  EXPECT_FALSE(index.query(0.0f, 0.0f, 1.0f, 1.0f, 64, got));
}

}  // namespace
}  // namespace animrt::herd
