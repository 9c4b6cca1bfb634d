#include "platform/field_geometry.h"

#include <cmath>
#include <random>

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

// The outline and centre line sampled every 2 cm, each point tested with DistanceToStructure:
// what FootprintIsFree computes, written the plain way.
bool FootprintIsFreeReference(const field::SeasonConfig& season, const Pose2D& pose,
                              double length_m, double width_m, double height_m) {
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  const int nx = static_cast<int>(std::ceil(length_m / 0.02));
  const int ny = static_cast<int>(std::ceil(width_m / 0.02));
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      if (i != 0 && i != nx && j != 0 && j != ny && j != ny / 2) continue;
      const double lx = -length_m / 2.0 + length_m * i / nx;
      const double ly = -width_m / 2.0 + width_m * j / ny;
      const Eigen::Vector2d p(pose.x_m + c * lx - s * ly, pose.y_m + s * lx + c * ly);
      if (std::abs(p.x()) > season.HalfSize() || std::abs(p.y()) > season.HalfSize()) return false;
      for (const field::Structure& st : season.structures) {
        if (BlocksRobot(st, height_m) && DistanceToStructure(st, p) <= 0.0) return false;
      }
    }
  }
  return true;
}

// The fast test (structures out of reach skipped, rotations worked out once) gives the plain
// test's answer everywhere, on every season, for robots that pass under barriers and not.
// Which goals objects are pushed in under: Over Under's nets (frames named apart from their
// goals, 0.16 m up), Push Back's upper centre goal (a tube: entered through its ends only, so
// nothing is pushed into it); not goals whose own structure blocks robots.
TEST(GoalTest, RaisedGoalsAreThoseObjectsPassUnder) {
  const auto raised = [](const std::string& season_name, const std::string& goal) {
    const field::SeasonConfig season = field::LoadSeasonConfig(season_name);
    for (const field::Goal& g : season.goals) {
      if (g.name == goal) return GoalIsRaised(season, g);
    }
    ADD_FAILURE() << season_name << " has no goal " << goal;
    return false;
  };
  EXPECT_TRUE(raised("over_under", "red_goal"));
  EXPECT_TRUE(raised("over_under", "blue_goal"));
  EXPECT_FALSE(raised("over_under", "red_offensive_zone"));
  EXPECT_TRUE(raised("push_back", "center_goal_upper"));
  EXPECT_FALSE(raised("push_back", "center_goal_lower"));
  EXPECT_FALSE(raised("push_back", "long_goal_left"));
  EXPECT_FALSE(raised("toss_up", "red_stash"));
  EXPECT_FALSE(raised("nothing_but_net", "red_low_goal"));
  EXPECT_FALSE(raised("high_stakes", "neutral_stake_left"));

  const field::SeasonConfig over_under = field::LoadSeasonConfig("over_under");
  const auto index = [](const field::SeasonConfig& season, const std::string& goal) {
    for (size_t g = 0; g < season.goals.size(); ++g) {
      if (season.goals[g].name == goal) return static_cast<int>(g);
    }
    return -2;
  };
  EXPECT_EQ(GoalPushedInto(over_under, Eigen::Vector2d(1.30, 0.1)), index(over_under, "red_goal"));
  EXPECT_EQ(GoalPushedInto(over_under, Eigen::Vector2d(-1.30, 0.0)),
            index(over_under, "blue_goal"));
  EXPECT_EQ(GoalPushedInto(over_under, Eigen::Vector2d(1.0, 0.0)), -1);  // in front of the bar
  const field::SeasonConfig push_back = field::LoadSeasonConfig("push_back");
  EXPECT_EQ(GoalPushedInto(push_back, Eigen::Vector2d(0.0, 0.0)), -1);  // tubes: ends only
}

TEST(FootprintTest, AgreesWithPointByPointTest) {
  std::mt19937_64 rng(17);
  for (const std::string& name : field::ListSeasons()) {
    const field::SeasonConfig season = field::LoadSeasonConfig(name);
    std::uniform_real_distribution<double> xy(-season.HalfSize(), season.HalfSize());
    std::uniform_real_distribution<double> heading(-3.2, 3.2);
    int free = 0;
    for (int k = 0; k < 2000; ++k) {
      const Pose2D pose{xy(rng), xy(rng), heading(rng)};
      for (const double height_m : {0.25, 0.60}) {
        const bool expected = FootprintIsFreeReference(season, pose, 0.45, 0.42, height_m);
        ASSERT_EQ(FootprintIsFree(season, pose, 0.45, 0.42, height_m), expected)
            << name << " at " << pose.x_m << ", " << pose.y_m << ", " << pose.theta_rad;
        free += expected;
      }
    }
    EXPECT_GT(free, 0) << name;
    EXPECT_LT(free, 4000) << name;
  }
}

}  // namespace
}  // namespace slamo::platform
