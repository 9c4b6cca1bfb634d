// Depth calibration (thesis ch. 3): back-project a depth image, fit the plane of a wall or a
// board with RANSAC (point-to-plane distance, 3.4.4), fit the linear depth correction
// d_c = (d - b) / a to (measured, true) pairs, and the accumulated error E of eq. 3-1.
// Pure functions: the caller reads the files and owns the data.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vision/camera_model.h"

namespace slamo::vision {

// Thesis 3.4.4: inlier threshold 0.05 m, normal within 10 deg of the camera axis, at most
// 1000 iterations.
struct PlaneFitOptions {
  double inlier_threshold_m = 0.05;  // point-to-plane distance of an inlier
  double max_normal_angle_deg = 10;  // largest angle between the normal and the optical axis
  int max_iterations = 1000;         // RANSAC samples drawn
  uint64_t seed = 1;                 // of the sampler: the same points give the same plane
  int min_inliers = 100;             // fewer inliers: no plane
};

struct PlaneFit {
  Eigen::Vector4d plane;  // ax + by + cz + d = 0, unit normal (a, b, c) facing the camera
  double distance_m = 0;  // |d|: camera-to-plane distance
  int inliers = 0;        // points within the threshold of the final plane
  int points = 0;         // points given
  double rms_m = 0;       // rms point-to-plane distance of the inliers
};

// RANSAC (thesis 3.4.4): planes through three random points whose normal is within
// max_normal_angle_deg of the camera's z axis, each new best refined by least squares on its
// inliers and kept only if the refined normal meets the constraint too; the result is the
// kept plane with the most inliers. Nothing when there are fewer points than min_inliers or
// no model meets the constraints.
std::optional<PlaneFit> FitPlaneRansac(const std::vector<Eigen::Vector3d>& points,
                                       const PlaneFitOptions& options);

// Camera-frame points (x right, y down, z forward) of every pixel of a CV_16UC1 depth image
// in millimetres with a reading (non-zero), at pixel centres, every `stride`-th row and column;
// depth corrected with the camera's d_c = (d - b) / a when apply_correction. Throws
// std::invalid_argument for an empty image, another type, a size other than the camera's, or
// stride < 1.
std::vector<Eigen::Vector3d> DepthToPoints(const cv::Mat& depth_mm, const CameraModel& camera,
                                           bool apply_correction, int stride = 1);

// Rotation from the camera frame to the levelled camera frame: the same origin and OpenCV
// axes, but z along the robot's heading and y straight down. A wall the robot faces has its
// normal on the levelled z axis whatever the mount's pitch (the thesis camera faced its board
// squarely; the robot's looks 15 deg down).
Eigen::Matrix3d LevelledFromCamera(const CameraModel& camera);

// The camera-frame points in the levelled frame, without those less than min_height_m above
// the floor (by the camera mount): floor points at a wall's foot would pull the plane.
std::vector<Eigen::Vector3d> LevelAboveFloor(const std::vector<Eigen::Vector3d>& points_camera,
                                             const CameraModel& camera, double min_height_m);

// measured = a * true + b, fitted by least squares; the correction is d_c = (d - b) / a, the
// robot config's camera.depth_correction.
struct LinearCorrection {
  double a = 1;
  double b_mm = 0;
  double rms_mm = 0;  // rms of measured - (a * true + b)
  int pairs = 0;
};

// Fits a and b to (measured_mm, true_mm) pairs. Throws std::invalid_argument with fewer than
// two distinct true values, a non-finite value, or a slope that is not positive.
LinearCorrection FitLinearCorrection(
    const std::vector<std::pair<double, double>>& measured_true_mm);

// Thesis eq. 3-1: E = (1/n) sqrt(sum_i sum_j (d_ij - d_i0)^2) over n sets of measurements
// d_ij of the true distance d_i0. Throws std::invalid_argument when there are no sets or the
// two sizes differ.
double AccumulatedError(const std::vector<std::vector<double>>& measured_m_per_set,
                        const std::vector<double>& true_m);

// Reads (measured_mm, true_mm) pairs from a CSV file whose header is `measured_mm,true_mm`
// or `measured_m,true_m` (converted to mm). Blank lines and lines starting with '#' are
// skipped. Throws std::invalid_argument naming the file and the line for anything else.
std::vector<std::pair<double, double>> ReadDepthPairsCsv(const std::string& path);

}  // namespace slamo::vision
