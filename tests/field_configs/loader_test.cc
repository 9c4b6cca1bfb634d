#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "field_configs/config_error.h"
#include "field_configs/loader.h"
#include "tests/field_configs/config_test_util.h"

namespace slamo::field {
namespace {

// Every shipped season file loads, and holds what every later module relies on.
TEST(LoaderTest, EveryShippedSeasonLoads) {
  const std::vector<std::string> seasons = ListSeasons();
  ASSERT_FALSE(seasons.empty());
  for (const std::string& name : seasons) {
    SCOPED_TRACE(name);
    SeasonConfig season;
    ASSERT_NO_THROW(season = LoadSeasonConfig(name));
    EXPECT_EQ(season.season, name);
    // 12 ft inside the perimeter; the seasons corrected from the field facts give the inner
    // faces of the walls, 3.566 m (their YAML files say so).
    const bool measured =
        name == "over_under" || name == "high_stakes" || name == "push_back" || name == "toss_up";
    EXPECT_NEAR(season.field.size_m, measured ? 3.566 : 3.658, 0.01);
    EXPECT_FALSE(season.landmarks.empty());
    EXPECT_FALSE(season.object_types.empty());
    EXPECT_GT(season.ObjectCount(), 0);
    EXPECT_FALSE(season.goals.empty());
    EXPECT_TRUE(std::any_of(season.starts.begin(), season.starts.end(),
                            [](const StartTile& s) { return s.alliance == Alliance::kRed; }));
    EXPECT_TRUE(std::any_of(season.starts.begin(), season.starts.end(),
                            [](const StartTile& s) { return s.alliance == Alliance::kBlue; }));
  }
}

TEST(LoaderTest, ShipsTheSevenSeasons) {
  const std::vector<std::string> seasons = ListSeasons();
  for (const char* name : {"toss_up", "skyrise", "nothing_but_net", "starstruck", "over_under",
                           "high_stakes", "push_back"}) {
    EXPECT_NE(std::find(seasons.begin(), seasons.end(), name), seasons.end()) << name;
  }
}

TEST(LoaderTest, EveryShippedRobotLoads) {
  const std::vector<std::string> robots = ListRobots();
  ASSERT_FALSE(robots.empty());
  for (const std::string& name : robots) {
    SCOPED_TRACE(name);
    EXPECT_NO_THROW(LoadRobotConfig(name));
  }
}

// The thesis's facts, read back from the default season and robot.
TEST(LoaderTest, TossUpMatchesTheThesis) {
  const SeasonConfig season = LoadSeasonConfig(kDefaultSeason);
  EXPECT_EQ(season.name, "Toss Up");
  EXPECT_DOUBLE_EQ(season.rules.autonomous_s, 45.0);
  EXPECT_EQ(season.landmarks.size(), 8u);
  int buckyballs = 0;
  int large_balls = 0;
  for (const ObjectPlacement& p : season.objects) {
    (p.type == "buckyball" ? buckyballs : large_balls) += p.count;
  }
  EXPECT_EQ(buckyballs, 20);
  EXPECT_EQ(large_balls, 8);
  EXPECT_EQ(season.FindObjectType("large_ball")->material, Material::kSemiTransparent);
  EXPECT_EQ(season.FindObjectType("buckyball")->material, Material::kSolid);
}

TEST(LoaderTest, ThesisRobotHasTheKinectV2Intrinsics) {
  const RobotConfig robot = LoadRobotConfig(kDefaultRobot);
  EXPECT_EQ(robot.camera.width_px, 512);
  EXPECT_EQ(robot.camera.height_px, 424);
  EXPECT_DOUBLE_EQ(robot.camera.cx, 254.878);
  EXPECT_DOUBLE_EQ(robot.camera.cy, 205.390);
  EXPECT_DOUBLE_EQ(robot.camera.fx, 365.456);
  EXPECT_DOUBLE_EQ(robot.camera.mount.height_m, 0.5);
  EXPECT_NEAR(robot.drive.wheel_diameter_m, 2.75 * 0.0254, 1e-4);
  EXPECT_EQ(robot.drive.pwm.stop, 90);
  EXPECT_DOUBLE_EQ(robot.drive.cruise_speed_mps, 0.067);
}

TEST(LoaderTest, ResolvesNamesAndPaths) {
  EXPECT_EQ(ResolveSeasonPath("toss_up"), ConfigDir() + "/toss_up.yaml");
  EXPECT_EQ(ResolveSeasonPath("some/dir/x.yaml"), "some/dir/x.yaml");
  try {
    ResolveSeasonPath("tossup");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("toss_up"), std::string::npos) << e.what();
  }
}

TEST(LoaderTest, MissingFileIsAConfigError) {
  EXPECT_THROW(LoadSeasonConfig("/nonexistent/field.yaml"), ConfigError);
}

}  // namespace
}  // namespace slamo::field
