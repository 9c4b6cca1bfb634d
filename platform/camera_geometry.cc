#include "platform/camera_geometry.h"

#include <algorithm>

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
