// Statistics over replicate seeds (lab/replicates.hpp) against numbers computed by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "lab/replicates.hpp"

using grainlab::lab::formatReplicates;
using grainlab::lab::replicateStats;

TEST(Replicates, MeanAndSampleStandardDeviationByHand) {
  // 46, 47, 48, 49, 50: mean 48, squared deviations 4+1+0+1+4 = 10, sample variance 10/4.
  const auto s = replicateStats({46.0, 47.0, 48.0, 49.0, 50.0});
  EXPECT_EQ(s.n, 5u);
  EXPECT_DOUBLE_EQ(s.mean, 48.0);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(2.5));
  EXPECT_DOUBLE_EQ(s.min, 46.0);
  EXPECT_DOUBLE_EQ(s.max, 50.0);
  EXPECT_EQ(formatReplicates(s, 1), "48.0 ± 1.6");
}

TEST(Replicates, ANullIsLeftOutAndCountedNeverTakenAsZero) {
  const auto s = replicateStats({40.0, std::nullopt, 44.0, 42.0});
  EXPECT_EQ(s.n, 3u);
  EXPECT_EQ(s.total, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 42.0);  // a 0 for the null would give 31.5
  EXPECT_DOUBLE_EQ(s.std, 2.0);
  EXPECT_EQ(formatReplicates(s, 1), "42.0 ± 2.0 (3 of 4)");
  const auto nan = replicateStats({1.0, std::nan(""), 3.0});
  EXPECT_EQ(nan.n, 2u);
}

TEST(Replicates, TwoSeedsGiveTheRangeOneTheValueNoneNull) {
  EXPECT_EQ(formatReplicates(replicateStats({47.25, 45.5}), 2), "[45.50, 47.25]");
  EXPECT_EQ(formatReplicates(replicateStats({0.61}), 3), "0.610");
  const auto none = replicateStats({std::nullopt, std::nullopt});
  EXPECT_EQ(none.n, 0u);
  EXPECT_TRUE(std::isnan(none.mean));
  EXPECT_EQ(formatReplicates(none, 1), "null");
  EXPECT_TRUE(std::isnan(replicateStats({5.0}).std));
}

TEST(Replicates, NoCancellationForLargeOffsets) {
  // 1e9 + {1, 2, 3}: one-pass sum-of-squares loses the digits; two passes give std 1 exactly.
  const auto s = replicateStats({1e9 + 1, 1e9 + 2, 1e9 + 3});
  EXPECT_DOUBLE_EQ(s.std, 1.0);
}
