#include "vision/circle_fit.h"

#include <cmath>

namespace slamo::vision {

std::optional<Circle> FitCircleKasa(const std::vector<cv::Point>& points) {
  const size_t n = points.size();
  if (n < 3) return std::nullopt;
  // Centre the points on their mean: the sums below are then of small numbers, and the sums
  // of x and y vanish, which uncouples F from D and E in the normal equations.
  double sum_x = 0.0, sum_y = 0.0;
  for (const cv::Point& p : points) sum_x += p.x, sum_y += p.y;
  const cv::Point2d mean(sum_x / n, sum_y / n);
  double sxx = 0.0, sxy = 0.0, syy = 0.0, sxz = 0.0, syz = 0.0, sz = 0.0;
  for (const cv::Point& p : points) {
    const double x = p.x - mean.x, y = p.y - mean.y, z = x * x + y * y;
    sxx += x * x, sxy += x * y, syy += y * y;
    sxz += x * z, syz += y * z, sz += z;
  }
  // Normal equations of [x y 1] (D E F)^T = -z, centred:
  //   [sxx sxy 0] [D]   [-sxz]
  //   [sxy syy 0] [E] = [-syz]
  //   [0   0   n] [F]   [-sz ]
  const double det = sxx * syy - sxy * sxy;
  // Collinear points make the 2x2 block singular; rounding leaves a few ulps of it.
  if (!(det > 1e-12 * (sxx + syy) * (sxx + syy))) return std::nullopt;
  const double d = (-sxz * syy + syz * sxy) / det;
  const double e = (-syz * sxx + sxz * sxy) / det;
  const double f = -sz / n;
  const double cx = -d / 2.0, cy = -e / 2.0;
  const double r2 = cx * cx + cy * cy - f;
  if (!(r2 > 0.0)) return std::nullopt;
  return Circle{mean + cv::Point2d(cx, cy), std::sqrt(r2)};
}

}  // namespace slamo::vision
