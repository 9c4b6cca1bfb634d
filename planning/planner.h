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
// outside the grid are invalid.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "field_configs/robot_config.h"
#include "mapping/object_map.h"

namespace slamo::planning {

struct PlannerOptions {
  double clearance_m = 0.05;      // margin kept around the footprint, metres
  double grid_cell_m = 0.02;      // cell edge of the planning grid built by SetMap(), metres
  double grid_min_z_m = 0.06;     // lowest height in the grid (above drive-over bumps), metres
  double grid_max_z_m = 0.50;     // highest height in the grid (about the robot's), metres
  double check_resolution_m = 0;  // motion checking step, metres (0: a quarter grid cell)
  double stop_spacing_m = 0.3;    // observation stops along the path, metres (0: none)
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
};

enum class PlanStatus { kSolved, kApproximate, kTimedOut, kInvalidStart, kInvalidGoal };

struct PlanResult {
  PlanStatus status = PlanStatus::kTimedOut;
  std::vector<Eigen::Vector2d> path;  // start to goal; empty unless solved or approximate
  double length_m = 0.0;
  double travel_time_s = 0.0;          // turn-and-drive along the path, final turn included
  std::vector<Eigen::Vector3d> stops;  // x, y (metres), heading (degrees)
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

// Plans on the latest map. Owns its grids; the robot config is copied.
class Planner {
 public:
  Planner(const field::RobotConfig& robot, const PlannerOptions& options = {});

  // Builds the planning grid from the map and precomputes the inflated obstacles.
  void SetMap(const mapping::ObjectMap& map);
  void SetGrid(const mapping::OccupancyGrid2D& grid);

  // True when the robot may stand at p_m (inside the grid, clear of inflated obstacles).
  bool IsClear(const Eigen::Vector2d& p_m) const;
  // Plans within request.time_budget_s. Throws std::invalid_argument on an unknown planner
  // name or before a map is set.
  PlanResult Plan(const PlanRequest& request) const;

  const mapping::OccupancyGrid2D& grid() const { return grid_; }
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
