#include "animrt/controllers/gait/froude.hpp"

#include <gtest/gtest.h>

namespace animrt {
namespace {

// Hand-computed: v = Fr sqrt(g h), lambda = 2.3 h Fr^0.6, f = v / lambda.

TEST(Froude, UnitHipAtFroudeOne) {
  // sqrt(9.81) = 3.1320919527; lambda = 2.3 h exactly; 3.1320919527 / 2.3.
  EXPECT_NEAR(froude_velocity(1.0, 1.0), 3.1320919526732, 1e-12);
  EXPECT_NEAR(froude_stride_length(1.0, 1.0), 2.3, 1e-12);
  EXPECT_NEAR(froude_stride_frequency(1.0, 1.0), 1.3617791098579, 1e-12);
}

TEST(Froude, SmallQuadrupedWalk) {
  // h = 0.18 m, Fr = 0.25: sqrt(9.81 * 0.18) = sqrt(1.7658) = 1.3288340754;
  // v = 0.3322085189; 0.25^0.6 = 0.4352752816, lambda = 0.414 * that =
  // 0.1802039666; f = 1.8435139088.
  EXPECT_NEAR(froude_velocity(0.25, 0.18), 0.33220851886, 1e-10);
  EXPECT_NEAR(froude_stride_length(0.25, 0.18), 0.18020396660, 1e-10);
  EXPECT_NEAR(froude_stride_frequency(0.25, 0.18), 1.84351390882, 1e-10);
}

TEST(Froude, OtherGravity) {
  // g = 1.62 (the Moon), h = 0.18: sqrt(0.2916) = 0.54, v = 0.135 exactly.
  // The stride length depends on Fr and h only; f = 0.135 / 0.1802039666.
  EXPECT_NEAR(froude_velocity(0.25, 0.18, 1.62), 0.135, 1e-12);
  EXPECT_NEAR(froude_stride_length(0.25, 0.18, 1.62), 0.18020396660, 1e-10);
  EXPECT_NEAR(froude_stride_frequency(0.25, 0.18, 1.62), 0.74915110109, 1e-10);
}

TEST(Froude, DynamicSimilarity) {
  // Same Fr, legs 4x longer: speed and stride scale by 2 and 4, frequency by 1/2.
  EXPECT_NEAR(froude_velocity(0.5, 1.2) / froude_velocity(0.5, 0.3), 2.0, 1e-12);
  EXPECT_NEAR(froude_stride_length(0.5, 1.2) / froude_stride_length(0.5, 0.3), 4.0, 1e-12);
  EXPECT_NEAR(froude_stride_frequency(0.5, 1.2) / froude_stride_frequency(0.5, 0.3), 0.5, 1e-12);
}

}  // namespace
}  // namespace animrt
