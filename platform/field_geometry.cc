#include "platform/field_geometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace slamo::platform {
namespace {

using field::SeasonConfig;
using field::SolidShape;
using field::Structure;

const field::StartTile& StartFor(const field::SeasonConfig& season, field::Alliance alliance,
                                 int index) {
  int seen = 0;
  for (const field::StartTile& s : season.starts) {
    if (s.alliance == alliance && seen++ == index) return s;
  }
  throw std::invalid_argument(season.name + " has no starting tile " + std::to_string(index) +
                              " for that alliance");
}

}  // namespace

double DistanceToStructure(const Structure& s, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = p - Eigen::Vector2d(s.center_m.x, s.center_m.y);
  if (s.shape == SolidShape::kCylinder) return std::max(0.0, d.norm() - s.radius_m);
  const double yaw = s.yaw_deg * kPi / 180.0;
  const double lx = std::cos(yaw) * d.x() + std::sin(yaw) * d.y();
  const double ly = -std::sin(yaw) * d.x() + std::cos(yaw) * d.y();
  const double ex = std::max(0.0, std::abs(lx) - s.size_m.x / 2.0);
  const double ey = std::max(0.0, std::abs(ly) - s.size_m.y / 2.0);
  return std::hypot(ex, ey);
}

bool BlocksRobot(const Structure& s, double height_m) {
  return s.blocks_robot || (s.PassUnder() && height_m >= s.z_min_m);
}

bool PointInBlockingStructure(const SeasonConfig& season, const Eigen::Vector2d& p,
                              double clearance_m, double height_m) {
  for (const Structure& s : season.structures) {
    if (BlocksRobot(s, height_m) && DistanceToStructure(s, p) <= clearance_m) return true;
  }
  return false;
}

bool PointBlocksObject(const SeasonConfig& season, const Eigen::Vector2d& p, double radius_m,
                       double object_height_m) {
  for (const Structure& s : season.structures) {
    const bool blocks = s.blocks_robot || (s.PassUnder() && object_height_m > s.z_min_m);
    if (blocks && DistanceToStructure(s, p) <= radius_m) return true;
  }
  return false;
}

bool GoalContains(const field::Goal& goal, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = p - Eigen::Vector2d(goal.center_m.x, goal.center_m.y);
  if (goal.shape == SolidShape::kCylinder) return d.norm() <= goal.radius_m;
  if (goal.shape == SolidShape::kTriangle) {
    // Inside (or on the edge) when p is on the same side of all three edges.
    const auto cross = [&](const field::Vec2& a, const field::Vec2& b) {
      return (b.x - a.x) * (p.y() - a.y) - (b.y - a.y) * (p.x() - a.x);
    };
    const std::vector<field::Vec2>& v = goal.vertices_m;
    const double c0 = cross(v[0], v[1]), c1 = cross(v[1], v[2]), c2 = cross(v[2], v[0]);
    return (c0 >= 0 && c1 >= 0 && c2 >= 0) || (c0 <= 0 && c1 <= 0 && c2 <= 0);
  }
  const double yaw = goal.yaw_deg * kPi / 180.0;
  const double lx = std::cos(yaw) * d.x() + std::sin(yaw) * d.y();
  const double ly = -std::sin(yaw) * d.x() + std::cos(yaw) * d.y();
  return std::abs(lx) <= goal.size_m.x / 2.0 && std::abs(ly) <= goal.size_m.y / 2.0;
}

std::vector<GoalMouth> GoalMouths(const field::Goal& goal) {
  const Eigen::Vector2d centre(goal.center_m.x, goal.center_m.y);
  if (goal.entry != field::Goal::Entry::kEnds) return {GoalMouth{centre, Eigen::Vector2d::Zero()}};
  const double yaw = goal.yaw_deg * kPi / 180.0;
  const bool along_x = goal.size_m.x >= goal.size_m.y;
  const Eigen::Vector2d axis = along_x ? Eigen::Vector2d(std::cos(yaw), std::sin(yaw))
                                       : Eigen::Vector2d(-std::sin(yaw), std::cos(yaw));
  const double half = 0.5 * std::max(goal.size_m.x, goal.size_m.y);
  return {GoalMouth{centre + half * axis, -axis}, GoalMouth{centre - half * axis, axis}};
}

bool GoalTakes(const field::Goal& goal, const Eigen::Vector2d& drop, double heading_rad,
               double object_size_m) {
  if (!GoalContains(goal, drop)) return false;
  if (goal.entry != field::Goal::Entry::kEnds) return true;
  const Eigen::Vector2d facing(std::cos(heading_rad), std::sin(heading_rad));
  for (const GoalMouth& m : GoalMouths(goal)) {
    if (facing.dot(m.inward) >= std::cos(kEntryAngle_deg * kPi / 180.0) &&
        (drop - m.point_m).dot(m.inward) <= object_size_m) {
      return true;
    }
  }
  return false;
}

double GoalHalfSize(const field::Goal& goal) {
  return goal.shape == SolidShape::kCylinder ? goal.radius_m
                                             : 0.5 * std::min(goal.size_m.x, goal.size_m.y);
}

bool IsGoalStructure(const field::Goal& goal, const field::Structure& s) {
  return std::hypot(s.center_m.x - goal.center_m.x, s.center_m.y - goal.center_m.y) <
         GoalHalfSize(goal);
}

bool GoalIsRaised(const SeasonConfig& season, const field::Goal& goal) {
  if (goal.kind != field::GoalKind::kGoal || !goal.on_object.empty()) return false;
  for (const Structure& s : season.structures) {
    if (s.name == goal.name) return s.PassUnder();
  }
  bool raised = false;
  for (const Structure& s : season.structures) {
    if (!IsGoalStructure(goal, s)) continue;
    if (s.blocks_robot) return false;
    raised = raised || s.PassUnder();
  }
  return raised;
}

int GoalPushedInto(const SeasonConfig& season, const Eigen::Vector2d& p) {
  for (size_t g = 0; g < season.goals.size(); ++g) {
    const field::Goal& goal = season.goals[g];
    if (goal.entry != field::Goal::Entry::kEnds && GoalContains(goal, p) &&
        GoalIsRaised(season, goal)) {
      return static_cast<int>(g);
    }
  }
  return -1;
}

double CarrierRadius(const SeasonConfig& season, const field::Goal& goal) {
  if (goal.on_object.empty()) return 0.0;
  const field::ObjectType* type = season.FindObjectType(goal.on_object);
  return type ? type->size_m / 2.0 : 0.0;
}

bool FootprintIsFree(const SeasonConfig& season, const Pose2D& pose, double length_m,
                     double width_m, double height_m) {
  // The structures that block this robot and could reach the footprint (the footprint lies
  // within its half diagonal of the pose, a structure within its own of its centre; the
  // millimetre covers rounding), each with its rotation worked out once: the same test as
  // DistanceToStructure(st, p) <= 0 (inside or on the edge), with fewer sines and cosines.
  struct Near {
    Eigen::Vector2d centre;
    bool cylinder;
    double radius_m, cos_yaw, sin_yaw, half_x, half_y;
  };
  Near near[16];
  std::vector<Near> more;
  int count = 0;
  const double reach = 0.5 * std::hypot(length_m, width_m) + 1e-3;
  for (const Structure& st : season.structures) {
    if (!BlocksRobot(st, height_m)) continue;
    const Eigen::Vector2d centre(st.center_m.x, st.center_m.y);
    const bool cylinder = st.shape == SolidShape::kCylinder;
    const double extent = cylinder ? st.radius_m : 0.5 * std::hypot(st.size_m.x, st.size_m.y);
    if ((centre - Eigen::Vector2d(pose.x_m, pose.y_m)).norm() > reach + extent) continue;
    const double yaw = st.yaw_deg * kPi / 180.0;
    const Near n{centre,        cylinder,          st.radius_m,      std::cos(yaw),
                 std::sin(yaw), st.size_m.x / 2.0, st.size_m.y / 2.0};
    if (!cylinder) {
      // A long box (a barrier) passes the test above from far along its length: in its own
      // frame the footprint's points lie within `reach` of the pose along each axis.
      const Eigen::Vector2d d = Eigen::Vector2d(pose.x_m, pose.y_m) - centre;
      if (std::abs(n.cos_yaw * d.x() + n.sin_yaw * d.y()) > n.half_x + reach ||
          std::abs(-n.sin_yaw * d.x() + n.cos_yaw * d.y()) > n.half_y + reach) {
        continue;
      }
    }
    if (count < 16) {
      near[count++] = n;
    } else {
      more.push_back(n);
    }
  }
  const double half = season.HalfSize();
  // Nothing within reach and the footprint well inside the perimeter: every point is free.
  if (count == 0 && std::abs(pose.x_m) + reach < half && std::abs(pose.y_m) + reach < half) {
    return true;
  }
  const auto inside = [](const Near& n, const Eigen::Vector2d& p) {
    const Eigen::Vector2d d = p - n.centre;
    if (n.cylinder) return d.norm() - n.radius_m <= 0.0;
    const double lx = n.cos_yaw * d.x() + n.sin_yaw * d.y();
    const double ly = -n.sin_yaw * d.x() + n.cos_yaw * d.y();
    return std::abs(lx) - n.half_x <= 0.0 && std::abs(ly) - n.half_y <= 0.0;
  };
  const double c = std::cos(pose.theta_rad);
  const double s = std::sin(pose.theta_rad);
  // Sample the footprint's outline and centre line densely enough for the thinnest posts.
  const double step = 0.02;
  const int nx = static_cast<int>(std::ceil(length_m / step));
  const int ny = static_cast<int>(std::ceil(width_m / step));
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      if (i != 0 && i != nx && j != 0 && j != ny && j != ny / 2) continue;
      const double lx = -length_m / 2.0 + length_m * i / nx;
      const double ly = -width_m / 2.0 + width_m * j / ny;
      const Eigen::Vector2d p(pose.x_m + c * lx - s * ly, pose.y_m + s * lx + c * ly);
      if (std::abs(p.x()) > half || std::abs(p.y()) > half) return false;
      for (int k = 0; k < count; ++k) {
        if (inside(near[k], p)) return false;
      }
      for (const Near& n : more) {
        if (inside(n, p)) return false;
      }
    }
  }
  return true;
}

Eigen::Vector3d LandmarkCentre(const field::SeasonConfig& season, const field::Landmark& l) {
  if (l.shape != field::LandmarkShape::kDisc && l.shape != field::LandmarkShape::kSquare)
    return Eigen::Vector3d(l.position_m.x, l.position_m.y, l.height_m);
  // A plate: on the inner face of the nearest wall.
  const double inset = season.HalfSize() - 0.005;
  double x = l.position_m.x, y = l.position_m.y;
  if (std::abs(l.position_m.x) >= std::abs(l.position_m.y)) {
    x = std::clamp(x, -inset, inset);
  } else {
    y = std::clamp(y, -inset, inset);
  }
  return Eigen::Vector3d(x, y, l.height_m);
}

std::vector<Eigen::Vector2d> SurveyedMarkers(const field::SeasonConfig& field) {
  std::vector<Eigen::Vector2d> out;
  for (const field::Landmark& l : field.landmarks)
    out.push_back(LandmarkCentre(field, l).head<2>());
  return out;
}

std::vector<int> MarkerIds(const field::SeasonConfig& field) {
  std::vector<int> marker_id(field.landmarks.size(), -1);
  for (size_t i = 0; i < field.landmarks.size(); ++i) {
    const auto same = std::count_if(
        field.landmarks.begin(), field.landmarks.end(),
        [&](const field::Landmark& l) { return l.colour == field.landmarks[i].colour; });
    if (same == 1) marker_id[i] = static_cast<int>(i);
  }
  return marker_id;
}

Pose2D StartPose(const field::SeasonConfig& season, field::Alliance alliance, int start_index) {
  const field::StartTile& start = StartFor(season, alliance, start_index);
  return {start.center_m.x, start.center_m.y, start.heading_deg * kPi / 180.0};
}

}  // namespace slamo::platform
