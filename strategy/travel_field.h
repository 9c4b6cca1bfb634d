// Travel times for the strategy from the planner's map: geodesic distances on the planner's
// inflated grid (Dijkstra, 8-connected, on a coarser copy of the grid), turned into seconds
// with the drive's turn rate, speed and acceleration (planning::DriveTime). One distance field
// is computed per start cell and cached until the map changes, so the strategy can ask for
// many targets at the cost of one search per start.
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "field_configs/robot_config.h"
#include "planning/planner.h"

namespace slamo::strategy {

class TravelField {
 public:
  // cell_m: edge of the coarse cells (a multiple of the planner's grid cell is best).
  TravelField(const field::DriveConfig& drive, double cell_m = 0.04);

  // Takes the planner's current inflated grid; drops the cached fields when its coarse copy
  // changed.
  void SetPlanner(const planning::Planner& planner);

  // Shortest collision-free distance between two points, or nothing when unreachable. A start
  // inside the inflation (after a close approach) leaves through the nearest free cell.
  std::optional<double> DistanceM(const Eigen::Vector2d& from, const Eigen::Vector2d& to);
  // Turn towards the target (or away from it, driving backwards: reverse_max_m), drive the
  // geodesic distance, turn to the final heading; plus settle_s for each of the three motions.
  std::optional<double> TravelTimeS(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

  double settle_s = 0.3;
  // How the executive drives a path (MatchWorld::Navigate): a leg shorter than min_leg_m is
  // not driven (the arrival accepts that error), and one behind the robot up to
  // reverse_max_m long is driven backwards instead of turning round twice (0: never).
  double min_leg_m = 0.0;
  double reverse_max_m = 0.0;

 private:
  std::optional<int> CellOf(const Eigen::Vector2d& p) const;
  const std::vector<float>& FieldFrom(int cell);

  field::DriveConfig drive_;
  double cell_m_;
  int width_ = 0, height_ = 0;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  std::vector<std::uint8_t> blocked_;
  std::unordered_map<int, std::vector<float>> fields_;  // by start cell, on blocked_
  int field_width_ = 0;                                 // the grid fields_ were computed on
  double field_cell_m_ = 0.0;
  Eigen::Vector2d field_origin_ = Eigen::Vector2d::Zero();
};

}  // namespace slamo::strategy
