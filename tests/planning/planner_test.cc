#include "planning/planner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

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
  const PlanResult result = planner.Plan(Request(-0.8955, 1.40, 0.3, -1.2));
  ASSERT_EQ(result.status, PlanStatus::kSolved) << PlanStatusName(result.status);
  ASSERT_GE(result.path.size(), 2u);
  EXPECT_NEAR(result.path.front().x(), -0.8955, 1e-9);
  EXPECT_NEAR(result.path.back().y(), -1.2, 1e-9);
  ExpectPathClear(planner, result.path);
  const double straight_m = (Eigen::Vector2d(0.3, -1.2) - Eigen::Vector2d(-0.8955, 1.40)).norm();
  EXPECT_GE(result.length_m, straight_m - 1e-9);
  EXPECT_GT(result.travel_time_s, 0.0);
}

TEST_F(PlannerTest, EveryPlannerSolvesAnOpenQuery) {
  const Planner planner = MakePlanner(*season_);
  for (const std::string& name : PlannerNames()) {
    PlanRequest request = Request(-0.8955, 1.40, 0.3, -1.2);
    request.planner = name;
    request.time_budget_s = 0.3;
    const PlanResult result = planner.Plan(request);
    EXPECT_EQ(result.status, PlanStatus::kSolved) << name << ": " << PlanStatusName(result.status);
    ExpectPathClear(planner, result.path);
  }
}

// With max_iterations the plan depends only on the seed: each plan runs in a fresh child
// process seeded alike (OMPL's seed is process-wide), once with a generous time budget and
// once with a budget far too small to plan in, while another thread keeps a core busy. The
// paths are the same to the bit.
TEST_F(PlannerTest, IterationBoundedPlansDependOnlyOnTheSeed) {
  const Planner planner = MakePlanner(*season_);
  const auto plan_in_child = [&](double budget_s, bool busy) {
    int fds[2];
    EXPECT_EQ(::pipe(fds), 0);
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::close(fds[0]);
      std::atomic<bool> stop{false};
      std::thread hog([&] {
        volatile double x = 0.0;
        while (busy && !stop) x = x + 1.0;
      });
      SeedPlanners(7);
      PlanRequest request = Request(-0.8955, 1.40, 0.3, -1.2);
      request.time_budget_s = budget_s;
      request.max_iterations = 10000;
      const PlanResult r = planner.Plan(request);
      stop = true;
      hog.join();
      const int status = static_cast<int>(r.status);
      ssize_t ok = ::write(fds[1], &status, sizeof(status));
      for (const Eigen::Vector2d& p : r.path) ok = ::write(fds[1], p.data(), 2 * sizeof(double));
      ::_exit(ok >= 0 ? 0 : 1);
    }
    ::close(fds[1]);
    std::vector<double> out;
    int status = -1;
    EXPECT_EQ(::read(fds[0], &status, sizeof(status)), static_cast<ssize_t>(sizeof(status)));
    double v = 0.0;
    while (::read(fds[0], &v, sizeof(v)) == static_cast<ssize_t>(sizeof(v))) out.push_back(v);
    ::close(fds[0]);
    int exit_status = 0;
    ::waitpid(pid, &exit_status, 0);
    EXPECT_EQ(status, static_cast<int>(PlanStatus::kSolved));
    return out;
  };
  const std::vector<double> calm = plan_in_child(1.0, false);
  const std::vector<double> rushed = plan_in_child(1e-9, true);
  ASSERT_GE(calm.size(), 4u);
  EXPECT_EQ(calm, rushed);
}

TEST_F(PlannerTest, StartOrGoalInsideTheRedGoalIsInvalid) {
  const Planner planner = MakePlanner(*season_);
  EXPECT_EQ(planner.Plan(Request(0.78, 0.61, -0.8955, 1.40)).status, PlanStatus::kInvalidStart);
  EXPECT_EQ(planner.Plan(Request(-0.8955, 1.40, 0.78, 0.61)).status, PlanStatus::kInvalidGoal);
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

  PlanRequest request = Request(-0.8955, 1.40, 0.0, -1.0);
  request.time_budget_s = 0.2;
  const auto start = std::chrono::steady_clock::now();
  const PlanResult result = planner.Plan(request);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(result.status, PlanStatus::kSolved) << PlanStatusName(result.status);
  EXPECT_LT(elapsed_s, request.time_budget_s + 0.5);  // a bound, not a benchmark
}

// A large ball across the straight line from the red start to (0.3, -1.2).
mapping::MappedObject BallAcrossThePath(int id) {
  mapping::MappedObject ball;
  ball.id = id;
  ball.type = "large_ball";
  ball.colour = "red";
  ball.centre_m = {-0.29775, 0.10, 0.2};
  ball.radius_m = 0.2;
  ball.height_m = 0.4;
  return ball;
}

TEST_F(PlannerTest, PathIsClearChecksTheRemainingSegments) {
  const Planner planner = MakePlanner(*season_);
  const std::vector<Eigen::Vector2d> path = {{-0.8955, 1.40}, {-1.0, -0.5}, {0.3, -1.2}};
  EXPECT_TRUE(planner.PathIsClear(path));
  EXPECT_TRUE(planner.PathIsClear(path, 1));
  EXPECT_TRUE(planner.PathIsClear(path, 2));  // the goal alone
  EXPECT_FALSE(planner.PathIsClear(path, 3));
  EXPECT_FALSE(planner.PathIsClear({}));
  // Through the red goal (0.78, 0.61), in the goal zone: the first segment is blocked, the
  // rest is not.
  const std::vector<Eigen::Vector2d> through = {{0.95, 1.3}, {0.95, 0.0}, {1.4, 0.0}};
  ASSERT_TRUE(planner.IsClear(through[0]));
  ASSERT_TRUE(planner.IsClear(through[1]));
  EXPECT_FALSE(planner.PathIsClear(through));
  EXPECT_TRUE(planner.PathIsClear(through, 1));
}

TEST_F(PlannerTest, ReplansWhenAnObjectLandsOnThePath) {
  mapping::ObjectMapOptions map_options;
  map_options.resolution_m = 0.02;
  mapping::ObjectMap map(*season_, map_options);
  Planner planner(*robot_);
  planner.SetMap(map);
  SeedPlanners(7);
  PlanRequest request = Request(-0.8955, 1.40, 0.3, -1.2);
  const PlanResult first = planner.Plan(request);
  ASSERT_EQ(first.status, PlanStatus::kSolved);
  ASSERT_TRUE(planner.PathIsClear(first.path));

  // Nothing changed: the rest of the path is kept, from where the robot is.
  PlanRequest again = request;
  const Eigen::Vector2d robot = first.path[0] + 0.1 * (first.path[1] - first.path[0]).normalized();
  again.start_x_m = robot.x();
  again.start_y_m = robot.y();
  const PlanResult kept = planner.Replan(again, first.path, 1);
  EXPECT_EQ(kept.status, PlanStatus::kSolved);
  EXPECT_FALSE(kept.replanned);
  ASSERT_EQ(kept.path.size(), first.path.size());
  EXPECT_TRUE(kept.path.front().isApprox(robot));
  EXPECT_NEAR(kept.length_m, first.length_m - 0.1, 1e-9);

  // A ball lands across the path: the path is blocked and Replan() goes round it.
  map.SetObjects({BallAcrossThePath(1)});
  planner.SetMap(map);
  EXPECT_FALSE(planner.PathIsClear(first.path));
  const PlanResult replanned = planner.Replan(again, first.path, 1);
  ASSERT_EQ(replanned.status, PlanStatus::kSolved) << PlanStatusName(replanned.status);
  EXPECT_TRUE(replanned.replanned);
  EXPECT_TRUE(replanned.path.front().isApprox(robot));
  EXPECT_TRUE(replanned.path.back().isApprox(Eigen::Vector2d(0.3, -1.2)));
  EXPECT_TRUE(planner.PathIsClear(replanned.path));
  ExpectPathClear(planner, replanned.path);
  EXPECT_GT(replanned.length_m, kept.length_m);
}

TEST_F(PlannerTest, TheTargetObjectIsNoObstacle) {
  mapping::ObjectMapOptions map_options;
  map_options.resolution_m = 0.02;
  mapping::ObjectMap map(*season_, map_options);
  const std::vector<mapping::MappedObject> objects = {BallAcrossThePath(4)};
  map.SetObjects(objects);
  const std::vector<Eigen::Vector2d> line = {{-0.8955, 1.40}, {0.3, -1.2}};
  const Eigen::Vector2d ball(-0.29775, 0.10);

  Planner planner(*robot_);
  planner.SetMap(map);  // every object is an obstacle
  EXPECT_FALSE(planner.IsClear(ball));
  EXPECT_FALSE(planner.PathIsClear(line));
  planner.SetMap(map, objects);  // the same objects, none ignored
  EXPECT_FALSE(planner.PathIsClear(line));
  planner.SetMap(map, objects, {4});  // object 4 is the target
  EXPECT_TRUE(planner.IsClear(ball));
  EXPECT_TRUE(planner.PathIsClear(line));
  // The map itself keeps the object.
  EXPECT_TRUE(map.IsOccupied({ball.x(), ball.y(), 0.2}));

  PlannerOptions options;
  options.ignore_object_ids = {4};
  Planner ignoring(*robot_, options);
  ignoring.SetMap(map, objects);
  EXPECT_TRUE(ignoring.PathIsClear(line));
  // Other objects still count.
  mapping::MappedObject other = BallAcrossThePath(5);
  ignoring.SetMap(map, {objects[0], other});
  EXPECT_FALSE(ignoring.PathIsClear(line));
}

TEST_F(PlannerTest, ShortenKeepsTheEndsAndNeverLengthens) {
  const Planner planner = MakePlanner(*season_);
  // A zigzag in open floor (the goal zone beyond the stashes) pulls to the straight line.
  const std::vector<Eigen::Vector2d> zigzag = {
      {1.25, -1.0}, {1.45, -0.5}, {1.25, 0.0}, {1.45, 0.5}, {1.25, 1.0}};
  ASSERT_TRUE(planner.PathIsClear(zigzag));
  const std::vector<Eigen::Vector2d> taut = planner.Shorten(zigzag);
  EXPECT_EQ(taut.size(), 2u);
  EXPECT_TRUE(taut.front().isApprox(zigzag.front()));
  EXPECT_TRUE(taut.back().isApprox(zigzag.back()));
  // OMPL's path round a ball (simplified, not shortened): no longer, still clear.
  mapping::ObjectMapOptions map_options;
  map_options.resolution_m = 0.02;
  mapping::ObjectMap map(*season_, map_options);
  map.SetObjects({BallAcrossThePath(1)});
  PlannerOptions options;
  options.shorten = false;
  Planner loose(*robot_, options);
  loose.SetMap(map);
  SeedPlanners(3);
  const PlanResult result = loose.Plan(Request(-0.8955, 1.40, 0.3, -1.2));
  ASSERT_EQ(result.status, PlanStatus::kSolved);
  const std::vector<Eigen::Vector2d> around = loose.Shorten(result.path);
  EXPECT_LE(PathLength(around), result.length_m + 1e-12);
  EXPECT_TRUE(loose.PathIsClear(around));
  EXPECT_TRUE(around.front().isApprox(result.path.front()));
  EXPECT_TRUE(around.back().isApprox(result.path.back()));
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
