// Narrow passages in a row are taken in turns as one (passage.hpp,
// PassageChain): which passages chain, and in which way.

#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "animrt/controllers/herd/passage.hpp"

namespace animrt::herd::passage_chain_test {
namespace {

std::optional<double> straight(Vec2 a, Vec2 b) { return norm(b - a); }

Box wall(double x, double y, double w, double h) {
  Box b;
  b.center = {x, y};
  b.size = {w, h};
  return b;
}

// The chain holding passage k.
const PassageChain& chain_of(const std::vector<PassageChain>& chains, int k) {
  for (const PassageChain& c : chains) {
    for (const int m : c.members) {
      if (m == k) return c;
    }
  }
  ADD_FAILURE() << "passage " << k << " in no chain";
  return chains.front();
}

// configs/herd/corridor.yaml's walls: a corridor 1.2 m wide along y = 2..3.2
// from x = 6 to 16, turning up along x = 16..17.2 to y = 14.
std::vector<Box> corridor() {
  return {wall(13, 1, 14, 2), wall(11, 8.6, 10, 10.8), wall(18.6, 8, 2.8, 12), wall(3, 13, 6, 14),
          wall(10, 17, 8, 6)};
}

TEST(PassageChain, ACorridorThatTurnsIsOneChainWalkedRoundTheCorner) {
  const std::vector<Passage> ps = find_passages(corridor(), 2.3);
  ASSERT_EQ(ps.size(), 2u);
  const auto chains = find_chains(ps, 6.0, straight);
  ASSERT_EQ(chains.size(), 1u);
  const PassageChain& c = chains[0];
  ASSERT_EQ(c.members.size(), 2u);
  // Whichever way the chain runs, a figure walking it goes east along the
  // first arm and then north along the second, or west and then south.
  Vec2 way[2];
  for (std::size_t m = 0; m < 2; ++m) {
    const Passage& p = ps[static_cast<std::size_t>(c.members[m])];
    way[m] = p.axis * c.orient[m];
  }
  const bool east_then_north = way[0].x > 0.9 && way[1].y > 0.9;
  const bool north_then_east = way[0].y > 0.9 && way[1].x > 0.9;
  const bool south_then_west = way[0].y < -0.9 && way[1].x < -0.9;
  const bool west_then_south = way[0].x < -0.9 && way[1].y < -0.9;
  EXPECT_TRUE(east_then_north || south_then_west || north_then_east || west_then_south)
      << way[0].x << "," << way[0].y << " then " << way[1].x << "," << way[1].y;
  if (east_then_north || west_then_south) {
    EXPECT_GT(std::abs(ps[static_cast<std::size_t>(c.members[0])].axis.x), 0.9);  // the first arm
  }
  // Farther apart than the link, the arms are two chains of one.
  EXPECT_EQ(find_chains(ps, 0.5, straight).size(), 2u);
  // And without a path between the mouths, too.
  EXPECT_EQ(
      find_chains(ps, 6.0, [](Vec2, Vec2) -> std::optional<double> { return std::nullopt; }).size(),
      2u);
}

// Three baffles 4 m apart, their 1.2 m gaps at the top and the bottom in
// turn (configs/herd/baffles.yaml): one chain of three, in order; 8 m
// apart, three chains of one.
TEST(PassageChain, GapsInARowChainInOrder) {
  const auto baffles = [](double spacing) {
    const double l = 4 * spacing + 1;
    return std::vector<Box>{wall(l / 2, 4.25, l + 1, 0.5), wall(l / 2, -0.25, l + 1, 0.5),
                            wall(spacing, 1.15, 0.5, 3.3), wall(2 * spacing, 2.85, 0.5, 3.3),
                            wall(3 * spacing, 1.15, 0.5, 3.3)};
  };
  const std::vector<Passage> near = find_passages(baffles(4.0), 2.3);
  ASSERT_EQ(near.size(), 3u);
  const auto chains = find_chains(near, 6.0, straight);
  ASSERT_EQ(chains.size(), 1u);
  ASSERT_EQ(chains[0].members.size(), 3u);
  std::vector<double> xs;
  for (std::size_t m = 0; m < 3; ++m) {
    const Passage& p = near[static_cast<std::size_t>(chains[0].members[m])];
    xs.push_back(p.centre.x);
    // All one way: every gap walked east, or every gap walked west.
    EXPECT_EQ(
        (p.axis * chains[0].orient[m]).x > 0,
        (near[static_cast<std::size_t>(chains[0].members[0])].axis * chains[0].orient[0]).x > 0);
  }
  EXPECT_TRUE((xs[0] < xs[1] && xs[1] < xs[2]) || (xs[0] > xs[1] && xs[1] > xs[2]));
  const std::vector<Passage> far = find_passages(baffles(8.0), 2.3);
  ASSERT_EQ(far.size(), 3u);
  EXPECT_EQ(find_chains(far, 6.0, straight).size(), 3u);
}

// Two gaps side by side in one wall face the same way: a figure out of
// one does not walk into the other, and each keeps its own turns (a team
// may own each, as in configs/herd/crossing_own_gaps.yaml).
TEST(PassageChain, GapsSideBySideInOneWallDoNotChain) {
  const std::vector<Box> walls = {wall(0, -5, 0.5, 6), wall(0, 0, 0.5, 2.8), wall(0, 5, 0.5, 6)};
  const std::vector<Passage> ps = find_passages(walls, 2.3);
  ASSERT_EQ(ps.size(), 2u);
  EXPECT_EQ(find_chains(ps, 6.0, straight).size(), 2u);
}

// Three corridors meeting at a junction: the mouths at the junction face
// more than one other, so none links, and each corridor keeps its own turns.
TEST(PassageChain, AJunctionLinksNone) {
  // Corridors 1.2 m wide along x (west, east) and y (north) meeting at a
  // square 1.2 m across round the origin.
  const std::vector<Box> walls = {
      wall(-4.1, 1.6, 7, 2),   // north of the west corridor
      wall(-4.1, -1.6, 7, 2),  // south of the west corridor
      wall(4.1, 1.6, 7, 2),    // north of the east corridor
      wall(4.1, -1.6, 7, 2),   // south of the east corridor
      wall(0, -5, 1.2, 6.8),   // south of the junction: a wall across its foot
      wall(-1.6, 4.1, 2, 7),   // west of the north corridor
      wall(1.6, 4.1, 2, 7),    // east of the north corridor
  };
  const std::vector<Passage> ps = find_passages(walls, 2.3);
  ASSERT_GE(ps.size(), 3u);
  const auto chains = find_chains(ps, 6.0, straight);
  for (const PassageChain& c : chains) EXPECT_EQ(c.members.size(), 1u);
  EXPECT_EQ(chain_of(chains, 0).orient[0], 1);
}

}  // namespace
}  // namespace animrt::herd::passage_chain_test
