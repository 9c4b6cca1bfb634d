#include <gtest/gtest.h>

#include "field_configs/loader.h"
#include "field_configs/summary.h"

namespace slamo::field {
namespace {

// Toss Up: each alliance owns 10 buckyballs (best: stash, 5) and 4 large balls (stash, 10),
// plus the 10-point autonomous bonus.
TEST(SummaryTest, TossUpPointsAvailableInAutonomous) {
  const SeasonSummary summary = Summarise(LoadSeasonConfig("toss_up"));
  EXPECT_EQ(summary.total_objects, 28);
  EXPECT_EQ((summary.objects.at({"buckyball", "red"})), 10);
  EXPECT_EQ((summary.objects.at({"large_ball", "blue"})), 4);
  EXPECT_EQ(summary.max_autonomous_points_red, 10 * 5 + 4 * 10 + 10);
  EXPECT_EQ(summary.max_autonomous_points_blue, 10 * 5 + 4 * 10 + 10);
}

TEST(SummaryTest, OwnColourRuleAndAllianceGoals) {
  const SeasonConfig season = LoadSeasonConfig("toss_up");
  EXPECT_EQ(BestPoints(season, "buckyball", "red", Alliance::kRed), 5);
  EXPECT_EQ(BestPoints(season, "buckyball", "red", Alliance::kBlue), 0);
  EXPECT_EQ(BestPoints(season, "large_ball", "blue", Alliance::kBlue), 10);
}

}  // namespace
}  // namespace slamo::field
