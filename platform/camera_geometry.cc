#include "platform/camera_geometry.h"

#include <algorithm>
#include <cmath>

namespace slamo::platform {

Eigen::Isometry3d RobotFromCamera(const field::CameraMount& mount) {
  Eigen::Matrix3d base;  // columns: the camera's x (right), y (down), z (forward) in the robot
  base << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(mount.yaw_deg * kPi / 180.0, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(mount.pitch_deg * kPi / 180.0, Eigen::Vector3d::UnitY()))
                      .toRotationMatrix() *
                  base;
  pose.translation() = Eigen::Vector3d(mount.x_m, mount.y_m, mount.height_m);
  return pose;
}

Eigen::Isometry3d WorldFromRobot(const Pose2D& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(pose.theta_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(pose.x_m, pose.y_m, 0.0);
  return t;
}

bool WholeInView(const field::CameraConfig& camera, const Eigen::Vector2d& centre_m, double size_m,
                 double height_m, double margin_rad) {
  const Eigen::Isometry3d camera_from_robot = RobotFromCamera(camera.mount).inverse();
  const double r = size_m / 2.0;
  const Eigen::Vector2d toward = centre_m.norm() > 1e-9
                                     ? Eigen::Vector2d(centre_m / centre_m.norm())
                                     : Eigen::Vector2d::UnitX();
  const Eigen::Vector2d side(-toward.y(), toward.x());
  const Eigen::Vector2d near = centre_m - r * toward;
  const Eigen::Vector3d points[] = {
      {near.x(), near.y(), 0.0},
      {centre_m.x(), centre_m.y(), height_m},
      {centre_m.x() + r * side.x(), centre_m.y() + r * side.y(), height_m / 2.0},
      {centre_m.x() - r * side.x(), centre_m.y() - r * side.y(), height_m / 2.0}};
  const double margin_u = camera.fx * std::tan(margin_rad),
               margin_v = camera.fy * std::tan(margin_rad);
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = camera_from_robot * p;
    if (q.z() < std::max(camera.min_range_m, 0.05)) return false;
    const double u = camera.fx * q.x() / q.z() + camera.cx;
    const double v = camera.fy * q.y() / q.z() + camera.cy;
    if (u < margin_u || u > camera.width_px - margin_u || v < margin_v ||
        v > camera.height_px - margin_v) {
      return false;
    }
  }
  return true;
}

double NearestWholeInView(const field::CameraConfig& camera, double size_m, double height_m,
                          double margin_rad, double max_m) {
  for (double d = 0.0; d < max_m; d += 0.01) {
    if (WholeInView(camera, Eigen::Vector2d(d, 0.0), size_m, height_m, margin_rad)) return d;
  }
  return max_m;
}

double DepthSigmaM(const field::CameraConfig& camera, double depth_m) {
  const std::vector<double>& d = camera.noise.distance_m;
  const std::vector<double>& s = camera.noise.sigma_m;
  if (depth_m <= d.front()) return s.front();
  if (depth_m >= d.back()) return s.back();
  const size_t i = std::upper_bound(d.begin(), d.end(), depth_m) - d.begin();
  const double f = (depth_m - d[i - 1]) / (d[i] - d[i - 1]);
  return s[i - 1] + f * (s[i] - s[i - 1]);
}

}  // namespace slamo::platform
