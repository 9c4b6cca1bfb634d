#include "planning/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>

#include <ompl/base/MotionValidator.h>
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

#include "platform/drive_base.h"

namespace slamo::planning {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

using platform::kPi;

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

// Length of the two segments meeting at q.
double Corner(const Eigen::Vector2d& a, const Eigen::Vector2d& q, const Eigen::Vector2d& b) {
  return (q - a).norm() + (b - q).norm();
}

bool Contains(const std::vector<int>& ids, int id) {
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

}  // namespace

double PathLength(const std::vector<Eigen::Vector2d>& path) {
  double length_m = 0.0;
  for (size_t i = 1; i < path.size(); ++i) length_m += (path[i] - path[i - 1]).norm();
  return length_m;
}

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
  const double max_z = options_.grid_max_z_m > 0.0 ? options_.grid_max_z_m : robot_.height_m;
  SetGrid(map.ToGrid(options_.grid_cell_m, options_.grid_min_z_m, max_z));
}

void Planner::SetMap(const mapping::ObjectMap& map,
                     const std::vector<mapping::MappedObject>& objects,
                     const std::vector<int>& ignore_object_ids) {
  std::vector<mapping::MappedObject> obstacles;
  for (const mapping::MappedObject& o : objects) {
    if (!Contains(ignore_object_ids, o.id) && !Contains(options_.ignore_object_ids, o.id)) {
      obstacles.push_back(o);
    }
  }
  mapping::ObjectMap without = map;  // unchanged objects cost nothing in SetObjects()
  without.SetObjects(obstacles);
  SetMap(without);
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

double Planner::check_step_m() const {
  return options_.check_resolution_m > 0 ? options_.check_resolution_m : grid_.cell_m / 4;
}

namespace {

// OMPL's motion checks through Planner::SegmentIsClear().
class GridMotionValidator : public ob::MotionValidator {
 public:
  GridMotionValidator(const ob::SpaceInformationPtr& si, const Planner& planner)
      : ob::MotionValidator(si), planner_(planner) {}

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const bool clear = planner_.SegmentIsClear(Point(s1), Point(s2));
    clear ? ++valid_ : ++invalid_;
    return clear;
  }

  // The last valid state: the last clear point every check step before the first blocked one.
  bool checkMotion(const ob::State* s1, const ob::State* s2,
                   std::pair<ob::State*, double>& last_valid) const override {
    if (checkMotion(s1, s2)) return true;
    const Eigen::Vector2d a = Point(s1), b = Point(s2);
    const int steps =
        std::max(1, static_cast<int>(std::ceil((b - a).norm() / planner_.check_step_m())));
    double t = 0.0;
    for (int k = 1; k <= steps; ++k) {
      const double next = static_cast<double>(k) / steps;
      if (!planner_.SegmentIsClear(a, a + (b - a) * next)) break;
      t = next;
    }
    if (last_valid.first != nullptr) si_->getStateSpace()->interpolate(s1, s2, t, last_valid.first);
    last_valid.second = t;
    return false;
  }

 private:
  static Eigen::Vector2d Point(const ob::State* state) {
    const auto* s = state->as<ob::RealVectorStateSpace::StateType>();
    return {s->values[0], s->values[1]};
  }

  const Planner& planner_;
};

}  // namespace

bool Planner::SegmentIsClear(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
  if (options_.check_resolution_m > 0) {  // sampled
    const double step_m = options_.check_resolution_m;
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step_m)));
    for (int k = 0; k <= steps; ++k) {
      if (!IsClear(a + (b - a) * (static_cast<double>(k) / steps))) return false;
    }
    return true;
  }
  // Exact: every cell the segment crosses (Amanatides and Woo's traversal), both side cells
  // where it passes through a cell corner.
  if (grid_.cells.empty()) return false;
  auto blocked = [this](long col, long row) {
    if (col < 0 || row < 0 || col >= grid_.width || row >= grid_.height) return true;
    return blocked_[static_cast<size_t>(row) * grid_.width + static_cast<size_t>(col)] != 0;
  };
  const Eigen::Vector2d pa = (a - grid_.origin_m) / grid_.cell_m;
  const Eigen::Vector2d pb = (b - grid_.origin_m) / grid_.cell_m;
  long col = static_cast<long>(std::floor(pa.x())), row = static_cast<long>(std::floor(pa.y()));
  const long end_col = static_cast<long>(std::floor(pb.x()));
  const long end_row = static_cast<long>(std::floor(pb.y()));
  if (blocked(col, row) || blocked(end_col, end_row)) return false;
  const double dx = pb.x() - pa.x(), dy = pb.y() - pa.y();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const long step_col = dx > 0 ? 1 : -1, step_row = dy > 0 ? 1 : -1;
  const double delta_x = dx != 0 ? 1.0 / std::abs(dx) : kInf;
  const double delta_y = dy != 0 ? 1.0 / std::abs(dy) : kInf;
  double next_x = dx > 0 ? (col + 1 - pa.x()) / dx : dx < 0 ? (pa.x() - col) / -dx : kInf;
  double next_y = dy > 0 ? (row + 1 - pa.y()) / dy : dy < 0 ? (pa.y() - row) / -dy : kInf;
  constexpr double kTie = 1e-12;
  while (std::min(next_x, next_y) <= 1.0) {
    if (next_x < next_y - kTie) {
      col += step_col;
      next_x += delta_x;
    } else if (next_y < next_x - kTie) {
      row += step_row;
      next_y += delta_y;
    } else {  // through a corner
      if (blocked(col + step_col, row) || blocked(col, row + step_row)) return false;
      col += step_col;
      row += step_row;
      next_x += delta_x;
      next_y += delta_y;
    }
    if (blocked(col, row)) return false;
  }
  return true;
}

bool Planner::PathIsClear(const std::vector<Eigen::Vector2d>& path, size_t from_index) const {
  if (from_index >= path.size()) return false;
  if (!IsClear(path[from_index])) return false;
  for (size_t i = from_index + 1; i < path.size(); ++i) {
    if (!SegmentIsClear(path[i - 1], path[i])) return false;
  }
  return true;
}

std::vector<Eigen::Vector2d> Planner::Shorten(std::vector<Eigen::Vector2d> path,
                                              int subdivisions) const {
  if (path.size() < 3) return path;
  // Drop vertices: from each kept vertex, jump to the farthest one in sight.
  auto pull = [this](const std::vector<Eigen::Vector2d>& in) {
    std::vector<Eigen::Vector2d> out = {in.front()};
    size_t i = 0;
    while (i + 1 < in.size()) {
      size_t j = in.size() - 1;
      while (j > i + 1 && !SegmentIsClear(in[i], in[j])) --j;
      out.push_back(in[j]);
      i = j;
    }
    return out;
  };
  // Slide each inner vertex (compass search, steps from two cells down to a millimetre)
  // while the two segments through it get shorter and stay clear.
  const double cell_m = grid_.cell_m > 0 ? grid_.cell_m : 0.02;
  const double kDiag = std::sqrt(0.5);
  const Eigen::Vector2d kDirections[8] = {{1, 0},          {-1, 0},         {0, 1},
                                          {0, -1},         {kDiag, kDiag},  {kDiag, -kDiag},
                                          {-kDiag, kDiag}, {-kDiag, -kDiag}};
  auto slide = [&](std::vector<Eigen::Vector2d>& p) {
    for (size_t i = 1; i + 1 < p.size(); ++i) {
      const Eigen::Vector2d a = p[i - 1], b = p[i + 1];
      for (double step_m = 2 * cell_m; step_m >= 0.001; step_m /= 2) {
        for (int moves = 0; moves < 32; ++moves) {
          bool moved = false;
          const double current_m = Corner(a, p[i], b);
          for (const Eigen::Vector2d& d : kDirections) {
            const Eigen::Vector2d q = p[i] + step_m * d;
            if (Corner(a, q, b) < current_m - 1e-9 && SegmentIsClear(a, q) &&
                SegmentIsClear(q, b)) {
              p[i] = q;
              moved = true;
              break;
            }
          }
          if (!moved) break;
        }
      }
    }
  };
  path = pull(path);
  for (int level = 0; level <= subdivisions; ++level) {
    if (level > 0) {  // a vertex between every two, so the path can bend round curves
      std::vector<Eigen::Vector2d> finer = {path.front()};
      for (size_t i = 1; i < path.size(); ++i) {
        finer.push_back((path[i - 1] + path[i]) / 2);
        finer.push_back(path[i]);
      }
      path = std::move(finer);
    }
    for (int round = 0; round < 4 && path.size() > 2; ++round) {
      const double before_m = PathLength(path);
      slide(path);
      path = pull(path);
      if (before_m - PathLength(path) < 1e-4) break;
    }
  }
  return path;
}

PlanResult Planner::Replan(const PlanRequest& request, const std::vector<Eigen::Vector2d>& path,
                           size_t next_index) const {
  const Eigen::Vector2d robot(request.start_x_m, request.start_y_m);
  const Eigen::Vector2d goal(request.goal_x_m, request.goal_y_m);
  if (next_index < path.size() && (path.back() - goal).norm() < 1e-6 && IsClear(robot) &&
      SegmentIsClear(robot, path[next_index]) && PathIsClear(path, next_index)) {
    PlanResult result;
    result.status = PlanStatus::kSolved;
    result.path.push_back(robot);
    for (size_t i = next_index; i < path.size(); ++i) {
      if ((path[i] - result.path.back()).norm() > 1e-9) result.path.push_back(path[i]);
    }
    if (result.path.size() < 2) result.path.push_back(path.back());
    result.length_m = PathLength(result.path);
    result.travel_time_s =
        TravelTime(robot_.drive, result.path, request.start_heading_deg, request.goal_heading_deg);
    result.stops = StopPoints(result.path, options_.stop_spacing_m, request.goal_heading_deg);
    return result;
  }
  PlanResult result = Plan(request);
  result.replanned = true;
  return result;
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

  // Validity: one lookup in the inflated grid; motions through SegmentIsClear().
  setup.setStateValidityChecker([this](const ob::State* state) {
    const auto* s = state->as<ob::RealVectorStateSpace::StateType>();
    return IsClear(Eigen::Vector2d(s->values[0], s->values[1]));
  });
  const double step_m = check_step_m();
  setup.getSpaceInformation()->setStateValidityCheckingResolution(step_m /
                                                                  space->getMaximumExtent());
  setup.getSpaceInformation()->setMotionValidator(
      std::make_shared<GridMotionValidator>(setup.getSpaceInformation(), *this));
  ob::ScopedState<ob::RealVectorStateSpace> start_state(space), goal_state(space);
  start_state[0] = start.x();
  start_state[1] = start.y();
  goal_state[0] = goal.x();
  goal_state[1] = goal.y();
  setup.setStartAndGoalStates(start_state, goal_state);
  setup.setPlanner(planner);

  // Solve, then simplify with what is left of the budget. RRTConnect keeps the first path it
  // finds, which may go the long way round an obstacle: it gets several attempts within the
  // budget, each simplified and shortened, and the shortest wins.
  const bool rrtconnect = request.planner == "rrtconnect";
  const int attempts = rrtconnect ? std::max(1, options_.rrtconnect_attempts) : 1;
  const auto began = std::chrono::steady_clock::now();
  auto left_s = [&] {
    return request.time_budget_s -
           std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  };
  const bool deterministic = request.max_iterations > 0;
  const double guard_s = std::max(1.0, 20.0 * request.time_budget_s);
  // Stops after max_iterations evaluations (the planners evaluate it once per iteration), or at
  // the wall-clock guard.
  const auto iterations = [&](int limit) {
    auto count = std::make_shared<int>(0);
    return ob::plannerOrTerminationCondition(
        ob::PlannerTerminationCondition([count, limit] { return ++*count > limit; }),
        ob::timedPlannerTerminationCondition(guard_s));
  };
  double best_m = std::numeric_limits<double>::infinity();
  for (int attempt = 0; attempt < attempts; ++attempt) {
    if (attempt > 0) {
      if (!deterministic && left_s() <= 0.0) break;
      if (deterministic && result.status != PlanStatus::kSolved) break;
      setup.clear();
    }
    const ob::PlannerStatus status =
        deterministic ? setup.solve(iterations(request.max_iterations))
                      : setup.solve(ob::timedPlannerTerminationCondition(std::max(left_s(), 1e-4)));
    PlanStatus attempt_status = PlanStatus::kTimedOut;
    if (status == ob::PlannerStatus::EXACT_SOLUTION) {
      attempt_status = PlanStatus::kSolved;
    } else if (status == ob::PlannerStatus::APPROXIMATE_SOLUTION) {
      attempt_status = PlanStatus::kApproximate;
    } else if (status == ob::PlannerStatus::INVALID_START) {
      attempt_status = PlanStatus::kInvalidStart;
    } else if (status == ob::PlannerStatus::INVALID_GOAL) {
      attempt_status = PlanStatus::kInvalidGoal;
    }
    if (attempt == 0) result.status = attempt_status;
    if (attempt_status != PlanStatus::kSolved && attempt_status != PlanStatus::kApproximate) {
      continue;
    }
    if (attempt_status == PlanStatus::kApproximate && result.status == PlanStatus::kSolved) {
      continue;  // an earlier attempt found a path to the goal
    }
    if (rrtconnect) {
      if (deterministic) {
        setup.simplifySolution(ob::timedPlannerTerminationCondition(guard_s));
      } else {
        setup.simplifySolution(std::max(0.005, left_s()));
      }
    }
    std::vector<Eigen::Vector2d> points;
    const og::PathGeometric& path = setup.getSolutionPath();
    for (size_t i = 0; i < path.getStateCount(); ++i) {
      const auto* s = path.getState(i)->as<ob::RealVectorStateSpace::StateType>();
      points.emplace_back(s->values[0], s->values[1]);
    }
    if (rrtconnect && options_.shorten && attempt_status == PlanStatus::kSolved) {
      points = Shorten(std::move(points));
    }
    const double length_m = PathLength(points);
    if (attempt_status == PlanStatus::kSolved && result.status != PlanStatus::kSolved) {
      best_m = std::numeric_limits<double>::infinity();  // a path to the goal beats any other
      result.status = PlanStatus::kSolved;
    }
    if (length_m < best_m) {
      best_m = length_m;
      result.path = std::move(points);
    }
    if (attempt_status != PlanStatus::kSolved) break;  // approximate: no more attempts
  }
  if (result.path.empty()) return result;

  // Stops and timing.
  result.length_m = PathLength(result.path);
  result.travel_time_s =
      TravelTime(robot_.drive, result.path, request.start_heading_deg, request.goal_heading_deg);
  result.stops = StopPoints(result.path, options_.stop_spacing_m, request.goal_heading_deg);
  return result;
}

}  // namespace slamo::planning
