#include "platform/sim/sim_field.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "field_configs/summary.h"
#include "platform/field_geometry.h"

namespace slamo::platform {
namespace {

using Eigen::Vector2d;

// Whether an object lies on the floor (not stacked on a structure, not held, not in a goal).
bool OnFloor(const SimObject& o) {
  return !o.held && o.in_goal < 0 && o.center_m.z() - o.type->height_m / 2.0 < 0.05;
}

// Whether an object rests on a structure's top (a ball on a raised barrier): it lies in no
// floor zone until it comes down.
bool OnStructure(const field::SeasonConfig& season, const SimObject& o) {
  const double bottom = o.center_m.z() - o.type->height_m / 2.0;
  if (o.held || o.in_goal >= 0 || bottom < 1e-3) return false;
  for (const field::Structure& s : season.structures) {
    if (std::abs(s.height_m - bottom) < 0.01 && DistanceToStructure(s, o.center_m.head<2>()) <= 0.0)
      return true;
  }
  return false;
}

// Whether a pusher `height_m` tall moves the object: one on the floor, or one resting on a
// structure's top lower than the pusher's (a robot knocking a ball off a raised barrier).
bool Pushable(const field::SeasonConfig& season, const SimObject& o, double height_m) {
  if (OnFloor(o)) return true;
  return OnStructure(season, o) && o.center_m.z() - o.type->height_m / 2.0 < height_m;
}

// Whether object o cannot be centred at p at its present height: on the floor, a structure it
// does not fit under (PointBlocksObject); raised, a structure reaching above its bottom (a
// ball on a barrier rolls over the barrier's top, not through a goal post).
bool ObjectBlockedAt(const field::SeasonConfig& season, const SimObject& o, const Vector2d& p) {
  const double r = o.type->size_m / 2.0;
  const double bottom = o.center_m.z() - o.type->height_m / 2.0;
  if (bottom < 0.05) return PointBlocksObject(season, p, r, o.type->height_m);
  for (const field::Structure& s : season.structures) {
    if (s.height_m > bottom + 1e-3 && s.z_min_m < bottom + o.type->height_m &&
        DistanceToStructure(s, p) <= r) {
      return true;
    }
  }
  return false;
}

// Oriented rectangles overlap (separating axis test).
bool RectanglesOverlap(const Pose2D& a, double al, double aw, const Pose2D& b, double bl,
                       double bw) {
  const Vector2d axes[4] = {{std::cos(a.theta_rad), std::sin(a.theta_rad)},
                            {-std::sin(a.theta_rad), std::cos(a.theta_rad)},
                            {std::cos(b.theta_rad), std::sin(b.theta_rad)},
                            {-std::sin(b.theta_rad), std::cos(b.theta_rad)}};
  const Vector2d d(b.x_m - a.x_m, b.y_m - a.y_m);
  for (const Vector2d& axis : axes) {
    const double ra =
        al / 2.0 * std::abs(axes[0].dot(axis)) + aw / 2.0 * std::abs(axes[1].dot(axis));
    const double rb =
        bl / 2.0 * std::abs(axes[2].dot(axis)) + bw / 2.0 * std::abs(axes[3].dot(axis));
    if (std::abs(d.dot(axis)) > ra + rb) return false;
  }
  return true;
}

}  // namespace

SimField::SimField(const field::SeasonConfig& season, const field::RobotConfig& robot,
                   field::Alliance alliance, uint64_t seed, const Pose2D& start,
                   const SimDriveOptions& drive_options, const SimFieldOptions& options)
    : season_(season),
      robot_(robot),
      alliance_(alliance),
      options_(options),
      world_(CreateWorld(season_, seed)),
      drive_(robot.drive, drive_options, seed, start) {
  world_.season = &season_;
  for (size_t g = 0; g < season_.goals.size(); ++g) {
    const field::Goal& goal = season_.goals[g];
    if (goal.on_object.empty()) continue;
    const SimObject* nearest = nullptr;
    double best = std::numeric_limits<double>::infinity();
    for (const SimObject& o : world_.objects) {
      if (o.type->name != goal.on_object) continue;
      const double d =
          std::hypot(o.center_m.x() - goal.center_m.x, o.center_m.y() - goal.center_m.y);
      if (d < best) best = d, nearest = &o;
    }
    if (nearest) carriers_.emplace_back(g, nearest->id);
  }
  FollowCarriers();
  drive_.SetFreeSpaceCheck([this](const Pose2D& pose) { return RobotPoseIsFree(pose); });
  if (options_.preload) Preload();
  // An object under the robot at the start is pushed clear of it.
  PushOut(start, robot_.length_m, robot_.width_m, robot_.height_m);
}

void SimField::Step(double dt_s) {
  drive_.Step(dt_s);
  PushOut(drive_.true_pose(), robot_.length_m, robot_.width_m, robot_.height_m);
  for (size_t i = 0; i < world_.opponents.size(); ++i) StepOpponent(i, dt_s);
  Settle();
  FollowCarriers();
  time_s_ += dt_s;
}

void SimField::FollowCarriers() {
  for (const auto& [g, id] : carriers_) {
    for (const SimObject& o : world_.objects) {
      if (o.id != id) continue;
      season_.goals[g].center_m = field::Vec2{o.center_m.x(), o.center_m.y()};
    }
  }
}

void SimField::Settle() {
  // Lowest first, so a whole stack comes down in one pass.
  std::vector<SimObject*> raised;
  for (SimObject& o : world_.objects) {
    if (!o.held && o.in_goal < 0 && o.center_m.z() - o.type->height_m / 2.0 > 1e-3) {
      raised.push_back(&o);
    }
  }
  std::sort(raised.begin(), raised.end(), [](const SimObject* a, const SimObject* b) {
    return a->center_m.z() < b->center_m.z();
  });
  for (SimObject* o : raised) {
    const double bottom = o->center_m.z() - o->type->height_m / 2.0;
    const Vector2d xy = o->center_m.head<2>();
    double support = 0.0;
    for (const SimObject& other : world_.objects) {
      if (&other == o || other.held || other.in_goal >= 0) continue;
      const double top = other.center_m.z() + other.type->height_m / 2.0;
      const double reach = 0.5 * std::max(o->type->size_m, other.type->size_m);
      if (top <= bottom + 1e-3 && (other.center_m.head<2>() - xy).norm() < reach) {
        support = std::max(support, top);
      }
    }
    for (const field::Structure& s : season_.structures) {
      if (s.height_m <= bottom + 1e-3 && DistanceToStructure(s, xy) <= 0.0) {
        support = std::max(support, s.height_m);
      }
    }
    if (support < bottom - 1e-3) o->center_m.z() = support + o->type->height_m / 2.0;
  }
}

bool SimField::RobotPoseIsFree(const Pose2D& pose) const {
  if (!FootprintIsFree(season_, pose, robot_.length_m, robot_.width_m, robot_.height_m))
    return false;
  for (const SimOpponent& o : world_.opponents) {
    if (RectanglesOverlap(pose, robot_.length_m, robot_.width_m, o.pose, o.config.size_m.x,
                          o.config.size_m.y)) {
      return false;
    }
  }
  return CanPushOut(pose, robot_.length_m, robot_.width_m, robot_.height_m);
}

bool SimField::OpponentPoseIsFree(size_t index, const Pose2D& pose) const {
  const SimOpponent& me = world_.opponents[index];
  const double l = me.config.size_m.x, w = me.config.size_m.y;
  // Opponents' heights are not configured: they do not pass under raised structures.
  if (!FootprintIsFree(season_, pose, l, w, std::numeric_limits<double>::infinity())) return false;
  if (RectanglesOverlap(pose, l, w, drive_.true_pose(), robot_.length_m, robot_.width_m)) {
    return false;
  }
  for (size_t j = 0; j < world_.opponents.size(); ++j) {
    const SimOpponent& other = world_.opponents[j];
    if (j != index &&
        RectanglesOverlap(pose, l, w, other.pose, other.config.size_m.x, other.config.size_m.y)) {
      return false;
    }
  }
  return CanPushOut(pose, l, w, std::numeric_limits<double>::infinity());
}

std::optional<Vector2d> SimField::PushedPosition(const SimObject& object, const Pose2D& pose,
                                                 double length_m, double width_m) const {
  const double r = object.type->size_m / 2.0;
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  const Vector2d rel(object.center_m.x() - pose.x_m, object.center_m.y() - pose.y_m);
  const Vector2d local(c * rel.x() + s * rel.y(), -s * rel.x() + c * rel.y());
  const Vector2d half(length_m / 2.0, width_m / 2.0);
  const Vector2d closest = local.cwiseMax(-half).cwiseMin(half);
  const double distance = (local - closest).norm();
  if (distance >= r) return object.center_m.head<2>();  // not touching
  Vector2d pushed = local;
  if (distance > 1e-9) {
    pushed = closest + (local - closest) / distance * (r + options_.push_gap_m);
  } else {
    // Centre inside the rectangle: out through the nearest side.
    const double to_side[4] = {half.x() - local.x(), local.x() + half.x(), half.y() - local.y(),
                               local.y() + half.y()};
    const int side = static_cast<int>(std::min_element(to_side, to_side + 4) - to_side);
    const double out = r + options_.push_gap_m;
    if (side == 0) pushed.x() = half.x() + out;
    if (side == 1) pushed.x() = -half.x() - out;
    if (side == 2) pushed.y() = half.y() + out;
    if (side == 3) pushed.y() = -half.y() - out;
  }
  const double limit = season_.HalfSize() - r;
  const auto valid = [&](const Vector2d& in_robot) -> std::optional<Vector2d> {
    Vector2d world(pose.x_m + c * in_robot.x() - s * in_robot.y(),
                   pose.y_m + s * in_robot.x() + c * in_robot.y());
    if (std::abs(world.x()) > limit || std::abs(world.y()) > limit) return std::nullopt;
    if (ObjectBlockedAt(season_, object, world)) return std::nullopt;
    if (OnStructure(season_, object)) {
      // Pushed off the structure's top, it rolls on over the edge and comes to rest on the
      // floor clear of the structure.
      SimObject moved = object;
      moved.center_m.head<2>() = world;
      const Vector2d away = (world - object.center_m.head<2>()).normalized();
      if (!OnStructure(season_, moved) && away.allFinite()) {
        for (int k = 0; k < 50 && PointBlocksObject(season_, world, r, object.type->height_m); ++k)
          world += 0.01 * away;
        if (std::abs(world.x()) > limit || std::abs(world.y()) > limit) return std::nullopt;
      }
    }
    return world;
  };
  if (const auto world = valid(pushed)) return world;
  // Pinned against a wall or structure: a ball rolls along the bumper and out past its
  // nearer side instead (a pinned object only blocks when neither side is free).
  const double side = half.y() + r + options_.push_gap_m;
  const double first = local.y() >= 0.0 ? 1.0 : -1.0;
  for (const double sign : {first, -first}) {
    if (const auto world = valid(Vector2d(std::clamp(local.x(), -half.x(), half.x()), sign * side)))
      return world;
  }
  return std::nullopt;
}

bool SimField::CanPushOut(const Pose2D& pose, double length_m, double width_m,
                          double height_m) const {
  for (const SimObject& o : world_.objects) {
    if (Pushable(season_, o, height_m) && !PushedPosition(o, pose, length_m, width_m)) return false;
  }
  return true;
}

void SimField::PushOut(const Pose2D& pose, double length_m, double width_m, double height_m) {
  for (SimObject& o : world_.objects) {
    if (!Pushable(season_, o, height_m)) continue;
    if (const auto p = PushedPosition(o, pose, length_m, width_m)) {
      o.center_m.head<2>() = *p;
      // Pushed along the floor in under a raised goal's frame (Over Under's nets), it is in
      // the goal, as a released one: scored, and no longer pushed about.
      if (OnFloor(o)) o.in_goal = GoalPushedInto(season_, *p);
    }
  }
}

void SimField::StepOpponent(size_t index, double dt_s) {
  SimOpponent& o = world_.opponents[index];
  const std::vector<field::Vec2>& path = o.config.path_m;
  if (o.next_waypoint >= path.size()) return;  // finished its path
  const Vector2d target(path[o.next_waypoint].x, path[o.next_waypoint].y);
  const Vector2d here(o.pose.x_m, o.pose.y_m);
  const Vector2d to_target = target - here;
  const double step = o.config.speed_mps * dt_s;
  Pose2D next = o.pose;
  if (to_target.norm() > 1e-9) next.theta_rad = std::atan2(to_target.y(), to_target.x());
  const bool arrives = to_target.norm() <= step;
  const Vector2d moved = arrives ? target : here + to_target.normalized() * step;
  next.x_m = moved.x();
  next.y_m = moved.y();
  if (!OpponentPoseIsFree(index, next)) return;  // blocked: wait
  o.pose = next;
  PushOut(o.pose, o.config.size_m.x, o.config.size_m.y, std::numeric_limits<double>::infinity());
  if (arrives) {
    ++o.next_waypoint;
    if (o.next_waypoint >= path.size() && o.config.loop) o.next_waypoint = 0;
  }
}

int SimField::HeldCount() const { return static_cast<int>(held_.size()); }

std::optional<int> SimField::Pick() {
  if (HeldCount() >= robot_.intake.capacity) return std::nullopt;
  const Pose2D& pose = drive_.true_pose();
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  SimObject* best = nullptr;
  double best_gap = std::numeric_limits<double>::infinity();
  for (SimObject& o : world_.objects) {
    if (!OnFloor(o)) continue;
    const Vector2d rel(o.center_m.x() - pose.x_m, o.center_m.y() - pose.y_m);
    const double ahead = c * rel.x() + s * rel.y();
    const double side = -s * rel.x() + c * rel.y();
    const double gap = ahead - o.type->size_m / 2.0 - robot_.length_m / 2.0;  // bumper to edge
    if (gap < -0.01 || gap > robot_.intake.reach_m || std::abs(side) > robot_.width_m / 2.0) {
      continue;
    }
    if (gap < best_gap) best_gap = gap, best = &o;
  }
  if (!best) return std::nullopt;
  best->held = true;
  held_.push_back(best->id);
  Settle();
  return best->id;
}

void SimField::Preload() {
  if (HeldCount() >= robot_.intake.capacity) return;
  const Pose2D& pose = drive_.true_pose();
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  SimObject* best = nullptr;
  double best_d = std::numeric_limits<double>::infinity();
  for (SimObject& o : world_.objects) {
    if (!OnFloor(o) || !field::ScoresFor(season_, o.colour, alliance_)) continue;
    const Vector2d rel(o.center_m.x() - pose.x_m, o.center_m.y() - pose.y_m);
    const double ahead = c * rel.x() + s * rel.y();
    const double side = -s * rel.x() + c * rel.y();
    if (std::abs(ahead) > robot_.length_m / 2.0 || std::abs(side) > robot_.width_m / 2.0) continue;
    if (rel.norm() < best_d) best_d = rel.norm(), best = &o;
  }
  if (!best) return;
  best->held = true;
  held_.push_back(best->id);
}

std::optional<ReleaseResult> SimField::Release() {
  if (held_.empty()) return std::nullopt;
  const int id = held_.front();
  SimObject& o = *std::find_if(world_.objects.begin(), world_.objects.end(),
                               [id](const SimObject& x) { return x.id == id; });
  const Pose2D& pose = drive_.true_pose();
  const double r = o.type->size_m / 2.0;
  const double ahead = robot_.length_m / 2.0 + r + 0.01;
  const Vector2d drop(pose.x_m + ahead * std::cos(pose.theta_rad),
                      pose.y_m + ahead * std::sin(pose.theta_rad));
  ReleaseResult result;
  result.object_id = o.id;
  // Onto a stake standing on an object (a mobile goal) the intake places it: the stake's base
  // within the intake's reach ahead of the bumper (as a pick's near edge), the stake within
  // the goal's radius of the robot's centre line.
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  for (size_t g = 0; g < season_.goals.size() && o.in_goal < 0; ++g) {
    const field::Goal& goal = season_.goals[g];
    if (goal.on_object.empty()) continue;
    const Vector2d rel(goal.center_m.x - pose.x_m, goal.center_m.y - pose.y_m);
    const double gap =
        c * rel.x() + s * rel.y() - CarrierRadius(season_, goal) - robot_.length_m / 2.0;
    const double side = -s * rel.x() + c * rel.y();
    if (gap < -0.01 || gap > robot_.intake.reach_m || std::abs(side) > goal.radius_m) continue;
    o.in_goal = static_cast<int>(g);
    o.center_m =
        Eigen::Vector3d(goal.center_m.x, goal.center_m.y, goal.height_m + o.type->height_m / 2.0);
  }
  for (size_t g = 0; g < season_.goals.size() && o.in_goal < 0; ++g) {
    const field::Goal& goal = season_.goals[g];
    // Into a goal structure only the way objects go in (a tube: through an end).
    if (goal.kind == field::GoalKind::kGoal && goal.on_object.empty() &&
        GoalTakes(goal, drop, pose.theta_rad, o.type->size_m)) {
      o.in_goal = static_cast<int>(g);
      o.center_m = Eigen::Vector3d(drop.x(), drop.y(), goal.height_m + o.type->height_m / 2.0);
      break;
    }
  }
  if (o.in_goal < 0) {
    const double limit = season_.HalfSize() - r;
    if (std::abs(drop.x()) > limit || std::abs(drop.y()) > limit ||
        PointBlocksObject(season_, drop, r, o.type->height_m)) {
      return std::nullopt;  // no room in front: keep holding it
    }
    o.center_m = Eigen::Vector3d(drop.x(), drop.y(), o.type->height_m / 2.0);
  }
  o.held = false;
  held_.erase(held_.begin());
  result.points = ObjectPoints(o, alliance_);
  for (size_t g = 0; g < season_.goals.size(); ++g) {
    const field::Goal& goal = season_.goals[g];
    const bool here = goal.kind == field::GoalKind::kGoal
                          ? o.in_goal == static_cast<int>(g)
                          : o.in_goal < 0 && GoalContains(goal, drop);
    if (here) {
      result.goal_index = static_cast<int>(g);
      if (goal.kind == field::GoalKind::kGoal) break;
    }
  }
  return result;
}

int SimField::ObjectPoints(const SimObject& object, field::Alliance alliance) const {
  if (object.held || !field::ScoresFor(season_, object.colour, alliance)) return 0;
  int best = 0;
  for (size_t g = 0; g < season_.goals.size(); ++g) {
    const field::Goal& goal = season_.goals[g];
    if (goal.alliance != field::Alliance::kNone && goal.alliance != alliance) continue;
    const bool inside = goal.kind == field::GoalKind::kGoal
                            ? object.in_goal == static_cast<int>(g)
                            : object.in_goal < 0 && !OnStructure(season_, object) &&
                                  GoalContains(goal, object.center_m.head<2>());
    if (!inside) continue;
    const auto it = goal.points.find(object.type->name);
    if (it != goal.points.end()) best = std::max(best, it->second);
  }
  return best;
}

int SimField::Score(field::Alliance alliance) const {
  int total = 0;
  for (const SimObject& o : world_.objects) total += ObjectPoints(o, alliance);
  return total;
}

}  // namespace slamo::platform
