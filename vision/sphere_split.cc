#include "vision/sphere_split.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "vision/contour_trace.h"
#include "vision/size_split.h"

namespace slamo::vision {

SphereSplitResult SplitSpheres(const cv::Mat& mask, const cv::Mat& depth_mm, cv::Point offset,
                               const CameraModel& camera, double radius_m,
                               const SphereSplitOptions& options) {
  SphereSplitResult result;
  const double r = radius_m;
  if (mask.empty() || !(r > 0.0)) return result;
  const double tol = options.surface_tolerance * r;
  const Eigen::Vector3d eye = camera.CameraToRobot(Eigen::Vector3d::Zero());
  Eigen::Matrix3d robot_from_camera;
  for (int i = 0; i < 3; ++i)
    robot_from_camera.col(i) = camera.CameraToRobot(Eigen::Vector3d::Unit(i)) - eye;
  const field::CameraConfig& intrinsics = camera.config();
  const auto robot_point = [&](int u, int v, double z) {
    return Eigen::Vector3d(
        eye +
        robot_from_camera * Eigen::Vector3d((u + offset.x - intrinsics.cx) / intrinsics.fx * z,
                                            (v + offset.y - intrinsics.cy) / intrinsics.fy * z, z));
  };
  // A first look at every third pixel of every third row: a blob most of whose points are
  // well above a ball's top (a structure of the colour, a larger ball) is passed over before
  // every pixel is back-projected (the full test below decides the rest).
  {
    int seen = 0, low = 0;
    for (int v = 1; v < mask.rows; v += 3) {
      const uint8_t* m = mask.ptr<uint8_t>(v);
      const uint16_t* d = depth_mm.ptr<uint16_t>(v);
      for (int u = 1; u < mask.cols; u += 3) {
        if (!m[u] || !d[u]) continue;
        const double z = camera.CorrectDepthM(d[u]);
        if (!(z > 0.0)) continue;
        ++seen;
        low += robot_point(u, v, z).z() <= 2.0 * r + 2.0 * tol;
      }
    }
    if (seen >= 32 && low < (options.min_explained - 0.2) * seen) return result;
  }
  const cv::Mat core = RimlessCore(mask, options.erode_px, options.min_points);
  // Every pixel_step-th pixel of every pixel_step-th row is looked at: counts of pixels
  // (points on a ball, the fewest a ball needs) are of those.
  const int pixel_step = std::max(1, options.pixel_step);
  const int min_points = std::max(3, options.min_points / (pixel_step * pixel_step));
  // The blob's points in the robot frame (z up from the floor), where a ball can be: from the
  // floor to its top, with the tolerance either side.
  std::vector<cv::Point> pixels;
  std::vector<Eigen::Vector3d> points;
  int with_depth = 0;               // every point of the blob, wherever it lies
  std::vector<double> slack_at_cm;  // noise_sigmas x sigma, per centimetre of depth
  for (int v = 0; v < core.rows; v += pixel_step) {
    const uint8_t* m = core.ptr<uint8_t>(v);
    const uint16_t* d = depth_mm.ptr<uint16_t>(v);
    for (int u = 0; u < core.cols; u += pixel_step) {
      if (!m[u] || !d[u]) continue;
      const double z = camera.CorrectDepthM(d[u]);
      if (!(z > 0.0)) continue;
      ++with_depth;
      const Eigen::Vector3d p = robot_point(u, v, z);
      if (p.z() < -tol || p.z() > 2.0 * r + tol) {
        const size_t cm = static_cast<size_t>(z * 100.0);
        if (cm >= slack_at_cm.size()) slack_at_cm.resize(cm + 1, -1.0);
        if (slack_at_cm[cm] < 0.0)
          slack_at_cm[cm] = options.noise_sigmas * camera.DepthSigmaM((cm + 1) / 100.0);
        const double slack = slack_at_cm[cm];
        if (p.z() < -slack || p.z() > 2.0 * r + slack) continue;
      }
      pixels.emplace_back(u, v);
      points.push_back(p);
    }
  }
  // Balls on the floor must explain the blob: too few of its points are low enough (a tall
  // structure, a larger ball of the colour), and no ball is looked for; nor when its top is
  // below a ball's centre (a floor marking: the camera, above the balls, sees every ball's
  // top).
  if (static_cast<int>(points.size()) < min_points ||
      static_cast<double>(points.size()) < options.min_explained * with_depth) {
    return result;
  }
  {
    std::vector<double> heights(points.size());
    for (size_t i = 0; i < points.size(); ++i) heights[i] = points[i].z();
    const size_t top = heights.size() - 1 - heights.size() / 32;  // the 97th percentile
    std::nth_element(heights.begin(), heights.begin() + top, heights.end());
    if (heights[top] < r) return result;
  }

  const double focal = camera.config().fx;

  // Votes on a floor grid round the points, padded by a radius.
  const int stride = std::max<int>(
      1, static_cast<int>(std::ceil(static_cast<double>(points.size()) / options.max_points)));
  const double cell = options.cell_fraction * r;
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const Eigen::Vector3d& p : points) {
    x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x());
    y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
  }
  x0 -= r + cell, y0 -= r + cell, x1 += r + cell, y1 += r + cell;
  const int cols = static_cast<int>(std::ceil((x1 - x0) / cell)) + 1;
  const int rows = static_cast<int>(std::ceil((y1 - y0) / cell)) + 1;
  if (static_cast<int64_t>(cols) * rows > 4'000'000) return result;  // not a pile of these
  cv::Mat votes(rows, cols, CV_32F, cv::Scalar(0));
  const double inv_cell = 1.0 / cell;
  for (size_t i = 0; i < points.size(); i += stride) {
    const Eigen::Vector3d& p = points[i];
    const double h = std::clamp(p.z(), 0.0, 2.0 * r);
    const double rho = std::sqrt(std::max(0.0, r * r - (h - r) * (h - r)));
    const Eigen::Vector3d to_eye = eye - p;
    const double eye_dist = to_eye.norm();
    // The arc of centres from which the point is on the ball's visible side: its outward
    // normal (p - c) faces the eye, a little past the silhouette for depth noise, i.e.
    // rho |e| cos(theta - phi) <= 0.2 r |to_eye| - (r - h) e_z with e the way to the eye.
    const double across = std::hypot(to_eye.x(), to_eye.y());
    const double bound = 0.2 * r * eye_dist - (r - h) * to_eye.z();
    double from = 0.0, span = 2.0 * M_PI;  // theta from `from` over `span`
    if (rho * across > 1e-12) {
      const double k = bound / (rho * across);
      if (k < -1.0) continue;
      if (k < 1.0) {
        const double half_gap = std::acos(k);  // the hidden arc, round phi
        from = std::atan2(to_eye.y(), to_eye.x()) + half_gap;
        span = 2.0 * M_PI - 2.0 * half_gap;
      }
    } else if (bound < 0.0) {
      continue;
    }
    const double step = rho < 0.5 * cell ? 2.0 * M_PI : std::min(2.0 * M_PI, cell / rho);
    const int samples = 1 + static_cast<int>(span / step);
    const double cos_step = std::cos(step), sin_step = std::sin(step);
    double ux = std::cos(from), uy = std::sin(from);
    int last = -1;
    for (int s = 0; s < samples; ++s) {
      const double cx = rho * ux, cy = rho * uy;
      const double next_x = ux * cos_step - uy * sin_step;
      uy = ux * sin_step + uy * cos_step;
      ux = next_x;
      const int gx = static_cast<int>((p.x() + cx - x0) * inv_cell);
      const int gy = static_cast<int>((p.y() + cy - y0) * inv_cell);
      const int at = gy * cols + gx;
      if (at == last) continue;
      last = at;
      votes.at<float>(gy, gx) += 1.0f;
    }
  }

  cv::Mat smooth;
  cv::boxFilter(votes, smooth, CV_32F, cv::Size(3, 3), cv::Point(-1, -1), false);

  // Peaks, strongest first: each a ball when the points on its sphere, not on a stronger
  // ball's, cover enough of what a ball shows at its range.
  std::vector<int> owner(points.size(), -1);
  std::vector<double> tols;  // each ball's surface tolerance
  std::vector<size_t> support;
  const double min_votes = static_cast<double>(min_points) / stride;
  int rejected_in_a_row = 0;
  for (int tries = 0; tries < 4 * options.max_objects && result.objects < options.max_objects;
       ++tries) {
    double peak = 0.0;
    cv::Point at;
    cv::minMaxLoc(smooth, nullptr, &peak, nullptr, &at);
    if (peak < min_votes || rejected_in_a_row >= options.max_rejections) break;
    Eigen::Vector3d c(x0 + (at.x + 0.5) * cell, y0 + (at.y + 0.5) * cell, r);
    // Points within the tolerance of its surface, or within the depth noise at its range
    // (cut off inside the noise, points off a flat face would fit a sphere as well as a plane).
    const double ball_tol =
        std::max(tol, options.noise_sigmas * camera.DepthSigmaM((c - eye).norm()));
    // Refined on its points (Gauss-Newton for the centre of a sphere of known radius resting
    // on the floor).
    for (int it = 0; it < 4; ++it) {
      Eigen::Matrix2d jtj = Eigen::Matrix2d::Zero();
      Eigen::Vector2d jtr = Eigen::Vector2d::Zero();
      int n = 0;
      for (size_t i = 0; i < points.size(); i += stride) {
        if (owner[i] >= 0) continue;
        const Eigen::Vector3d d = points[i] - c;
        const double dist = d.norm();
        if (dist < 1e-9 || std::abs(dist - r) > ball_tol) continue;
        const Eigen::Vector2d j(-d.x() / dist, -d.y() / dist);
        jtj += j * j.transpose();
        jtr += j * (dist - r);
        ++n;
      }
      if (n < 3 || std::abs(jtj.determinant()) < 1e-12) break;
      const Eigen::Vector2d step = -jtj.ldlt().solve(jtr);
      c.x() += step.x(), c.y() += step.y();
      if (step.norm() < 0.01 * r) break;
    }
    support.clear();
    for (size_t i = 0; i < points.size(); ++i) {
      if (owner[i] < 0 && std::abs((points[i] - c).norm() - r) <= ball_tol) support.push_back(i);
    }
    const double range = (c - eye).norm();
    const double whole_px =
        M_PI * std::pow(focal * r / std::max(range, r), 2) / (pixel_step * pixel_step);
    bool ball = static_cast<int>(support.size()) >= min_points &&
                static_cast<double>(support.size()) >= options.min_support * whole_px;
    if (ball && options.min_curve_ratio > 0.0) {
      // Its points curve as a ball's do: a plane through them fits worse than the sphere by
      // this ratio (a flat face, a robot's bumper, lies within the tolerance of a row of balls
      // behind it).
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (size_t i : support) mean += points[i];
      mean /= static_cast<double>(support.size());
      Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
      double sphere_ss = 0.0;
      for (size_t i : support) {
        const Eigen::Vector3d d = points[i] - mean;
        scatter += d * d.transpose();
        const double e = (points[i] - c).norm() - r;
        sphere_ss += e * e;
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
      const double plane_ss = std::max(0.0, eig.eigenvalues()(0));
      ball = plane_ss > options.min_curve_ratio * options.min_curve_ratio * sphere_ss;
    }
    const double clear = (ball ? options.min_separation : 0.5) * r;
    const cv::Point2d peak_at((c.x() - x0) / cell - 0.5, (c.y() - y0) / cell - 0.5);
    cv::circle(smooth, cv::Point(at), static_cast<int>(std::ceil(clear / cell)), cv::Scalar(0),
               cv::FILLED);
    if (ball) {
      cv::circle(smooth,
                 cv::Point(static_cast<int>(std::lround(peak_at.x)),
                           static_cast<int>(std::lround(peak_at.y))),
                 static_cast<int>(std::ceil(clear / cell)), cv::Scalar(0), cv::FILLED);
      for (size_t i : support) owner[i] = result.objects;
      result.centres.push_back(c);
      tols.push_back(ball_tol);
      ++result.objects;
      rejected_in_a_row = 0;
    } else {
      ++rejected_in_a_row;
    }
  }

  // Fewer balls than asked for (one or none, to split): nothing (not looked at further).
  if (result.objects < std::max(1, options.min_objects)) {
    result.centres.clear();
    return result;
  }

  // The balls must be what the blob is: most of its points on them (not a ball on top of
  // others, a ball against a bumper of its colour, or a wall whose votes line up by chance).
  int explained = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    bool on = owner[i] >= 0;
    for (int b = 0; b < result.objects && !on; ++b)
      on = std::abs((points[i] - result.centres[b]).norm() - r) <= tols[b];
    explained += on;
  }
  if (explained < options.min_explained * with_depth) {
    result = SphereSplitResult{};
    return result;
  }

  // Each ball's pixels: those on its sphere, then the rim and pixels without depth next to
  // them (up to a few pixels away); pixels with depth on no ball belong to none. (Drawing the
  // balls as the camera sees them instead, the nearest sphere along each pixel's ray, placed
  // centres better but cut Nothing but Net's arena precision 0.976 -> 0.948: in the heaps of
  // driver loads, where balls overlap, a drawn ball covers its neighbours.)
  cv::Mat label(mask.size(), CV_32S, cv::Scalar(-1));
  for (size_t i = 0; i < points.size(); ++i) {
    int on = owner[i];
    if (on < 0) {
      // Points thinned out of the votes, or left by every ball: the nearest sphere's, if on it.
      double best = std::numeric_limits<double>::infinity();
      for (int b = 0; b < result.objects; ++b) {
        const double e = std::abs((points[i] - result.centres[b]).norm() - r);
        if (e <= tols[b] && e < best) best = e, on = b;
      }
    }
    label.at<int>(pixels[i]) = on < 0 ? -2 : on;
  }
  // The pixels not looked at (pixel_step > 1), with depth where a ball can be: the nearest
  // sphere's, if on it, as the others.
  for (int v = 0; v < core.rows && pixel_step > 1; ++v) {
    const uint8_t* m = core.ptr<uint8_t>(v);
    const uint16_t* d = depth_mm.ptr<uint16_t>(v);
    for (int u = 0; u < core.cols; ++u) {
      if ((v % pixel_step == 0 && u % pixel_step == 0) || !m[u] || !d[u]) continue;
      const double z = camera.CorrectDepthM(d[u]);
      if (!(z > 0.0)) continue;
      const Eigen::Vector3d p = robot_point(u, v, z);
      if (p.z() < -tol || p.z() > 2.0 * r + tol) {  // where no ball can be, as above
        const size_t cm = static_cast<size_t>(z * 100.0);
        if (cm >= slack_at_cm.size()) slack_at_cm.resize(cm + 1, -1.0);
        if (slack_at_cm[cm] < 0.0)
          slack_at_cm[cm] = options.noise_sigmas * camera.DepthSigmaM((cm + 1) / 100.0);
        if (p.z() < -slack_at_cm[cm] || p.z() > 2.0 * r + slack_at_cm[cm]) continue;
      }
      int on = -2;
      double best = std::numeric_limits<double>::infinity();
      for (int b = 0; b < result.objects; ++b) {
        const double e = std::abs((p - result.centres[b]).norm() - r);
        if (e <= tols[b] && e < best) best = e, on = b;
      }
      label.at<int>(v, u) = on;
    }
  }
  cv::Mat free_px(mask.size(), CV_8UC1, cv::Scalar(255));  // 0 where a ball's pixel is
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (label.at<int>(v, u) >= 0) free_px.at<uint8_t>(v, u) = 0;
    }
  }
  cv::Mat dist, nearest;
  // One ball: every pixel near a ball's is its (no labels to look up).
  const bool one = result.objects == 1;
  if (one) {
    // The mask the labelled transform uses for DIST_L2 (OpenCV takes 5 x 5 there), so that
    // the distances are the same.
    cv::distanceTransform(free_px, dist, cv::DIST_L2, cv::DIST_MASK_5);
  } else {
    cv::distanceTransform(free_px, dist, nearest, cv::DIST_L2, 3, cv::DIST_LABEL_PIXEL);
  }
  // Each zero pixel's label index -> its ball.
  std::vector<int> ball_of_index(1, -1);
  for (int v = 0; v < mask.rows && !one; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (!free_px.at<uint8_t>(v, u)) {
        const int index = nearest.at<int>(v, u);
        if (index >= static_cast<int>(ball_of_index.size())) ball_of_index.resize(index + 1, -1);
        ball_of_index[index] = label.at<int>(v, u);
      }
    }
  }
  const float reach = static_cast<float>(options.erode_px + 4);
  std::vector<cv::Mat> groups(result.objects);
  for (cv::Mat& g : groups) g = cv::Mat::zeros(mask.size(), CV_8UC1);
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (!mask.at<uint8_t>(v, u) || label.at<int>(v, u) == -2) continue;
      if (dist.at<float>(v, u) > reach) continue;
      if (one) {
        groups[0].at<uint8_t>(v, u) = 255;
        continue;
      }
      const int index = nearest.at<int>(v, u);
      const int b = index < static_cast<int>(ball_of_index.size()) ? ball_of_index[index] : -1;
      if (b >= 0) groups[b].at<uint8_t>(v, u) = 255;
    }
  }
  std::vector<Eigen::Vector3d> centres;
  for (int b = 0; b < result.objects; ++b) {
    std::vector<std::vector<cv::Point>> contours;
    FindOuterContours(groups[b], &contours);
    if (contours.empty()) continue;
    const auto largest = std::max_element(
        contours.begin(), contours.end(),
        [](const auto& a, const auto& c) { return cv::contourArea(a) < cv::contourArea(c); });
    result.pieces.push_back(std::move(*largest));
    centres.push_back(result.centres[b]);
  }
  result.centres = std::move(centres);
  result.objects = static_cast<int>(result.pieces.size());

  return result;
}

}  // namespace slamo::vision
