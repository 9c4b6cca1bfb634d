// Touching balls of one size counted by their centres (issue 16, item 4): every depth point of
// a blob lies on the visible front of a ball of known radius resting on the floor, so the
// ball's centre lies on a circle at the radius's height above the floor round the point, on
// the side away from the camera. Each point votes for that arc on a floor grid (a Hough
// transform for spheres of one radius); the points of one ball all vote for its centre, and a
// flat face (a bumper, a wall) spreads its votes along a line. Peaks are taken strongest first,
// each keeping the points that lie on its sphere and not on a stronger one's; a peak is a ball
// when its points cover enough of what a ball shows at its range and curve as a ball's do
// (a sphere fits them better than a plane), and the balls found must explain the blob. A ball
// half hidden behind another, which the outline's concave defects cannot find, has a centre of
// its own. Pure function of the mask and depth.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vision/camera_model.h"

namespace slamo::vision {

struct SphereSplitOptions {
  double cell_fraction = 0.25;  // the vote grid's cell, x the radius
  // A point lies on a ball within this x the radius of its surface, or within this many
  // sigmas of one depth reading at the ball's range (the robot file's noise table), whichever
  // is wider: cut off inside the noise, the points of a flat face fit a sphere as well as a
  // plane. On the V5 robot's camera (2 cm at 2 m) the noise term cut Toss Up's false
  // detections on robots from 73 to 39 (arena, seed 1).
  double surface_tolerance = 0.25;
  double noise_sigmas = 2.0;
  // A ball: its points at least this fraction of the pixels a whole ball covers at its range
  // (a ball mostly hidden behind others in a pile shows a cap), and at least min_points.
  double min_support = 0.1;
  int min_points = 12;
  // A ball's points fit its sphere better than a plane through them by this ratio (rms): a
  // flat face, a robot's bumper, lies within the tolerance of a row of balls behind it.
  double min_curve_ratio = 1.5;
  // The balls are the blob: at least this fraction of its points with depth lie on them (not
  // a ball on top of others, or a ball against a bumper of its colour).
  double min_explained = 0.7;
  double min_separation = 1.5;  // centres at least this x the radius apart on the floor
  int max_points = 2500;        // more points than this are thinned to every n-th pixel
  int max_objects = 40;
  int max_rejections = 8;  // peaks in a row that are no ball end the search
  int erode_px = 1;        // the blob's rim (depth there may see past the ball) is left out
  // Fewest balls returned as pieces: 2 splits a blob; 1 also finds one ball alone (a
  // semi-transparent ball whose ragged outline no circle fits), checked against the blob as
  // two or more are.
  int min_objects = 2;
  // Every n-th pixel of every n-th row of the blob is looked at (1: all): a large ball near
  // the camera covers tens of thousands of pixels, and a few thousand place it as well.
  int pixel_step = 1;
};

// Two balls or more (options.min_objects or more): a piece and a centre each. Fewer: nothing
// to split, no pieces (a single ball is then not checked against the blob).
struct SphereSplitResult {
  std::vector<std::vector<cv::Point>> pieces;  // one external contour per ball, mask pixels
  std::vector<Eigen::Vector3d> centres;        // robot frame, metres, one per piece
  int objects = 0;
};

// `mask`: CV_8UC1, non-zero on the blob; `depth_mm`: CV_16UC1 raw readings of the same size;
// `offset`: where the mask's (0, 0) lies in the full image (for the camera's intrinsics).
SphereSplitResult SplitSpheres(const cv::Mat& mask, const cv::Mat& depth_mm, cv::Point offset,
                               const CameraModel& camera, double radius_m,
                               const SphereSplitOptions& options = {});

}  // namespace slamo::vision
