// A blob turned into what SLAM-O consumes: depth (median of the blob's valid readings,
// corrected by the camera's linear model), back-projection, and range and bearing from the
// robot's centre with a covariance from the camera's sigma(d) and the pixel uncertainty.
// A blob without valid depth yields no measurement; it never yields a NaN.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vision/camera_model.h"

namespace slamo::vision {

struct MeasurementOptions {
  int min_depth_pixels = 5;  // fewer valid readings in the blob: no measurement
  // ... or fewer than this share of its pixels: what reads is not the object (one nearer than
  // the camera's least range, whose few readings are of something beside it).
  double min_depth_fraction = 0.2;
  int erode_px = 2;                // shrink the blob first: its rim sees the background
  double pixel_sigma_px = 1.0;     // centre uncertainty floor (px)
  double pixel_sigma_ratio = 0.1;  // plus this x the blob radius (partial views, blur)
  double model_sigma_m = 0.01;     // depth model error beyond sigma(d): surface vs centre, bias
};

struct Measurement {
  double range_m = 0.0;      // from the robot's centre, in the floor plane
  double bearing_rad = 0.0;  // counter-clockwise from the robot's heading
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();  // of (range, bearing)
  Eigen::Vector3d position_camera_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_robot_m = Eigen::Vector3d::Zero();
  double depth_m = 0.0;  // corrected median depth of the blob's surface
  int depth_pixels = 0;  // valid readings used
};

// `blob_mask`: CV_8UC1 of the depth image's size, non-zero on the blob (both may be the same
// window of the full images). `centre_px`: where the object's centre projects, in full-image
// pixels. `surface_to_centre_m`: added to the surface depth to reach
// the object's centre (its radius for a ball; 0 for a flat marker).
std::optional<Measurement> MeasureBlob(const cv::Mat& depth_mm, const cv::Mat& blob_mask,
                                       const cv::Point2d& centre_px, double surface_to_centre_m,
                                       double radius_px, const CameraModel& camera,
                                       const MeasurementOptions& options = {});

// MeasureBlob in two steps, for callers that try several surface_to_centre_m on one blob
// (the median depth and its erosion are computed once): the blob's corrected surface depth
// and reading count, nullopt exactly when MeasureBlob gives none; then the measurement.
struct BlobSurface {
  double depth_m = 0.0;
  int pixels = 0;
};
std::optional<BlobSurface> MeasureBlobSurface(const cv::Mat& depth_mm, const cv::Mat& blob_mask,
                                              const CameraModel& camera,
                                              const MeasurementOptions& options = {});
Measurement MeasureFromSurface(const BlobSurface& surface, const cv::Point2d& centre_px,
                               double surface_to_centre_m, double radius_px,
                               const CameraModel& camera, const MeasurementOptions& options = {});

// How much deeper a round object's surface reads at its left and right rims than at its
// centre, along the rows through its centre: a ball's cap curves away from the camera (about
// 0.28 x its radius between the bands used here), a flat face (a wall, a robot's bumper) does
// not, whatever its angle: compared in inverse depth, which is linear across the image for a
// plane (a slope adds as much on one side as it takes on the other).
// Bands, in x the apparent radius: rows within 0.35 of the centre; the centre |u| <= 0.3, the
// rims 0.55 <= |u| <= 0.85. `centre_px` is in the mask's own pixels (not the full image's).
// `along_columns`: the same with rows and columns swapped (top and bottom rims). A ball curves
// away both ways; the edge where two faces of a box meet curves one way only (a vertical edge
// across the rows, the top face's edge across the columns).
struct SurfaceBulge {
  double bulge_m = 0.0;  // the rims' mean inverse median depth below the centre's, x depth^2
  double sigma_m = 0.0;  // its standard deviation from the camera's depth noise
};
std::optional<SurfaceBulge> MeasureSurfaceBulge(const cv::Mat& depth_mm, const cv::Mat& blob_mask,
                                                const cv::Point2d& centre_px, double radius_px,
                                                const CameraModel& camera,
                                                bool along_columns = false);

// How the surface under a mask curves where it curves least: a quadric z = a + bx + cy +
// dx^2 + exy + fy^2 fitted by least squares to its readings (x, y, z in metres in the camera
// frame about the mask's centre; `offset`: the mask's top-left pixel in the image; the mask
// eroded by `erode_px` first so that the rim's mixed readings stay out, the caller's mask left
// as it is; readings farther than `band_m` from `depth_m`, the piece's own depth, left out as
// another object seen beside it), and the eigenvalue of its Hessian nearest zero, in 1/m. A
// sphere of radius R facing the camera gives about 1/R; a cylinder (a bumper's noodle) or the
// edge where two faces of a box meet, convex or concave, about 0 along it, whichever way it
// runs in the image; a plane, 0. `sigma`: its standard deviation from the camera's depth
// noise (along one eigenvector: where both are equal, a ball's, noise pulls the smaller one
// down a little more than it says). nullopt with fewer than `min_readings` readings, or when
// they do not spread both ways (a strip).
struct LeastCurvature {
  double curvature = 0.0;  // 1/m
  double sigma = 0.0;      // 1/m
  // The lowest, signed (the same as `curvature` where the surface curves away both ways;
  // below zero where it curves towards the camera along some direction: a saddle, a hollow).
  double lowest = 0.0;        // 1/m
  double lowest_sigma = 0.0;  // 1/m
};
std::optional<LeastCurvature> MeasureLeastCurvature(const cv::Mat& depth_mm, const cv::Mat& mask,
                                                    cv::Point offset, const CameraModel& camera,
                                                    double depth_m, double band_m, int erode_px = 2,
                                                    int min_readings = 20);

// The median of depth readings as std::nth_element gives it (the element of rank size / 2),
// by a two-pass radix count instead of partial sorting. `readings` must not be empty.
uint16_t MedianReading(const std::vector<uint16_t>& readings);
uint16_t MedianReading(const uint16_t* readings, size_t count);  // count > 0

// The non-zero readings of `depth_mm` (CV_16UC1) under the non-zero pixels of `mask` (CV_8UC1,
// the same size) inside `box`, row by row, into `readings` (grown as needed, never shrunk);
// returns how many. Sixteen pixels at a time where the mask is all background or all set.
size_t MaskedReadings(const cv::Mat& depth_mm, const cv::Mat& mask, const cv::Rect& box,
                      std::vector<uint16_t>* readings);

// Range and bearing in the robot frame of a pixel with its (centre) depth.
Eigen::Vector2d RangeBearing(const CameraModel& camera, double u, double v, double z_m);

}  // namespace slamo::vision
