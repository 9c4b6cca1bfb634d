#include "platform/field_geometry.h"

#include <gtest/gtest.h>

#include "field_configs/loader.h"

namespace slamo::platform {
namespace {

TEST(FootprintTest, WallsAndStructuresBlock) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  EXPECT_TRUE(FootprintIsFree(season, {-1.5, 0.3, 0.0}, 0.45, 0.42, 0.60));
  EXPECT_FALSE(FootprintIsFree(season, {-1.7, 0.3, 0.0}, 0.45, 0.42, 0.60));  // through the wall
  EXPECT_FALSE(FootprintIsFree(season, {1.0, 0.61, 0.0}, 0.45, 0.42, 0.60));  // on the red goal
  EXPECT_TRUE(FootprintIsFree(season, {-0.3, 0.0, 0.0}, 0.45, 0.42, 0.60));  // the bump is drivable
}

// The Toss Up barrier is raised 0.30 m: a robot lower than that drives under it, a taller one
// (the thesis robot's 0.60 m mast) does not; buckyballs roll under it, large balls do not.
TEST(FootprintTest, RaisedBarrierPassesOnlyWhatFitsUnder) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const Pose2D under_barrier{0.61, 0.0, 0.0};
  EXPECT_FALSE(FootprintIsFree(season, under_barrier, 0.45, 0.42, 0.60));
  EXPECT_FALSE(FootprintIsFree(season, under_barrier, 0.45, 0.42, 0.30));  // touches it
  EXPECT_TRUE(FootprintIsFree(season, under_barrier, 0.45, 0.42, 0.25));
  EXPECT_TRUE(PointInBlockingStructure(season, {0.61, 0.0}, 0.0, 0.60));
  EXPECT_FALSE(PointInBlockingStructure(season, {0.61, 0.0}, 0.0, 0.25));
  EXPECT_TRUE(PointBlocksObject(season, {0.61, 0.0}, 0.20, 0.40));      // a large ball
  EXPECT_FALSE(PointBlocksObject(season, {0.61, 0.0}, 0.0635, 0.127));  // a buckyball
}

}  // namespace
}  // namespace slamo::platform
