#include "planning/planner.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/prm/PRMstar.h>
#include <ompl/geometric/planners/rrt/InformedRRTstar.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace slamo::planning {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

constexpr double kPi = 3.14159265358979323846;

double HeadingDeg(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const Eigen::Vector2d d = to - from;
  return std::atan2(d.y(), d.x()) * 180.0 / kPi;
}

// Smallest turn between two headings, degrees in [0, 180].
double TurnDeg(double from_deg, double to_deg) {
  double turn = std::fmod(std::abs(to_deg - from_deg), 360.0);
  return turn > 180.0 ? 360.0 - turn : turn;
}

ob::PlannerPtr MakePlanner(const std::string& name, const ob::SpaceInformationPtr& si) {
  if (name == "rrtconnect") return std::make_shared<og::RRTConnect>(si);
  if (name == "rrtstar") return std::make_shared<og::RRTstar>(si);
  if (name == "informedrrtstar") return std::make_shared<og::InformedRRTstar>(si);
  if (name == "prmstar") return std::make_shared<og::PRMstar>(si);
  if (name == "bitstar") return std::make_shared<og::BITstar>(si);
  throw std::invalid_argument("unknown planner '" + name +
                              "' (expected rrtconnect, rrtstar, informedrrtstar, prmstar or "
                              "bitstar)");
}

double PathLength(const std::vector<Eigen::Vector2d>& path) {
  double length_m = 0.0;
  for (size_t i = 1; i < path.size(); ++i) length_m += (path[i] - path[i - 1]).norm();
  return length_m;
}

}  // namespace

const std::vector<std::string>& PlannerNames() {
  static const std::vector<std::string> kNames = {"rrtconnect", "rrtstar", "informedrrtstar",
                                                  "prmstar", "bitstar"};
  return kNames;
}

const char* PlanStatusName(PlanStatus status) {
  switch (status) {
    case PlanStatus::kSolved:
      return "solved";
    case PlanStatus::kApproximate:
      return "approximate";
    case PlanStatus::kTimedOut:
      return "timed out";
    case PlanStatus::kInvalidStart:
      return "invalid start";
    case PlanStatus::kInvalidGoal:
      return "invalid goal";
  }
  return "unknown";
}

void SeedPlanners(std::uint64_t seed) { ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(seed)); }

double InflationRadius(const field::RobotConfig& robot, const PlannerOptions& options) {
  return robot.width_m / 2.0 + options.clearance_m;
}

std::vector<Eigen::Vector3d> StopPoints(const std::vector<Eigen::Vector2d>& path, double spacing_m,
                                        double goal_heading_deg) {
  std::vector<Eigen::Vector3d> stops;
  if (spacing_m <= 0.0 || path.size() < 2) return stops;
  const double length_m = PathLength(path);
  double next_m = spacing_m;  // arc length of the next stop
  double walked_m = 0.0;      // arc length at the start of the segment
  for (size_t i = 1; i < path.size(); ++i) {
    const double segment_m = (path[i] - path[i - 1]).norm();
    const double heading_deg = HeadingDeg(path[i - 1], path[i]);
    // Stops strictly inside the path; the goal gets its own stop below.
    while (next_m < walked_m + segment_m && next_m < length_m - 1e-9) {
      const Eigen::Vector2d p =
          path[i - 1] + (path[i] - path[i - 1]) * ((next_m - walked_m) / segment_m);
      stops.emplace_back(p.x(), p.y(), heading_deg);
      next_m += spacing_m;
    }
    walked_m += segment_m;
  }
  stops.emplace_back(path.back().x(), path.back().y(), goal_heading_deg);
  return stops;
}

double DriveTime(const field::DriveConfig& drive, double distance_m) {
  if (distance_m <= 0.0) return 0.0;
  const double v = drive.cruise_speed_mps, a = drive.accel_mps2;
  if (a <= 0.0) return distance_m / v;  // no ramp configured: cruise speed at once
  const double ramps_m = v * v / a;     // accelerating plus braking distance
  if (distance_m >= ramps_m) return distance_m / v + v / a;
  return 2.0 * std::sqrt(distance_m / a);  // triangular: never reaches cruise speed
}

double TravelTime(const field::DriveConfig& drive, const std::vector<Eigen::Vector2d>& path,
                  double start_heading_deg, double goal_heading_deg) {
  double time_s = 0.0, heading_deg = start_heading_deg;
  const double turn_rate_dps = drive.turn_rate_dps;
  for (size_t i = 1; i < path.size(); ++i) {
    const double distance_m = (path[i] - path[i - 1]).norm();
    if (distance_m <= 1e-9) continue;
    const double segment_deg = HeadingDeg(path[i - 1], path[i]);
    if (turn_rate_dps > 0.0) time_s += TurnDeg(heading_deg, segment_deg) / turn_rate_dps;
    time_s += DriveTime(drive, distance_m);
    heading_deg = segment_deg;
  }
  if (turn_rate_dps > 0.0) time_s += TurnDeg(heading_deg, goal_heading_deg) / turn_rate_dps;
  return time_s;
}

Planner::Planner(const field::RobotConfig& robot, const PlannerOptions& options)
    : robot_(robot), options_(options), inflation_radius_m_(InflationRadius(robot, options)) {
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
}

void Planner::SetMap(const mapping::ObjectMap& map) {
  SetGrid(map.ToGrid(options_.grid_cell_m, options_.grid_min_z_m, options_.grid_max_z_m));
}

void Planner::SetGrid(const mapping::OccupancyGrid2D& grid) {
  grid_ = grid;
  // Distance (in cells, centre to centre) from every cell to the nearest occupied one.
  cv::Mat free_cells(grid.height, grid.width, CV_8UC1);
  for (int row = 0; row < grid.height; ++row) {
    for (int col = 0; col < grid.width; ++col) {
      free_cells.at<std::uint8_t>(row, col) =
          grid.At(col, row) == mapping::OccupancyGrid2D::kOccupied ? 0 : 1;
    }
  }
  cv::Mat distance_cells;
  cv::distanceTransform(free_cells, distance_cells, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  // Blocked when the disc may reach the occupied cell: the cell's half diagonal added.
  const double reach_cells = inflation_radius_m_ / grid.cell_m + std::sqrt(0.5);
  blocked_.assign(grid.cells.size(), 0);
  for (int row = 0; row < grid.height; ++row) {
    for (int col = 0; col < grid.width; ++col) {
      blocked_[static_cast<size_t>(row) * grid.width + col] =
          distance_cells.at<float>(row, col) < reach_cells ? 1 : 0;
    }
  }
}

bool Planner::IsClear(const Eigen::Vector2d& p_m) const {
  const std::optional<size_t> index = grid_.IndexOf(p_m);
  return index.has_value() && blocked_[*index] == 0;
}

PlanResult Planner::Plan(const PlanRequest& request) const {
  if (grid_.cells.empty()) throw std::invalid_argument("Planner::Plan: no map set");
  PlanResult result;
  const Eigen::Vector2d start(request.start_x_m, request.start_y_m);
  const Eigen::Vector2d goal(request.goal_x_m, request.goal_y_m);

  // Space: the grid's extent in R².
  auto space = std::make_shared<ob::RealVectorStateSpace>(2);
  ob::RealVectorBounds bounds(2);
  bounds.setLow(0, grid_.origin_m.x());
  bounds.setLow(1, grid_.origin_m.y());
  bounds.setHigh(0, grid_.origin_m.x() + grid_.width * grid_.cell_m);
  bounds.setHigh(1, grid_.origin_m.y() + grid_.height * grid_.cell_m);
  space->setBounds(bounds);
  og::SimpleSetup setup(space);
  ob::PlannerPtr planner = MakePlanner(request.planner, setup.getSpaceInformation());
  if (!IsClear(start)) {
    result.status = PlanStatus::kInvalidStart;
    return result;
  }
  if (!IsClear(goal)) {
    result.status = PlanStatus::kInvalidGoal;
    return result;
  }

  // Validity: one lookup in the inflated grid; motions checked every check_resolution_m.
  setup.setStateValidityChecker([this](const ob::State* state) {
    const auto* s = state->as<ob::RealVectorStateSpace::StateType>();
    return IsClear(Eigen::Vector2d(s->values[0], s->values[1]));
  });
  const double step_m =
      options_.check_resolution_m > 0 ? options_.check_resolution_m : grid_.cell_m / 4;
  setup.getSpaceInformation()->setStateValidityCheckingResolution(step_m /
                                                                  space->getMaximumExtent());
  ob::ScopedState<ob::RealVectorStateSpace> start_state(space), goal_state(space);
  start_state[0] = start.x();
  start_state[1] = start.y();
  goal_state[0] = goal.x();
  goal_state[1] = goal.y();
  setup.setStartAndGoalStates(start_state, goal_state);
  setup.setPlanner(planner);

  // Solve, then simplify with what is left of the budget.
  const ob::PlannerStatus status =
      setup.solve(ob::timedPlannerTerminationCondition(request.time_budget_s));
  if (status == ob::PlannerStatus::EXACT_SOLUTION) {
    result.status = PlanStatus::kSolved;
  } else if (status == ob::PlannerStatus::APPROXIMATE_SOLUTION) {
    result.status = PlanStatus::kApproximate;
  } else if (status == ob::PlannerStatus::INVALID_START) {
    result.status = PlanStatus::kInvalidStart;
  } else if (status == ob::PlannerStatus::INVALID_GOAL) {
    result.status = PlanStatus::kInvalidGoal;
  } else {
    result.status = PlanStatus::kTimedOut;
  }
  if (result.status != PlanStatus::kSolved && result.status != PlanStatus::kApproximate) {
    return result;
  }
  if (request.planner == "rrtconnect") {
    const double left_s =
        std::max(0.005, request.time_budget_s - setup.getLastPlanComputationTime());
    setup.simplifySolution(left_s);
  }

  // Path, stops and timing.
  const og::PathGeometric& path = setup.getSolutionPath();
  for (size_t i = 0; i < path.getStateCount(); ++i) {
    const auto* s = path.getState(i)->as<ob::RealVectorStateSpace::StateType>();
    result.path.emplace_back(s->values[0], s->values[1]);
  }
  result.length_m = PathLength(result.path);
  result.travel_time_s =
      TravelTime(robot_.drive, result.path, request.start_heading_deg, request.goal_heading_deg);
  result.stops = StopPoints(result.path, options_.stop_spacing_m, request.goal_heading_deg);
  return result;
}

}  // namespace slamo::planning
