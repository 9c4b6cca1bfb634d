#include "planning/reference_path.h"

#include <cmath>

#include <gtest/gtest.h>

#include "field_configs/loader.h"
#include "mapping/object_map.h"
#include "platform/drive_base.h"

namespace slamo::planning {
namespace {

using platform::kPi;

field::RobotConfig Robot() { return field::LoadRobotConfig("thesis_robot"); }

// An open 3 m square grid, 2 cm cells, with one occupied cell at the origin (if asked).
mapping::OccupancyGrid2D OpenGrid(bool post) {
  mapping::OccupancyGrid2D grid;
  grid.width = grid.height = 150;
  grid.cell_m = 0.02;
  grid.origin_m = {-1.5, -1.5};
  grid.cells.assign(150 * 150, mapping::OccupancyGrid2D::kFree);
  if (post) grid.cells[*grid.IndexOf({0.001, 0.001})] = mapping::OccupancyGrid2D::kOccupied;
  return grid;
}

// Shortest path between (-a, 0) and (a, 0) round a disc of radius r at the origin: two
// tangents and the arc between them.
double AroundDisc(double a, double r) {
  return 2 * std::sqrt(a * a - r * r) + r * (kPi - 2 * std::acos(r / a));
}

void ExpectClear(const Planner& planner, const std::vector<Eigen::Vector2d>& path) {
  EXPECT_TRUE(planner.PathIsClear(path));
}

TEST(ReferencePathTest, ClearStraightLineIsTheReference) {
  Planner planner(Robot());
  planner.SetGrid(OpenGrid(false));
  const Eigen::Vector2d start(-1.0, -0.7), goal(0.9, 0.8);
  const auto path = ReferencePath(planner, start, goal);
  ASSERT_TRUE(path.has_value());
  EXPECT_LE(PathLength(*path), (goal - start).norm() + 1e-12);
  EXPECT_NEAR(PathLength(*path), (goal - start).norm(), 1e-12);
}

TEST(ReferencePathTest, RoundAPostWithinTheDiscBounds) {
  Planner planner(Robot());
  planner.SetGrid(OpenGrid(true));
  // The post's cell centre is at (0.01, 0.01); cells whose centre lies within reach of it are
  // blocked, so the blocked area holds the disc of radius reach - half a cell diagonal and lies
  // inside the disc of radius reach + half a diagonal (reach: inflation + half a diagonal).
  const double half_diagonal_m = 0.02 * std::sqrt(0.5);
  const double reach_m = planner.inflation_radius_m() + half_diagonal_m;
  const Eigen::Vector2d centre(0.01, 0.01);
  const double a = 1.2;
  const Eigen::Vector2d start = centre + Eigen::Vector2d(-a, 0),
                        goal = centre + Eigen::Vector2d(a, 0);
  ASSERT_FALSE(planner.SegmentIsClear(start, goal));
  const auto path = ReferencePath(planner, start, goal);
  ASSERT_TRUE(path.has_value());
  ExpectClear(planner, *path);
  const double length_m = PathLength(*path);
  EXPECT_GE(length_m, AroundDisc(a, reach_m - half_diagonal_m) - 1e-9);
  // A polyline round the staircase: within 1 cm of the outer disc's tangent-and-arc path.
  EXPECT_LE(length_m, AroundDisc(a, reach_m + half_diagonal_m) + 0.01);
  EXPECT_TRUE(path->front().isApprox(start));
  EXPECT_TRUE(path->back().isApprox(goal));
}

TEST(ReferencePathTest, NoPathToAnEnclosedGoalOrFromABlockedStart) {
  Planner planner(Robot());
  mapping::OccupancyGrid2D grid = OpenGrid(false);
  // A ring of occupied cells of radius 0.6 m round the origin.
  for (int k = 0; k < 2000; ++k) {
    const double t = 2 * kPi * k / 2000;
    grid.cells[*grid.IndexOf({0.6 * std::cos(t), 0.6 * std::sin(t)})] =
        mapping::OccupancyGrid2D::kOccupied;
  }
  planner.SetGrid(grid);
  ASSERT_TRUE(planner.IsClear({0, 0}));
  EXPECT_FALSE(ReferencePath(planner, {-1.3, -1.3}, {0, 0}).has_value());
  EXPECT_FALSE(ReferencePath(planner, {0.6, 0.0}, {-1.3, -1.3}).has_value());
}

// OMPL's paths are never meaningfully shorter than the reference on a season's field.
TEST(ReferencePathTest, OmplPathsAreNoShorterThanTheReference) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  mapping::ObjectMapOptions map_options;
  map_options.resolution_m = 0.02;
  const mapping::ObjectMap map(season, map_options);
  Planner planner(Robot());
  planner.SetMap(map);
  SeedPlanners(11);
  // OMPL checks motions at its own sample positions; a segment may graze a blocked cell's
  // corner between two samples. A grid cell per query is the tolerance.
  const double tolerance_m = planner.grid().cell_m;
  const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> queries = {
      {{-0.8955, 1.40}, {0.3, -1.2}},  // straight
      {{0.95, 1.3}, {0.95, -1.3}},     // round both stashes, in the goal zone
      {{-1.0, 0.0}, {1.2, -0.3}},      // round the end of the barrier (the 0.60 m robot
                                       // does not pass under it)
      {{-0.2, 0.61}, {1.3, 0.61}}};    // round the barrier, past the red goal
  for (const auto& [start, goal] : queries) {
    const auto reference = ReferencePath(planner, start, goal);
    ASSERT_TRUE(reference.has_value()) << start.transpose() << " -> " << goal.transpose();
    ExpectClear(planner, *reference);
    const double reference_m = PathLength(*reference);
    EXPECT_GE(reference_m, (goal - start).norm() - 1e-9);
    for (const std::string& name : PlannerNames()) {
      PlanRequest request;
      request.start_x_m = start.x();
      request.start_y_m = start.y();
      request.goal_x_m = goal.x();
      request.goal_y_m = goal.y();
      request.planner = name;
      // Round the barrier's end the inflated robot barely fits through the gap by the wall
      // (0.56 m for 0.52 m): those queries get 1 s. RRTConnect (the shipped planner) must
      // solve them; the optimising planners often do not within a wall-clock budget on a busy
      // machine (their solve rates through the gap are the benchmark's, planning/README.md),
      // and their length is checked when they do.
      const bool crosses = (start.x() < 0.61) != (goal.x() < 0.61);
      request.time_budget_s = crosses ? 1.0 : 0.2;
      const PlanResult result = planner.Plan(request);
      if (crosses && name != "rrtconnect" && result.status != PlanStatus::kSolved) continue;
      ASSERT_EQ(result.status, PlanStatus::kSolved)
          << name << " " << start.transpose() << " -> " << goal.transpose();
      EXPECT_GE(result.length_m, reference_m - tolerance_m)
          << name << " " << start.transpose() << " -> " << goal.transpose();
    }
  }
}

}  // namespace
}  // namespace slamo::planning
