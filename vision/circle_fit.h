// The algebraic (Kasa) least-squares circle through points: the circle x^2 + y^2 + D x + E y +
// F = 0 whose equation residuals have the least sum of squares. Solved in closed form from the
// normal equations of the points centred on their mean, where they fall apart into a 2x2
// system for the centre and the mean squared distance for the radius.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace slamo::vision {

struct Circle {
  cv::Point2d centre;
  double radius = 0.0;
};

// Nothing for fewer than three points, points on one line (or all in one place), or a
// non-positive squared radius.
std::optional<Circle> FitCircleKasa(const std::vector<cv::Point>& points);

}  // namespace slamo::vision
