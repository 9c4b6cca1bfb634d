#include "platform/field_geometry.h"

#include <gtest/gtest.h>

#include "field_configs/loader.h"

namespace slamo::platform {
namespace {

TEST(FootprintTest, WallsAndStructuresBlock) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  EXPECT_TRUE(FootprintIsFree(season, {-1.5, 0.3, 0.0}, 0.45, 0.42));
  EXPECT_FALSE(FootprintIsFree(season, {-1.7, 0.3, 0.0}, 0.45, 0.42));   // through the wall
  EXPECT_FALSE(FootprintIsFree(season, {0.45, 0.61, 0.0}, 0.45, 0.42));  // on the red goal
  EXPECT_TRUE(FootprintIsFree(season, {-0.3, 0.0, 0.0}, 0.45, 0.42));    // the bump is drivable
}

}  // namespace
}  // namespace slamo::platform
