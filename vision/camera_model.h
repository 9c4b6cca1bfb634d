// The depth camera as vision uses it: the thesis's linear depth correction, back-projection
// of a pixel with its depth (thesis 4.2.1), and the camera-to-robot transform of the mount.
#pragma once

#include <Eigen/Geometry>

#include "field_configs/robot_config.h"

namespace slamo::vision {

class CameraModel {
 public:
  explicit CameraModel(const field::CameraConfig& config);

  const field::CameraConfig& config() const { return config_; }

  // Corrected depth in metres from a raw reading in millimetres: d_c = (d - b) / a.
  double CorrectDepthM(double raw_mm) const;
  // fZ = depth, fX = (u - cx) fZ / fx, fY = (v - cy) fZ / fy (camera frame: x right, y down,
  // z forward).
  Eigen::Vector3d BackProject(double u, double v, double z_m) const;
  Eigen::Vector2d Project(const Eigen::Vector3d& p_camera) const;
  // Camera frame -> robot frame (x forward, y left, z up, origin at the robot's centre).
  Eigen::Vector3d CameraToRobot(const Eigen::Vector3d& p_camera) const;
  // sigma of one raw depth reading at this distance (the robot config's noise table).
  double DepthSigmaM(double z_m) const;

  // The same camera at another image size (a colour image of a different resolution):
  // intrinsics scaled by the width and height ratios.
  CameraModel Scaled(int width_px, int height_px) const;

 private:
  field::CameraConfig config_;
  Eigen::Isometry3d robot_from_camera_;
};

}  // namespace slamo::vision
