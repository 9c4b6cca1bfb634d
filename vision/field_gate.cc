#include "vision/field_gate.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vision/detector.h"

namespace slamo::vision {
namespace {

// The robot-frame point where the ray through pixel (u, v) meets the plane z = height_m, and
// its depth along the camera's axis; nullopt when the ray does not reach the plane.
std::optional<std::pair<Eigen::Vector3d, double>> RayOnPlane(const CameraModel& camera, double u,
                                                             double v, double height_m) {
  const Eigen::Vector3d origin = camera.CameraToRobot(Eigen::Vector3d::Zero());
  const Eigen::Vector3d direction = camera.CameraToRobot(camera.BackProject(u, v, 1.0)) - origin;
  if (std::abs(direction.z()) < 1e-9) return std::nullopt;
  const double s = (height_m - origin.z()) / direction.z();  // the depth: BackProject's z = 1
  if (!(s > 0.0)) return std::nullopt;
  return std::make_pair(Eigen::Vector3d(origin + s * direction), s);
}

// The structures of FieldBounds::solids (see there for what is left out).
void AddSolids(const field::SeasonConfig& season, FieldBounds* bounds) {
  for (const field::Structure& st : season.structures) {
    if (st.colour.empty() || st.shape == field::SolidShape::kTriangle) continue;
    FieldBounds::Solid solid;
    solid.colour = st.colour;
    solid.cylinder = st.shape == field::SolidShape::kCylinder;
    solid.centre_m = {st.center_m.x, st.center_m.y};
    solid.half_size_m = {st.size_m.x / 2.0, st.size_m.y / 2.0};
    solid.radius_m = st.radius_m;
    solid.yaw_rad = st.yaw_deg * 3.14159265358979323846 / 180.0;
    solid.z_min_m = st.z_min_m;
    solid.z_max_m = st.height_m;
    bool hollow = false;
    for (const field::Goal& g : season.goals) {
      if (g.kind != field::GoalKind::kGoal) continue;
      const double reach = g.radius_m > 0.0 ? g.radius_m : std::hypot(g.size_m.x, g.size_m.y) / 2;
      if (solid.DistanceOutside({g.center_m.x, g.center_m.y}) > reach) continue;
      if (g.entry == field::Goal::Entry::kEnds || !g.on_object.empty()) hollow = true;
      for (const auto& [type_name, points] : g.points) {
        const field::ObjectType* type = season.FindObjectType(type_name);
        if (type && type->shape == field::ObjectShape::kTorus) hollow = true;
      }
    }
    for (const field::ObjectPlacement& p : season.objects) {
      const field::ObjectType* type = season.FindObjectType(p.type);
      if (!type || p.z_m >= solid.z_max_m) continue;  // above it: outside the solid
      Eigen::Vector2d at;
      double spread = type->size_m / 2.0;
      if (p.position_m) {
        at = {p.position_m->x, p.position_m->y};
      } else if (p.region && p.z_m > 0.0) {  // drawn on the floor: never inside a structure
        at = {(p.region->min_m.x + p.region->max_m.x) / 2.0,
              (p.region->min_m.y + p.region->max_m.y) / 2.0};
        spread += std::hypot(p.region->max_m.x - p.region->min_m.x,
                             p.region->max_m.y - p.region->min_m.y) /
                  2.0;
      } else {
        continue;
      }
      if (solid.DistanceOutside(at) < spread && p.z_m + type->height_m > solid.z_min_m) {
        hollow = true;
      }
    }
    if (!hollow) bounds->solids.push_back(solid);
  }
}

}  // namespace

FieldBounds FieldBoundsOf(const field::SeasonConfig& season) {
  FieldBounds bounds;
  bounds.half_size_m = season.HalfSize();
  bounds.floor_top_m = season.field.wall_height_m;
  double tallest = 0.0;
  for (const field::ObjectType& type : season.object_types)
    tallest = std::max(tallest, type.height_m);
  bounds.floor_top_m = std::max(bounds.floor_top_m, tallest);
  const auto add = [&](Eigen::Vector2d centre, Eigen::Vector2d half, double top) {
    bounds.raised.push_back({centre - half, centre + half, top});
  };
  for (const field::ObjectPlacement& p : season.objects) {
    const field::ObjectType* type = season.FindObjectType(p.type);
    if (!type || p.z_m <= 0.0) continue;
    const double top = p.z_m + type->height_m;
    if (p.position_m) {
      add({p.position_m->x, p.position_m->y}, Eigen::Vector2d::Constant(type->size_m / 2.0), top);
    } else if (p.region) {
      const Eigen::Vector2d lo(p.region->min_m.x, p.region->min_m.y);
      const Eigen::Vector2d hi(p.region->max_m.x, p.region->max_m.y);
      add((lo + hi) / 2.0, (hi - lo) / 2.0 + Eigen::Vector2d::Constant(type->size_m / 2.0), top);
    }
  }
  for (const field::Goal& g : season.goals) {
    if (g.kind != field::GoalKind::kGoal) continue;
    // The goal's footprint (its bounding square when turned), up to its opening plus the
    // tallest object.
    const double r = g.radius_m > 0.0 ? g.radius_m : std::hypot(g.size_m.x, g.size_m.y) / 2.0;
    add({g.center_m.x, g.center_m.y}, Eigen::Vector2d::Constant(r), g.height_m + tallest);
  }
  AddSolids(season, &bounds);
  return bounds;
}

double FieldBounds::Solid::DistanceOutside(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d d = p - centre_m;
  if (cylinder) return std::max(0.0, d.norm() - radius_m);
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const Eigen::Vector2d local(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  return (local.cwiseAbs() - half_size_m).cwiseMax(0.0).norm();
}

std::optional<Measurement> GroundPlaneMeasurement(const CameraModel& camera,
                                                  const cv::Point2d& centre_px, double radius_px,
                                                  double centre_height_m,
                                                  const MeasurementOptions& options) {
  const auto hit = RayOnPlane(camera, centre_px.x, centre_px.y, centre_height_m);
  if (!hit) return std::nullopt;
  Measurement m;
  m.position_robot_m = hit->first;
  m.depth_m = hit->second;
  m.depth_pixels = 0;
  m.position_camera_m = camera.BackProject(centre_px.x, centre_px.y, hit->second);
  m.range_m = std::hypot(m.position_robot_m.x(), m.position_robot_m.y());
  m.bearing_rad = std::atan2(m.position_robot_m.y(), m.position_robot_m.x());
  // Covariance: the pixel uncertainty through the plane intersection (numerical Jacobian of
  // (u, v) -> (range, bearing)).
  const double sigma_px = options.pixel_sigma_px + options.pixel_sigma_ratio * radius_px;
  Eigen::Matrix2d jacobian;
  constexpr double kStep = 0.5;
  for (int k = 0; k < 2; ++k) {
    const cv::Point2d step = k == 0 ? cv::Point2d(kStep, 0) : cv::Point2d(0, kStep);
    const auto plus =
        RayOnPlane(camera, centre_px.x + step.x, centre_px.y + step.y, centre_height_m);
    const auto minus =
        RayOnPlane(camera, centre_px.x - step.x, centre_px.y - step.y, centre_height_m);
    if (!plus || !minus) return std::nullopt;  // at the horizon: no usable range
    const Eigen::Vector3d& a = plus->first;
    const Eigen::Vector3d& b = minus->first;
    jacobian.col(k) = Eigen::Vector2d(std::hypot(a.x(), a.y()) - std::hypot(b.x(), b.y()),
                                      std::atan2(a.y(), a.x()) - std::atan2(b.y(), b.x())) /
                      (2.0 * kStep);
  }
  m.covariance = sigma_px * sigma_px * jacobian * jacobian.transpose();
  return m;
}

namespace {

// Whether the ray origin + t direction (t > 0) passes through the box [lo, hi].
bool RayMeetsBox(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                 const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t_in = 0.0, t_out = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (std::abs(direction[k]) < 1e-12) {
      if (origin[k] < lo[k] || origin[k] > hi[k]) return false;
      continue;
    }
    double t0 = (lo[k] - origin[k]) / direction[k], t1 = (hi[k] - origin[k]) / direction[k];
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
  }
  return t_in <= t_out;
}

}  // namespace

GateVerdict Judge(const Detection& detection, const CameraModel& camera,
                  const Eigen::Vector3d& robot_pose, const FieldBounds& bounds,
                  const FieldGateOptions& options, const MeasurementOptions& measurement_options) {
  const double c = std::cos(robot_pose.z()), s = std::sin(robot_pose.z());
  const auto to_world = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(robot_pose.x() + c * p.x() - s * p.y(),
                           robot_pose.y() + s * p.x() + c * p.y(), p.z());
  };
  // The boxes objects can be in, grown by `margin_m` across (the pose's and position's
  // uncertainty) and `margin_z_m` upwards (the position's only), from `bottom_m` up (a
  // position below the floor is a poor measurement, not one off the field).
  const auto boxes = [&](double margin_m, double margin_z_m, double bottom_m) {
    std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> out;
    const double h = bounds.half_size_m + margin_m;
    out.emplace_back(Eigen::Vector3d(-h, -h, bottom_m),
                     Eigen::Vector3d(h, h, bounds.floor_top_m + margin_z_m));
    for (const FieldBounds::Column& col : bounds.raised) {
      out.emplace_back(
          Eigen::Vector3d(col.min_m.x() - margin_m, col.min_m.y() - margin_m, bottom_m),
          Eigen::Vector3d(col.max_m.x() + margin_m, col.max_m.y() + margin_m,
                          col.top_m + margin_z_m));
    }
    return out;
  };
  if (detection.measurement) {
    // A position: in one of the boxes, within its uncertainty (range and bearing) and, across,
    // the pose's.
    const Measurement& m = *detection.measurement;
    const Eigen::Vector3d p = to_world(m.position_robot_m);
    const double sigma = std::sqrt(std::max(0.0, m.covariance(0, 0)) +
                                   m.range_m * m.range_m * std::max(0.0, m.covariance(1, 1)));
    const double across = options.sigmas * std::hypot(sigma, options.pose_sigma_m);
    bool inside = false;
    for (const auto& [lo, hi] :
         boxes(across, options.sigmas * sigma, -std::numeric_limits<double>::infinity())) {
      if ((p.array() >= lo.array() - 1e-9).all() && (p.array() <= hi.array()).all()) {
        inside = true;
        break;
      }
    }
    if (!inside) return GateVerdict::kOffField;
    // Without depth the position is the ground plane's, which assumes an object resting on
    // the floor: it says nothing of whether a structure was seen.
    if (m.depth_pixels == 0) return GateVerdict::kOnField;
    // A structure of the detection's colour, where no object can be: the object's centre
    // inside it (a real object touching one has its centre at least its own half-size
    // outside), or the measured surface on it within the depth's uncertainty (a thin post or
    // bar, whose "centre" lands behind it). The pose's uncertainty is left out of the margin:
    // an error of the pose keeps such a detection rather than dropping a real object.
    for (const FieldBounds::Solid& solid : bounds.solids) {
      if (solid.colour != detection.colour || p.z() < solid.z_min_m || p.z() > solid.z_max_m) {
        continue;
      }
      if (solid.DistanceOutside(p.head<2>()) <= 0.0) return GateVerdict::kStructure;
    }
    if (m.position_camera_m.z() > 0.0) {  // the median depth's point
      const Eigen::Vector3d surface = to_world(
          camera.CameraToRobot(m.position_camera_m * (m.depth_m / m.position_camera_m.z())));
      const double t = options.sigmas * sigma;
      for (const FieldBounds::Solid& solid : bounds.solids) {
        // Across, the depth's uncertainty; up and down, none: an object resting on top of a
        // structure of its colour (a ball on a stash) or under one (a triball under a goal's
        // frame) has its surface just beyond it.
        if (solid.colour != detection.colour || surface.z() < solid.z_min_m ||
            surface.z() > solid.z_max_m) {
          continue;
        }
        if (solid.DistanceOutside(surface.head<2>()) <= t) return GateVerdict::kStructure;
      }
    }
    return GateVerdict::kOnField;
  }
  // No position: the ray through the detection's lowest pixel (moved down by the pixel
  // uncertainty, which only makes it reach the floor sooner) must pass through one of the
  // boxes; one that stays above them all looks over the wall.
  double lowest_v = detection.box.y + detection.box.height - 1.0;
  double lowest_u = detection.box.x + detection.box.width / 2.0;
  for (const cv::Point& p : detection.contour) {
    if (p.y >= lowest_v) lowest_v = p.y, lowest_u = p.x;
  }
  lowest_v += options.sigmas * measurement_options.pixel_sigma_px;
  const Eigen::Vector3d origin = to_world(camera.CameraToRobot(Eigen::Vector3d::Zero()));
  const Eigen::Vector3d direction =
      to_world(camera.CameraToRobot(camera.BackProject(lowest_u, lowest_v, 1.0))) - origin;
  for (const auto& [lo, hi] : boxes(options.sigmas * options.pose_sigma_m, 0.0, 0.0)) {
    if (RayMeetsBox(origin, direction, lo, hi)) return GateVerdict::kOnField;
  }
  return GateVerdict::kOffField;
}

bool OnField(const Detection& detection, const CameraModel& camera,
             const Eigen::Vector3d& robot_pose, const FieldBounds& bounds,
             const FieldGateOptions& options, const MeasurementOptions& measurement_options) {
  return Judge(detection, camera, robot_pose, bounds, options, measurement_options) ==
         GateVerdict::kOnField;
}

std::vector<Detection> RejectOffField(const std::vector<Detection>& detections,
                                      const CameraModel& camera, const Eigen::Vector3d& robot_pose,
                                      const FieldBounds& bounds, const FieldGateOptions& options,
                                      const MeasurementOptions& measurement_options,
                                      int* rejected) {
  std::vector<Detection> kept;
  kept.reserve(detections.size());
  for (const Detection& d : detections) {
    if (OnField(d, camera, robot_pose, bounds, options, measurement_options)) {
      kept.push_back(d);
    } else if (rejected) {
      ++*rejected;
    }
  }
  return kept;
}

}  // namespace slamo::vision
