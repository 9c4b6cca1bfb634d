// Paths for the robot across the field, planned with OMPL on a 2D footprint of the object
// map, cut into observation stops and timed for the drive train.
//
// The robot is a skid steer that turns in place, so the planner works in R² (x, y): it finds
// a geometric path, and the robot follows it as turn-and-drive (turn in place towards the
// next point, drive straight to it). Headings are only used for the turns and the stops.
//
// Validity: a position is valid when a disc of inflation radius (footprint + clearance
// margin) around it touches no occupied cell of the grid. The grid of obstacles inflated by
// that radius is precomputed once per SetMap()/SetGrid() with a distance transform, so a state
// check is one lookup. Unknown cells count as free: inside the perimeter the season lists
// every fixed element, so unknown means "not observed, probably free" (see ObjectMap). Points
// outside the grid are invalid. A segment is clear when every cell it crosses is
// (SegmentIsClear(): an exact grid traversal, no sampling step to slip between, and cheaper
// than sampling at a quarter cell); OMPL checks its motions with it too.
//
// Obstacles (the object-obstacle policy): every occupied cell of the grid between
// grid_min_z_m and grid_max_z_m (the robot's height by default) is an obstacle: walls and
// structures (drive-over bumps lower than grid_min_z_m are not, nor raised barriers above the
// robot's top), every game object in the map's object layer, and whatever the
// camera put in the map (opponent robots among it). Game objects are obstacles because driving
// into one pushes it (and the robot off its path), except the target of the current task: the
// robot drives up to it to take it. SetMap(map, objects, ignore_object_ids) leaves such
// objects out (PlannerOptions::ignore_object_ids adds ids to every such call). Objects under
// the robot at its start (preloads) are the robot's own and belong in that list too. The
// planner never decides by itself that an object may be pushed aside: SetMap(map) plans round
// whatever the map holds, so a caller that accepts pushing small objects leaves them out of
// the map it hands over.
//
// Replanning: when the map changes (the tracker moved an object, a new one was seen), the
// executive calls SetMap() with the new map and then Replan() with the robot's current pose,
// the current path and the index of the waypoint it is driving to. Replan() keeps the rest of
// the path when PathIsClear() says it is still clear, and plans afresh from the robot's
// position otherwise.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "field_configs/robot_config.h"
#include "mapping/object_map.h"

namespace slamo::planning {

struct PlannerOptions {
  double clearance_m = 0.05;   // margin kept around the footprint, metres
  double grid_cell_m = 0.02;   // cell edge of the planning grid built by SetMap(), metres
  double grid_min_z_m = 0.06;  // lowest height in the grid (above drive-over bumps), metres
  // Highest height in the grid, metres; 0: the robot's height, so that a raised structure
  // (a barrier robots pass under) is an obstacle exactly when the robot does not fit under it.
  double grid_max_z_m = 0.0;
  // Segment checks: 0 for exact (every cell crossed); > 0 to sample every that many metres.
  double check_resolution_m = 0;
  double stop_spacing_m = 0.3;  // observation stops along the path, metres (0: none)
  // After OMPL's simplification, pull the path taut on the grid (Planner::Shorten()). Only
  // the planners that do not optimise length (rrtconnect) are shortened.
  bool shorten = true;
  // RRTConnect returns the first path it finds, which may go the long way round: it is run
  // this many times within the budget (each simplified and shortened) and the shortest path
  // kept. 1: a single run.
  int rrtconnect_attempts = 8;
  // Objects (MappedObject::id) that are never obstacles, e.g. the target of the current
  // task; used by SetMap(map, objects) and SetMap(map, objects, ignore_object_ids).
  std::vector<int> ignore_object_ids;
};

struct PlanRequest {
  double start_x_m = 0.0;
  double start_y_m = 0.0;
  double start_heading_deg = 0.0;
  double goal_x_m = 0.0;
  double goal_y_m = 0.0;
  double goal_heading_deg = 0.0;
  std::string planner = "rrtconnect";  // one of PlannerNames()
  double time_budget_s = 0.05;         // planning and simplification together, seconds
  // > 0: a plan that depends only on the seed, not on how busy the machine is. Each attempt
  // stops after this many planner iterations instead of at the time budget, RRTConnect makes
  // all its attempts (none after one that fails) and the simplifier runs until it stops
  // improving. A wall-clock guard of 20x time_budget_s (at least 1 s) still ends a runaway.
  // The match uses this; the benchmark measures the time-budgeted mode.
  int max_iterations = 0;
};

enum class PlanStatus { kSolved, kApproximate, kTimedOut, kInvalidStart, kInvalidGoal };

struct PlanResult {
  PlanStatus status = PlanStatus::kTimedOut;
  std::vector<Eigen::Vector2d> path;  // start to goal; empty unless solved or approximate
  double length_m = 0.0;
  double travel_time_s = 0.0;          // turn-and-drive along the path, final turn included
  std::vector<Eigen::Vector3d> stops;  // x, y (metres), heading (degrees)
  bool replanned = false;              // Replan(): true when the path was planned afresh
};

// The planners Plan() accepts: rrtconnect, rrtstar, informedrrtstar, prmstar, bitstar.
const std::vector<std::string>& PlannerNames();
const char* PlanStatusName(PlanStatus status);

// Seeds OMPL's process-wide random numbers for repeatable plans; call it once, before the
// first Plan() (OMPL ignores a seed set after its first random number generator exists).
void SeedPlanners(std::uint64_t seed);

// Radius of the disc checked around a position: half the robot's width (its sides while it
// drives along the path) plus the clearance margin. The circumscribed circle (half the
// diagonal) would be safer for turns in place but does not fit the starting tiles next to
// the wall, so turns in place near obstacles are not checked.
double InflationRadius(const field::RobotConfig& robot, const PlannerOptions& options);

// Observation stops every spacing_m of arc length along the path, then the goal; headings
// (degrees) along the path, the goal's stop facing goal_heading_deg. None for spacing_m <= 0.
std::vector<Eigen::Vector3d> StopPoints(const std::vector<Eigen::Vector2d>& path, double spacing_m,
                                        double goal_heading_deg);

// Seconds to drive a straight segment from rest to rest: trapezoidal speed profile with
// accel_mps2 up to cruise_speed_mps (triangular when the segment is too short).
double DriveTime(const field::DriveConfig& drive, double distance_m);

// Turn-and-drive time along the path: for each segment a turn in place at turn_rate_dps
// from the current heading, then DriveTime(); finally the turn to the goal heading.
double TravelTime(const field::DriveConfig& drive, const std::vector<Eigen::Vector2d>& path,
                  double start_heading_deg, double goal_heading_deg);

// Sum of the segment lengths, metres.
double PathLength(const std::vector<Eigen::Vector2d>& path);

// Plans on the latest map. Owns its grids; the robot config is copied.
class Planner {
 public:
  Planner(const field::RobotConfig& robot, const PlannerOptions& options = {});

  // Builds the planning grid from the map and precomputes the inflated obstacles. Every
  // object in the map is an obstacle.
  void SetMap(const mapping::ObjectMap& map);
  // As SetMap(map), with the map's object layer replaced by `objects` (normally the list last
  // given to map.SetObjects()) less those whose id is in ignore_object_ids or in
  // PlannerOptions::ignore_object_ids. The map is copied for that, not changed.
  void SetMap(const mapping::ObjectMap& map, const std::vector<mapping::MappedObject>& objects,
              const std::vector<int>& ignore_object_ids = {});
  void SetGrid(const mapping::OccupancyGrid2D& grid);

  // True when the robot may stand at p_m (inside the grid, clear of inflated obstacles).
  bool IsClear(const Eigen::Vector2d& p_m) const;
  // True when every point of the segment is clear (every cell it crosses is; with
  // check_resolution_m > 0, points that far apart).
  bool SegmentIsClear(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const;
  // True when every segment of the path from path[from_index] on is clear on the current
  // grid (a path of one point: that point). False for an empty path or from_index past it.
  bool PathIsClear(const std::vector<Eigen::Vector2d>& path, size_t from_index = 0) const;
  // Plans within request.time_budget_s. Throws std::invalid_argument on an unknown planner
  // name or before a map is set.
  PlanResult Plan(const PlanRequest& request) const;
  // For an executive driving `path` after the map changed (SetMap() called since): the robot
  // is at request.start_* and heading for path[next_index]. While the straight line from the
  // robot to path[next_index] and the rest of the path are clear, returns that (status
  // solved, replanned false; request.goal_* is not used for the path, only for the final
  // heading); otherwise Plan(request) from the robot's position, replanned true. A path whose
  // end is not the request's goal is replanned.
  PlanResult Replan(const PlanRequest& request, const std::vector<Eigen::Vector2d>& path,
                    size_t next_index) const;

  // The path pulled taut: vertices dropped while the shortcut is clear, then each vertex
  // slid (compass search down to 1 mm) while the two segments through it get shorter and
  // stay clear, a few rounds. With subdivisions > 0, that many times more with a vertex added
  // in the middle of every segment first, so the path can bend round curved obstacles.
  // Never longer than `path`; the ends stay; a clear path stays clear.
  std::vector<Eigen::Vector2d> Shorten(std::vector<Eigen::Vector2d> path,
                                       int subdivisions = 0) const;

  const mapping::OccupancyGrid2D& grid() const { return grid_; }
  const PlannerOptions& options() const { return options_; }
  // Sampling step for OMPL's state-validity resolution and last-valid-state searches: the
  // check_resolution_m option, or a quarter grid cell.
  double check_step_m() const;
  // Per grid cell: 1 when a robot centred there would touch an obstacle.
  const std::vector<std::uint8_t>& blocked() const { return blocked_; }
  double inflation_radius_m() const { return inflation_radius_m_; }

 private:
  field::RobotConfig robot_;
  PlannerOptions options_;
  double inflation_radius_m_;
  mapping::OccupancyGrid2D grid_;
  std::vector<std::uint8_t> blocked_;
};

}  // namespace slamo::planning
