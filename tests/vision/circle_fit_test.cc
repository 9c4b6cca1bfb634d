#include "vision/circle_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

namespace slamo::vision {
namespace {

// The fit the detector used before FitCircleKasa: the same least squares, [x y 1] (D E F)^T =
// -(x^2 + y^2) on the points centred on their mean, solved by SVD.
std::optional<Circle> FitCircleSvd(const std::vector<cv::Point>& points) {
  cv::Point2d mean(0, 0);
  for (const cv::Point& p : points) mean += cv::Point2d(p);
  mean *= 1.0 / points.size();
  const int n = static_cast<int>(points.size());
  cv::Mat a(n, 3, CV_64F), b(n, 1, CV_64F);
  for (int i = 0; i < n; ++i) {
    const double x = points[i].x - mean.x, y = points[i].y - mean.y;
    double* row = a.ptr<double>(i);
    row[0] = x;
    row[1] = y;
    row[2] = 1.0;
    b.at<double>(i, 0) = -(x * x + y * y);
  }
  cv::Mat solution;
  if (!cv::solve(a, b, solution, cv::DECOMP_SVD)) return std::nullopt;
  const double cx = -solution.at<double>(0) / 2.0, cy = -solution.at<double>(1) / 2.0;
  const double r2 = cx * cx + cy * cy - solution.at<double>(2);
  if (!(r2 > 0.0)) return std::nullopt;
  return Circle{mean + cv::Point2d(cx, cy), std::sqrt(r2)};
}

// True when all points lie on one line (exactly: integer cross products).
bool Collinear(const std::vector<cv::Point>& points) {
  for (size_t i = 1; i < points.size(); ++i) {
    if (points[i] == points[0]) continue;
    const cv::Point d = points[i] - points[0];
    for (const cv::Point& p : points) {
      const cv::Point e = p - points[0];
      if (static_cast<int64_t>(d.x) * e.y != static_cast<int64_t>(d.y) * e.x) return false;
    }
    return true;
  }
  return true;  // all in one place
}

TEST(CircleFitTest, AgreesWithSvdOnRandomArcs) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  int fitted = 0, collinear = 0;
  double worst_centre = 0.0, worst_radius = 0.0;
  for (int trial = 0; trial < 20000; ++trial) {
    // Radii from 3 to 600 px (log-uniform), arcs of 15 to 360 degrees, up to a pixel of noise
    // before rounding to pixels, as an outline gives them.
    const double radius = 3.0 * std::pow(200.0, unit(rng));
    const cv::Point2d centre(1920.0 * unit(rng), 1080.0 * unit(rng));
    const double span = (15.0 + 345.0 * unit(rng)) * M_PI / 180.0;
    const double start = 2.0 * M_PI * unit(rng);
    const double sigma = unit(rng);
    const int n = 8 + static_cast<int>(400 * unit(rng));
    std::vector<cv::Point> points;
    for (int i = 0; i < n; ++i) {
      const double angle = start + span * i / (n - 1);
      points.emplace_back(
          static_cast<int>(std::lround(centre.x + radius * std::cos(angle) + sigma * noise(rng))),
          static_cast<int>(std::lround(centre.y + radius * std::sin(angle) + sigma * noise(rng))));
    }
    const std::optional<Circle> kasa = FitCircleKasa(points);
    if (Collinear(points)) {
      EXPECT_FALSE(kasa) << "trial " << trial;
      ++collinear;
      continue;
    }
    const std::optional<Circle> svd = FitCircleSvd(points);
    ASSERT_TRUE(svd) << "trial " << trial;
    ASSERT_TRUE(kasa) << "trial " << trial;
    // Both solve the same well-posed least squares; they differ by rounding only, which grows
    // with the radius against the arc's extent.
    const double tolerance = 1e-10 * std::max(1.0, svd->radius);
    const double centre_error = cv::norm(kasa->centre - svd->centre);
    const double radius_error = std::abs(kasa->radius - svd->radius);
    EXPECT_LE(centre_error, tolerance) << "trial " << trial << " radius " << radius;
    EXPECT_LE(radius_error, tolerance) << "trial " << trial << " radius " << radius;
    worst_centre = std::max(worst_centre, centre_error / std::max(1.0, svd->radius));
    worst_radius = std::max(worst_radius, radius_error / std::max(1.0, svd->radius));
    ++fitted;
  }
  RecordProperty("fitted", fitted);
  RecordProperty("collinear", collinear);
  std::printf("%d arcs fitted, %d collinear; worst difference / radius: centre %.3g, radius %.3g\n",
              fitted, collinear, worst_centre, worst_radius);
  EXPECT_GT(fitted, 19000);
}

TEST(CircleFitTest, CollinearOrCoincidentPointsHaveNoCircle) {
  const auto line = [](cv::Point from, cv::Point step, int n) {
    std::vector<cv::Point> points;
    for (int i = 0; i < n; ++i) points.push_back(from + i * step);
    return points;
  };
  EXPECT_FALSE(FitCircleKasa(line({10, 20}, {1, 0}, 50)));   // horizontal
  EXPECT_FALSE(FitCircleKasa(line({10, 20}, {0, 1}, 50)));   // vertical
  EXPECT_FALSE(FitCircleKasa(line({10, 20}, {3, -2}, 50)));  // slanted
  EXPECT_FALSE(FitCircleKasa(line({1900, 1070}, {-7, -4}, 200)));
  EXPECT_FALSE(FitCircleKasa(line({5, 5}, {0, 0}, 20)));  // one place
  EXPECT_FALSE(FitCircleKasa({{0, 0}, {1, 1}}));          // too few
  // Unordered points of one line, repeated.
  EXPECT_FALSE(FitCircleKasa({{4, 2}, {0, 0}, {8, 4}, {2, 1}, {4, 2}, {-6, -3}, {100, 50}}));
}

TEST(CircleFitTest, ExactCircle) {
  // Points of the circle of radius 5 about (100, 200) with integer coordinates.
  std::vector<cv::Point> points;
  for (const cv::Point& p : {cv::Point(5, 0), cv::Point(4, 3), cv::Point(3, 4), cv::Point(0, 5)}) {
    for (const cv::Point& s :
         {cv::Point(1, 1), cv::Point(-1, 1), cv::Point(1, -1), cv::Point(-1, -1)}) {
      points.emplace_back(100 + s.x * p.x, 200 + s.y * p.y);
    }
  }
  const std::optional<Circle> fit = FitCircleKasa(points);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->centre.x, 100.0, 1e-12);
  EXPECT_NEAR(fit->centre.y, 200.0, 1e-12);
  EXPECT_NEAR(fit->radius, 5.0, 1e-12);
}

}  // namespace
}  // namespace slamo::vision
