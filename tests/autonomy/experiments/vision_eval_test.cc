#include "autonomy/experiments/vision_eval.h"

#include <gtest/gtest.h>

#include "field_configs/loader.h"

namespace slamo::autonomy {
namespace {

std::vector<VisionMethodScore> Scores(const std::string& season_name, int frames, uint64_t seed,
                                      bool arena) {
  const field::SeasonConfig season = field::LoadSeasonConfig(season_name);
  VisionEvalOptions options;
  options.frames = frames;
  options.seed = seed;
  options.arena = arena;
  return EvaluateVision(season, field::LoadRobotConfig("thesis_robot"), options);
}

// In the arena, the field gate drops the crowd, posters and lights beyond the perimeter:
// precision with it beats precision without it by a wide margin for every method, and it
// drops no real object. Measured with `slamo eval vision --season toss_up --arena --frames 10
// --seed 1`: +0.35 for the smallest gain (0.837 against 0.488 for threshold+defects), no
// object dropped; the test asks for +0.25.
TEST(VisionEvalTest, ArenaPrecisionIsBetterWithTheFieldGate) {
  const std::vector<VisionMethodScore> scores = Scores("toss_up", 10, 1, true);
  ASSERT_EQ(scores.size(), 6u);
  for (const VisionMethodScore& s : scores) {
    SCOPED_TRACE(s.name);
    EXPECT_GT(s.rejected_by_geometry, 10);
    EXPECT_EQ(s.rejected_objects, 0);
    EXPECT_GT(s.Precision(), s.RawPrecision() + 0.25);
    EXPECT_GT(s.expected, 20);
  }
}

// The same seed gives the same scores; the clean field (no arena) has almost nothing for the
// gate to drop.
TEST(VisionEvalTest, DeterministicPerSeedAndTheCleanFieldHasLittleToReject) {
  const std::vector<VisionMethodScore> a = Scores("over_under", 4, 3, true);
  const std::vector<VisionMethodScore> b = Scores("over_under", 4, 3, true);
  EXPECT_EQ(FormatVisionTable(a), FormatVisionTable(b));
  const std::vector<VisionMethodScore> clean = Scores("over_under", 4, 3, false);
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_LT(clean[k].rejected_by_geometry, a[k].rejected_by_geometry) << a[k].name;
  }
}

}  // namespace
}  // namespace slamo::autonomy
