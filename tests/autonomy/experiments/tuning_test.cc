#include "autonomy/experiments/tuning.h"

#include <gtest/gtest.h>

namespace slamo::autonomy {
namespace {

TEST(Tuning, ParsesParametersAndRejectsBadOnes) {
  const auto p = ParseParam("strategy=planner,greedy");
  EXPECT_EQ(p.first, "strategy");
  EXPECT_EQ(p.second, (std::vector<std::string>{"planner", "greedy"}));
  EXPECT_THROW(ParseParam("strategy"), std::invalid_argument);
  EXPECT_THROW(ParseParam("strategy=planner,,greedy"), std::invalid_argument);
  EXPECT_THROW(ParseParam("strategy=random"), std::invalid_argument);
  EXPECT_THROW(ParseParam("speed=fast"), std::invalid_argument);
  EXPECT_THROW(ParseParam("warp=1"), std::invalid_argument);
  MatchSetup setup;
  ApplyParam("frames", "fixed:7", &setup);
  EXPECT_EQ(setup.frames.rule, mapping::FrameRule::kFixed);
  EXPECT_EQ(setup.frames.fixed_frames, 7);
  ApplyParam("speed", "0.2", &setup);
  EXPECT_DOUBLE_EQ(setup.drive_speed_mps, 0.2);
}

TEST(Tuning, CombinationsAreTheCartesianProduct) {
  const ParamGrid grid = {{"strategy", {"planner", "greedy", "scripted"}},
                          {"speed", {"0.1", "0.2"}}};
  const std::vector<ParamSet> combos = Combinations(grid);
  ASSERT_EQ(combos.size(), 6u);
  EXPECT_EQ(Describe(combos.front()), "strategy=planner speed=0.1");
  EXPECT_EQ(Describe(combos.back()), "strategy=scripted speed=0.2");
  EXPECT_EQ(Combinations({}).size(), 1u);
}

TEST(Tuning, SummaryRanksByMeanPointsWithConfidenceIntervals) {
  std::vector<MatchOutcome> outcomes;
  for (int i = 0; i < 4; ++i) {
    MatchOutcome a;
    a.combo = "a";
    a.points = 10 + i;
    a.points_start = 10;
    outcomes.push_back(a);
    MatchOutcome b;
    b.combo = "b";
    b.points = 20;
    b.points_start = 10;
    b.overrun_s = i == 0 ? 0.1 : 0.0;
    outcomes.push_back(b);
  }
  MatchOutcome crashed;
  crashed.combo = "a";
  crashed.failed = true;
  outcomes.push_back(crashed);
  const std::vector<ComboSummary> rows = Summarise(outcomes);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].combo, "b");
  EXPECT_DOUBLE_EQ(rows[0].mean_points, 20.0);
  EXPECT_DOUBLE_EQ(rows[0].ci95_points, 0.0);
  EXPECT_EQ(rows[0].overruns, 1);
  EXPECT_EQ(rows[1].matches, 4);
  EXPECT_EQ(rows[1].failed, 1);
  EXPECT_DOUBLE_EQ(rows[1].mean_gained, 1.5);
  // sd of {0,1,2,3} = 1.291; 1.96 * 1.291 / 2
  EXPECT_NEAR(rows[1].ci95_gained, 1.96 * 1.2909944 / 2.0, 1e-6);
  EXPECT_NE(SummaryCsv(rows).find("rank,combo"), std::string::npos);
}

}  // namespace
}  // namespace slamo::autonomy
