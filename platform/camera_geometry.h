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

// sigma of one depth reading at `depth_m`, interpolated linearly in the camera's noise table.
double DepthSigmaM(const field::CameraConfig& camera, double depth_m);

}  // namespace slamo::platform
