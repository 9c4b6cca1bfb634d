#include "autonomy/experiments/tuning.h"

#include <algorithm>

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

// Pick and release rates per combination from the attempt records, which survive the trip
// through JSON (a tune shard, or the pipe from a match process) and end up in attempts.csv.
TEST(Tuning, PickAndReleaseRatesComeFromTheAttemptRecords) {
  const auto attempt = [](const std::string& action, const std::string& outcome) {
    AttemptCheck a;
    a.action = action;
    a.outcome = outcome;
    a.kind = "buckyball";
    a.colour = "red";
    a.range_m = 0.7;
    a.three_sigma_m = 0.09;
    return a;
  };
  MatchOutcome m;
  m.combo = "strategy=planner";
  m.records = {attempt("PICK", "target"),  attempt("PICK", "target"),  attempt("PICK", "other"),
               attempt("PICK", "nothing"), attempt("SCORE", "scored"), attempt("SCORE", "missed")};
  const MatchOutcome back = OutcomeFromJson(nlohmann::json::parse(ToJson(m).dump()));
  ASSERT_EQ(back.records.size(), m.records.size());
  EXPECT_EQ(back.records[2].outcome, "other");
  EXPECT_DOUBLE_EQ(back.records[0].range_m, 0.7);
  const std::vector<ComboSummary> rows = Summarise({back});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].picks, 4);
  EXPECT_DOUBLE_EQ(rows[0].pick_target_fraction, 0.5);
  EXPECT_DOUBLE_EQ(rows[0].pick_other_fraction, 0.25);
  EXPECT_DOUBLE_EQ(rows[0].pick_nothing_fraction, 0.25);
  EXPECT_EQ(rows[0].releases, 2);
  EXPECT_DOUBLE_EQ(rows[0].release_scored_fraction, 0.5);
  const std::string csv = AttemptsCsv({back});
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7);  // the header and six attempts
  EXPECT_NE(csv.find("PICK,buckyball,red,-1,0.7,0,0.03,"), std::string::npos) << csv;
}

}  // namespace
}  // namespace slamo::autonomy
