#include "planning/planner.h"

#include <chrono>
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "field_configs/loader.h"
#include "mapping/object_map.h"

namespace slamo::planning {
namespace {

class PlannerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    season_ = new field::SeasonConfig(field::LoadSeasonConfig("toss_up"));
    robot_ = new field::RobotConfig(field::LoadRobotConfig("thesis_robot"));
  }
  static void TearDownTestSuite() {
    delete season_;
    delete robot_;
  }

  static Planner MakePlanner(const field::SeasonConfig& season) {
    mapping::ObjectMapOptions options;
    options.resolution_m = 0.02;  // as fine as the planning grid
    const mapping::ObjectMap map(season, options);
    Planner planner(*robot_);
    planner.SetMap(map);
    return planner;
  }

  static PlanRequest Request(double sx, double sy, double gx, double gy) {
    PlanRequest request;
    request.start_x_m = sx;
    request.start_y_m = sy;
    request.goal_x_m = gx;
    request.goal_y_m = gy;
    request.time_budget_s = 1.0;
    return request;
  }

  // Every path point and every 1 cm along the segments between them is clear.
  static void ExpectPathClear(const Planner& planner, const std::vector<Eigen::Vector2d>& path) {
    for (size_t i = 1; i < path.size(); ++i) {
      const Eigen::Vector2d a = path[i - 1], b = path[i];
      const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.01)));
      for (int k = 0; k <= steps; ++k) {
        const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / steps);
        ASSERT_TRUE(planner.IsClear(p)) << "segment " << i << " at " << p.transpose();
      }
    }
  }

  static field::SeasonConfig* season_;
  static field::RobotConfig* robot_;
};

field::SeasonConfig* PlannerTest::season_ = nullptr;
field::RobotConfig* PlannerTest::robot_ = nullptr;

TEST_F(PlannerTest, SolvesFromTheRedStartAroundTheField) {
  const Planner planner = MakePlanner(*season_);
  const PlanResult result = planner.Plan(Request(-1.524, 0.3048, 0.3, -1.2));
  ASSERT_EQ(result.status, PlanStatus::kSolved) << PlanStatusName(result.status);
  ASSERT_GE(result.path.size(), 2u);
  EXPECT_NEAR(result.path.front().x(), -1.524, 1e-9);
  EXPECT_NEAR(result.path.back().y(), -1.2, 1e-9);
  ExpectPathClear(planner, result.path);
  const double straight_m = (Eigen::Vector2d(0.3, -1.2) - Eigen::Vector2d(-1.524, 0.3048)).norm();
  EXPECT_GE(result.length_m, straight_m - 1e-9);
  EXPECT_GT(result.travel_time_s, 0.0);
}

TEST_F(PlannerTest, EveryPlannerSolvesAnOpenQuery) {
  const Planner planner = MakePlanner(*season_);
  for (const std::string& name : PlannerNames()) {
    PlanRequest request = Request(-1.524, 0.3048, 0.3, -1.2);
    request.planner = name;
    request.time_budget_s = 0.3;
    const PlanResult result = planner.Plan(request);
    EXPECT_EQ(result.status, PlanStatus::kSolved) << name << ": " << PlanStatusName(result.status);
    ExpectPathClear(planner, result.path);
  }
}

TEST_F(PlannerTest, StartOrGoalInsideTheRedGoalIsInvalid) {
  const Planner planner = MakePlanner(*season_);
  EXPECT_EQ(planner.Plan(Request(0.45, 0.61, -1.524, 0.3048)).status, PlanStatus::kInvalidStart);
  EXPECT_EQ(planner.Plan(Request(-1.524, 0.3048, 0.45, 0.61)).status, PlanStatus::kInvalidGoal);
}

TEST_F(PlannerTest, EnclosedGoalEndsUnsolvedWithinBudget) {
  // A closed square of walls around (0, -1): the goal is clear but unreachable.
  field::SeasonConfig season = *season_;
  const double half_m = 0.5, thick_m = 0.05;
  auto wall = [&](double x, double y, double sx, double sy) {
    field::Structure s;
    s.name = "enclosure";
    s.center_m = {x, y};
    s.size_m = {sx, sy};
    s.height_m = 0.3;
    s.colour = season.structures.front().colour;
    season.structures.push_back(s);
  };
  wall(0.0, -1.0 + half_m, 2 * half_m + thick_m, thick_m);
  wall(0.0, -1.0 - half_m, 2 * half_m + thick_m, thick_m);
  wall(half_m, -1.0, thick_m, 2 * half_m + thick_m);
  wall(-half_m, -1.0, thick_m, 2 * half_m + thick_m);
  const Planner planner = MakePlanner(season);
  ASSERT_TRUE(planner.IsClear({0.0, -1.0}));

  PlanRequest request = Request(-1.524, 0.3048, 0.0, -1.0);
  request.time_budget_s = 0.2;
  const auto start = std::chrono::steady_clock::now();
  const PlanResult result = planner.Plan(request);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(result.status, PlanStatus::kSolved) << PlanStatusName(result.status);
  EXPECT_LT(elapsed_s, request.time_budget_s + 0.5);  // a bound, not a benchmark
}

TEST(StopPointsTest, StopsAreAtMostSpacingApart) {
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {1.0, 0}, {1.0, 0.75}, {0.2, 1.1}};
  const double spacing_m = 0.3;
  const std::vector<Eigen::Vector3d> stops = StopPoints(path, spacing_m, 45.0);
  ASSERT_GE(stops.size(), 2u);
  Eigen::Vector2d previous = path.front();
  for (const Eigen::Vector3d& stop : stops) {
    EXPECT_LE((stop.head<2>() - previous).norm(), spacing_m + 1e-9);
    previous = stop.head<2>();
  }
  EXPECT_TRUE(stops.back().head<2>().isApprox(path.back()));
  EXPECT_DOUBLE_EQ(stops.back().z(), 45.0);
  EXPECT_DOUBLE_EQ(stops.front().z(), 0.0);  // along the first segment
  EXPECT_TRUE(StopPoints(path, 0.0, 0.0).empty());
}

TEST(TravelTimeTest, StraightMetreIsTheTrapezoid) {
  field::DriveConfig drive;
  drive.cruise_speed_mps = 0.067;
  drive.accel_mps2 = 0.5;
  drive.turn_rate_dps = 30.0;
  const double v = drive.cruise_speed_mps, a = drive.accel_mps2;
  // Accelerate to v, cruise, brake: d / v + v / a.
  const double expected_s = 1.0 / v + v / a;
  EXPECT_NEAR(TravelTime(drive, {{0, 0}, {1, 0}}, 0.0, 0.0), expected_s, 1e-9);
  // A quarter turn before and after adds 2 * 90 / 30 s.
  EXPECT_NEAR(TravelTime(drive, {{0, 0}, {0, 1}}, 0.0, 0.0), expected_s + 6.0, 1e-9);
  // Too short to reach cruise speed: triangular profile.
  EXPECT_NEAR(DriveTime(drive, 0.004), 2.0 * std::sqrt(0.004 / a), 1e-12);
}

}  // namespace
}  // namespace slamo::planning
