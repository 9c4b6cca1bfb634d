// Where the camera sits and how noisy it is: the one definition of the camera's mount
// transform and depth noise, shared by the renderer (to draw) and vision (to measure).
#pragma once

#include <Eigen/Geometry>

#include "field_configs/robot_config.h"
#include "platform/drive_base.h"

namespace slamo::platform {

// Camera frame (OpenCV axes: x right, y down, z forward) in the robot frame (x forward,
// y left, z up, origin at the robot's centre on the floor), from the mount config.
Eigen::Isometry3d RobotFromCamera(const field::CameraMount& mount);

// The robot frame in the world for a planar pose.
Eigen::Isometry3d WorldFromRobot(const Pose2D& pose);

// Whether an object standing on the floor at `centre_m` (robot frame), an upright box of
// `size_m` across and `height_m` high facing the camera, is seen whole: its near bottom edge
// (what leaves the view first as the robot comes close, the camera looking down), its top and
// its sides inside the image by `margin_rad` and beyond the camera's minimum depth.
bool WholeInView(const field::CameraConfig& camera, const Eigen::Vector2d& centre_m, double size_m,
                 double height_m, double margin_rad);
// The nearest distance from the robot's centre, straight ahead, at which such an object is
// seen whole (to 1 cm), searched up to `max_m`; max_m when it never is.
double NearestWholeInView(const field::CameraConfig& camera, double size_m, double height_m,
                          double margin_rad, double max_m);

// sigma of one depth reading at `depth_m`, interpolated linearly in the camera's noise table.
double DepthSigmaM(const field::CameraConfig& camera, double depth_m);

}  // namespace slamo::platform
