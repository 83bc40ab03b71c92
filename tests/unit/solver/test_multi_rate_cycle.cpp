// Unit tests of the multi-rate cycle (src/solver/multi_rate.hpp, make_cycle): a plan's cycle
// length and base step, and the cut that lands a cycle exactly on an output time without
// lengthening any part's step.
#include <gtest/gtest.h>

#include <limits>

#include "solver/multi_rate.hpp"

namespace crater::solver {
namespace {

TEST(MultiRateCycle, RunsTheLargestRatioWhenNoOutputIsNear) {
  const RateCycle cy = make_cycle({{1, 4, 2}, 1e-7}, 0.0, 1.0, 1e-15);
  EXPECT_EQ(cy.length, 4);
  EXPECT_EQ(cy.ratio, (std::vector<std::int64_t>{1, 4, 2}));
  EXPECT_DOUBLE_EQ(cy.h, 1e-7);
  EXPECT_DOUBLE_EQ(cy.t_end, 4e-7);
  EXPECT_FALSE(cy.at_frame);
}

TEST(MultiRateCycle, LandsOnAnOutputTimeWithTheFewestBaseSteps) {
  // 2.5 base steps to the output: 4 would pass it, so 4 base steps of 2.5/4 h, ratios <= 4.
  const RateCycle a = make_cycle({{1, 8, 2}, 1.0}, 10.0, 12.5, 1e-12);
  EXPECT_TRUE(a.at_frame);
  EXPECT_EQ(a.length, 4);
  EXPECT_EQ(a.ratio, (std::vector<std::int64_t>{1, 4, 2}));
  EXPECT_DOUBLE_EQ(a.h, 0.625);
  EXPECT_EQ(a.t_end, 12.5);  // exactly
  // Less than one base step left: one shortened base step for everyone.
  const RateCycle b = make_cycle({{1, 8, 2}, 1.0}, 10.0, 10.25, 1e-12);
  EXPECT_EQ(b.length, 1);
  EXPECT_EQ(b.ratio, (std::vector<std::int64_t>{1, 1, 1}));
  EXPECT_DOUBLE_EQ(b.h, 0.25);
  // Exactly a full cycle to the output: kept as planned, and marked as landing on it.
  const RateCycle c = make_cycle({{1, 8, 2}, 1.0}, 10.0, 18.0, 1e-12);
  EXPECT_EQ(c.length, 8);
  EXPECT_DOUBLE_EQ(c.h, 1.0);
  EXPECT_TRUE(c.at_frame);
}

TEST(MultiRateCycle, NoLimitGoesStraightToTheOutputTime) {
  const RateCycle cy =
      make_cycle({{8, 8}, std::numeric_limits<Real>::infinity()}, 0.5, 0.75, 1e-12);
  EXPECT_EQ(cy.length, 1);
  EXPECT_EQ(cy.ratio, (std::vector<std::int64_t>{1, 1}));
  EXPECT_DOUBLE_EQ(cy.h, 0.25);
  EXPECT_TRUE(cy.at_frame);
}

}  // namespace
}  // namespace crater::solver
