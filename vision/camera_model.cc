#include "vision/camera_model.h"

#include "platform/camera_geometry.h"

namespace slamo::vision {

CameraModel::CameraModel(const field::CameraConfig& config)
    : config_(config), robot_from_camera_(platform::RobotFromCamera(config.mount)) {}

double CameraModel::CorrectDepthM(double raw_mm) const {
  return (raw_mm - config_.depth_correction.b_mm) / config_.depth_correction.a / 1000.0;
}

Eigen::Vector3d CameraModel::BackProject(double u, double v, double z_m) const {
  return Eigen::Vector3d((u - config_.cx) * z_m / config_.fx, (v - config_.cy) * z_m / config_.fy,
                         z_m);
}

Eigen::Vector2d CameraModel::Project(const Eigen::Vector3d& p) const {
  return Eigen::Vector2d(config_.fx * p.x() / p.z() + config_.cx,
                         config_.fy * p.y() / p.z() + config_.cy);
}

Eigen::Vector3d CameraModel::CameraToRobot(const Eigen::Vector3d& p_camera) const {
  return robot_from_camera_ * p_camera;
}

double CameraModel::DepthSigmaM(double z_m) const { return platform::DepthSigmaM(config_, z_m); }

CameraModel CameraModel::Scaled(int width_px, int height_px) const {
  field::CameraConfig c = config_;
  const double sx = static_cast<double>(width_px) / config_.width_px;
  const double sy = static_cast<double>(height_px) / config_.height_px;
  c.width_px = width_px;
  c.height_px = height_px;
  c.cx *= sx, c.fx *= sx;
  c.cy *= sy, c.fy *= sy;
  return CameraModel(c);
}

}  // namespace slamo::vision
