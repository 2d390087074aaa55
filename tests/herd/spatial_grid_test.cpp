// The grid's neighbour search (and its any-point test) against a scan of
// all pairs.

#include "animrt/controllers/herd/spatial_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "support/alloc_counter.hpp"

namespace animrt::herd {
namespace {

std::vector<int> brute(const std::vector<Vec2>& pts, Vec2 p, double r, int skip = -1) {
  std::vector<int> out;
  for (std::size_t j = 0; j < pts.size(); ++j)
    if (static_cast<int>(j) != skip && norm2(pts[j] - p) <= r * r)
      out.push_back(static_cast<int>(j));
  return out;
}

// Random points in a 20 m square, some snapped to cell borders, some far out
// of it, some repeated.
std::vector<Vec2> points(int n, double cell, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Vec2> pts;
  for (int i = 0; i < n; ++i) {
    Vec2 p{u(rng), u(rng)};
    switch (i % 7) {
      case 1:
        p.x = std::round(p.x / cell) * cell;
        break;
      case 2:
        p = {std::round(p.x / cell) * cell, std::round(p.y / cell) * cell};
        break;
      case 3:
        p = p * 1e5;
        break;
      case 4:
        if (!pts.empty()) p = pts.back();
        break;
      default:
        break;
    }
    pts.push_back(p);
  }
  return pts;
}

TEST(SpatialGrid, QueriesEqualAllPairsOnRandomSets) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-12.0, 12.0);
  for (const int n : {0, 1, 2, 17, 300, 1500}) {
    for (const double r : {0.1, 0.5, 1.0, 3.0}) {
      for (const double cell_scale : {1.0, 0.4, 2.5}) {  // cell = r, smaller, larger
        const std::vector<Vec2> pts = points(n, r * cell_scale, rng);
        SpatialGrid g;
        g.build(pts, r * cell_scale);
        std::vector<int> got;
        for (int q = 0; q < 40; ++q) {
          Vec2 p{u(rng), u(rng)};
          if (q % 5 == 0 && n > 0) p = pts[static_cast<std::size_t>(q) % pts.size()];
          if (q % 5 == 1) p = {std::round(p.x / r) * r, std::round(p.y / r) * r};
          g.query(p, r, got);
          std::sort(got.begin(), got.end());
          ASSERT_EQ(got, brute(pts, p, r)) << "n " << n << " r " << r << " cell " << r * cell_scale;
          ASSERT_EQ(g.any_within(p, r), !got.empty()) << "n " << n << " r " << r;
        }
        for (int i = 0; i < n; i += std::max(1, n / 50)) {
          g.query_near(i, r, got);
          std::sort(got.begin(), got.end());
          ASSERT_EQ(got, brute(pts, pts[static_cast<std::size_t>(i)], r, i)) << "point " << i;
        }
      }
    }
  }
}

TEST(SpatialGrid, DenseAndHashedLayoutsAnswerInTheSameOrder) {
  // Points in a 24 m square span few cells: a dense layout. One point far
  // out spans too many for it: the hashed table. Queries near the square
  // never reach the far point, so both must answer alike, order included.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-12.0, 12.0);
  for (const double r : {0.3, 1.0, 2.5}) {
    for (const double cell_scale : {1.0, 0.5, 2.0}) {
      std::vector<Vec2> pts;
      for (int i = 0; i < 600; ++i) {
        Vec2 p{u(rng), u(rng)};
        if (i % 5 == 1) p = {std::round(p.x / r) * r, std::round(p.y / r) * r};
        if (i % 5 == 2 && !pts.empty()) p = pts.back();
        pts.push_back(p);
      }
      std::vector<Vec2> with_far = pts;
      with_far.push_back({3e7, -4e7});
      SpatialGrid dense, hashed;
      dense.build(pts, r * cell_scale);
      hashed.build(with_far, r * cell_scale);
      std::vector<int> a, b;
      for (int q = 0; q < 200; ++q) {
        const Vec2 p = q % 2 == 0 ? pts[static_cast<std::size_t>(q)] : Vec2{u(rng), u(rng)};
        dense.query(p, r, a);
        hashed.query(p, r, b);
        ASSERT_EQ(a, b) << "r " << r << " cell " << r * cell_scale;
        std::sort(b.begin(), b.end());
        ASSERT_EQ(b, brute(pts, p, r));
        dense.query_near(q, r, a);
        hashed.query_near(q, r, b);
        ASSERT_EQ(a, b);
      }
    }
  }
}

TEST(SpatialGrid, PointsOnTheQueryCircleAndCellBordersAreFound) {
  // Exactly r away along the axes, across cell borders (cell = r).
  const std::vector<Vec2> pts{{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}, {2, 0}, {1.0000001, 0}};
  SpatialGrid g;
  g.build(pts, 1.0);
  std::vector<int> got;
  g.query_near(0, 1.0, got);
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, (std::vector<int>{1, 2, 3, 4}));
}

TEST(SpatialGrid, FarAndNonFinitePositionsAreHandled) {
  const std::vector<Vec2> pts{{1e300, 0}, {1e300, 0}, {-1e15, 3}, {NAN, 0}, {0, 0}};
  SpatialGrid g;
  g.build(pts, 0.5);
  std::vector<int> got;
  g.query_near(0, 1.0, got);
  EXPECT_EQ(got, (std::vector<int>{1}));
  g.query({-1e15, 3.2}, 0.5, got);
  EXPECT_EQ(got, (std::vector<int>{2}));
  g.query({0, 0}, 10.0, got);
  EXPECT_EQ(got, (std::vector<int>{4}));
}

TEST(SpatialGrid, OrderIsTheSameForTheSamePoints) {
  std::mt19937_64 rng(3);
  const std::vector<Vec2> pts = points(500, 1.0, rng);
  SpatialGrid a, b;
  a.build(pts, 1.0);
  b.build(std::vector<Vec2>(400, Vec2{5, 5}), 0.3);  // a different earlier build
  b.build(pts, 1.0);
  std::vector<int> qa, qb;
  for (int i = 0; i < 500; i += 7) {
    a.query_near(i, 1.0, qa);
    b.query_near(i, 1.0, qb);
    ASSERT_EQ(qa, qb);
  }
}

TEST(SpatialGrid, RebuildingDoesNotAllocate) {
  std::mt19937_64 rng(5);
  SpatialGrid g;
  g.reserve(1000);
  std::vector<int> out;
  out.reserve(1000);
  std::vector<std::vector<Vec2>> sets;
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (int k = 0; k < 5; ++k) {
    sets.push_back(points(1000 - k * 100, 0.7, rng));  // far points: hashed
    std::vector<Vec2> near;                            // a 20 m square: dense
    for (int i = 0; i < 1000 - k * 150; ++i) near.push_back({u(rng), u(rng)});
    sets.push_back(near);
  }
  animrt::test::AllocationCounter c;
  for (const auto& s : sets) {
    g.build(s, 0.7);
    g.query_near(3, 0.7, out);
  }
  EXPECT_EQ(c.count(), 0);
}

TEST(SpatialGrid, RejectsABadCellSize) {
  SpatialGrid g;
  const std::vector<Vec2> pts{{0, 0}};
  EXPECT_THROW(g.build(pts, 0.0), std::invalid_argument);
  EXPECT_THROW(g.build(pts, -1.0), std::invalid_argument);
  EXPECT_THROW(g.build(pts, INFINITY), std::invalid_argument);
}

}  // namespace
}  // namespace animrt::herd
