// Reducing a recorded curve to keys: within the bound everywhere, and far
// fewer keys than samples for smooth motion.

#include "animrt/controllers/show/key_reducer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace animrt::show {
namespace {

double linear_at(const std::vector<double>& t, const std::vector<double>& v,
                 const std::vector<std::size_t>& keys, double time) {
  for (std::size_t k = 0; k + 1 < keys.size(); ++k) {
    const double t0 = t[keys[k]], t1 = t[keys[k + 1]];
    if (time <= t1) return v[keys[k]] + (v[keys[k + 1]] - v[keys[k]]) * (time - t0) / (t1 - t0);
  }
  return v[keys.back()];
}

TEST(KeyReducer, StaysWithinTheToleranceWithFewKeys) {
  std::vector<double> t, v;
  for (int i = 0; i <= 2000; ++i) {  // 10 s at 200 Hz
    t.push_back(i * 0.005);
    v.push_back(40.0 * std::sin(t.back() * 1.3) + 10.0 * std::sin(t.back() * 4.1));
  }
  const std::vector<std::size_t> keys = reduce_keys(t, v, 0.5);
  ASSERT_GE(keys.size(), 2u);
  EXPECT_EQ(keys.front(), 0u);
  EXPECT_EQ(keys.back(), t.size() - 1);
  double worst = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    worst = std::max(worst, std::abs(v[i] - linear_at(t, v, keys, t[i])));
  }
  EXPECT_LE(worst, 0.5);
  EXPECT_GT(worst, 0.1);  // it did simplify, up to the bound
  EXPECT_LT(keys.size(), t.size() / 10);
  // A tighter bound keeps more keys.
  EXPECT_GT(reduce_keys(t, v, 0.05).size(), keys.size());
}

TEST(KeyReducer, KeepsCornersAndDropsStraightRuns) {
  std::vector<double> t, v;
  for (int i = 0; i <= 20; ++i) {
    t.push_back(i);
    v.push_back(i <= 10 ? i : 20 - i);  // up, then down: one corner at 10
  }
  EXPECT_EQ(reduce_keys(t, v, 0.0), (std::vector<std::size_t>{0, 10, 20}));
  // A step held: the edges of the step are keys.
  std::vector<double> step{0, 0, 0, 5, 5, 5};
  std::vector<double> ts{0, 1, 2, 3, 4, 5};
  EXPECT_EQ(reduce_keys(ts, step, 0.1), (std::vector<std::size_t>{0, 2, 3, 5}));
}

TEST(KeyReducer, RefusesBadInput) {
  std::vector<double> t{0, 1, 1}, v{0, 1, 2};
  EXPECT_THROW(reduce_keys(t, v, 0.5), std::invalid_argument);
  std::vector<double> t2{0, 1};
  EXPECT_THROW(reduce_keys(t2, v, 0.5), std::invalid_argument);
  std::vector<double> t3{0, 1, 2};
  EXPECT_THROW(reduce_keys(t3, v, -1.0), std::invalid_argument);
  std::vector<double> v3{0, NAN, 2};
  EXPECT_THROW(reduce_keys(t3, v3, 0.5), std::invalid_argument);
  EXPECT_EQ(reduce_keys(std::vector<double>{}, std::vector<double>{}, 0.5).size(), 0u);
}

}  // namespace
}  // namespace animrt::show
