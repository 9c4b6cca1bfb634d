#include "platform/clock.h"

#include <gtest/gtest.h>

namespace slamo::platform {
namespace {

TEST(SimClockTest, AdvancesOnlyWhenTold) {
  SimClock clock(2.0);
  EXPECT_DOUBLE_EQ(clock.NowS(), 2.0);
  clock.Advance(0.5);
  clock.Advance(0.0);
  EXPECT_DOUBLE_EQ(clock.NowS(), 2.5);
  const Clock& as_clock = clock;
  EXPECT_DOUBLE_EQ(as_clock.NowS(), 2.5);
}

TEST(SimClockDeathTest, NegativeStepAborts) {
  SimClock clock;
  EXPECT_DEATH(clock.Advance(-0.1), "dt_s must be >= 0");
}

TEST(SteadyClockTest, NeverGoesBack) {
  SteadyClock clock;
  const double first_s = clock.NowS();
  EXPECT_GE(first_s, 0.0);
  EXPECT_GE(clock.NowS(), first_s);
}

}  // namespace
}  // namespace slamo::platform
