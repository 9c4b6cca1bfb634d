#include "vision/detector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/area_resize.h"
#include "vision/circle_fit.h"
#include "vision/contour_fill.h"
#include "vision/contour_trace.h"
#include "vision/field_gate.h"
#include "vision/span_morphology.h"

namespace slamo::vision {
namespace {

void CheckInput(const cv::Mat& bgr, const cv::Mat& depth_mm) {
  if (bgr.empty()) throw std::invalid_argument("the colour image is empty");
  if (bgr.type() != CV_8UC3) {
    throw std::invalid_argument("the colour image must be 8-bit, 3-channel BGR");
  }
  if (depth_mm.empty()) return;
  if (depth_mm.type() != CV_16UC1) {
    throw std::invalid_argument(
        "the depth image must be 16-bit single-channel millimetres (an 8-bit depth image has "
        "lost its scale)");
  }
  if (depth_mm.size() != bgr.size()) {
    throw std::invalid_argument("the depth image (" + std::to_string(depth_mm.cols) + "x" +
                                std::to_string(depth_mm.rows) +
                                ") must be registered to the colour image (" +
                                std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) + ")");
  }
}

// Median of the valid depth readings under a mask, raw millimetres; 0 when none.
double MedianDepthMm(const cv::Mat& depth_mm, const cv::Mat& mask, const cv::Rect& box) {
  thread_local std::vector<uint16_t> readings;  // reused: no allocation per blob
  const size_t count = MaskedReadings(depth_mm, mask, box, &readings);
  if (count == 0) return 0.0;
  return MedianReading(readings.data(), count);
}

// The area of the convex hull of an outline, exactly what cv::contourArea gives for its
// cv::convexHull (both are exact on integer points), without the sort of every point: the hull
// of an outline is the hull of the leftmost and rightmost point of each of its rows. `box`:
// the outline's bounding rectangle.
double ConvexHullArea(const std::vector<cv::Point>& outline, const cv::Rect& box) {
  thread_local std::vector<int> left, right;
  thread_local std::vector<cv::Point> ends, hull;
  left.assign(box.height, std::numeric_limits<int>::max());
  right.assign(box.height, std::numeric_limits<int>::min());
  for (const cv::Point& p : outline) {
    const int row = p.y - box.y;
    left[row] = std::min(left[row], p.x);
    right[row] = std::max(right[row], p.x);
  }
  // Sorted by row, then column: Andrew's monotone chain, both halves in one list.
  ends.clear();
  for (int row = 0; row < box.height; ++row) {
    if (left[row] > right[row]) continue;
    ends.emplace_back(left[row], box.y + row);
    if (right[row] != left[row]) ends.emplace_back(right[row], box.y + row);
  }
  if (ends.size() < 3) return 0.0;
  const auto cross = [](const cv::Point& o, const cv::Point& a, const cv::Point& b) {
    return static_cast<int64_t>(a.x - o.x) * (b.y - o.y) -
           static_cast<int64_t>(a.y - o.y) * (b.x - o.x);
  };
  hull.assign(2 * ends.size(), cv::Point());
  size_t k = 0;
  for (size_t i = 0; i < ends.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], ends[i]) <= 0) --k;
    hull[k++] = ends[i];
  }
  for (size_t i = ends.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], ends[i]) <= 0) --k;
    hull[k++] = ends[i];
  }
  int64_t twice_area = 0;  // shoelace, exact in 64 bits
  for (size_t i = 0; i + 1 < k; ++i) {
    twice_area += static_cast<int64_t>(hull[i].x) * hull[i + 1].y -
                  static_cast<int64_t>(hull[i].y) * hull[i + 1].x;
  }
  return std::abs(static_cast<double>(twice_area)) * 0.5;
}

// cv::morphologyEx(MORPH_CLOSE) of a binary mask.
void CloseBinary(cv::Mat* mask, const cv::Mat& kernel) {
  cv::Mat dilated;
  DilateLike(*mask, kernel, &dilated);
  ErodeLike(dilated, kernel, mask);
}

// A circle fitted (algebraic least squares, Kasa) to outline points.
struct ArcFit {
  cv::Point2d centre;
  double radius = 0.0;
  double rms = 0.0;           // of the points' distance to the circle
  double coverage_deg = 0.0;  // 360 minus the largest angular gap between points
};

// The circle alone (centre and radius; rms and coverage are left 0): FitArc refits up to
// four times and needs the statistics of the last fit only.
std::optional<ArcFit> FitCircle(const std::vector<cv::Point>& points) {
  if (points.size() < 8) return std::nullopt;
  const std::optional<Circle> circle = FitCircleKasa(points);
  if (!circle) return std::nullopt;
  ArcFit fit;
  fit.centre = circle->centre;
  fit.radius = circle->radius;
  return fit;
}

// The largest difference between consecutive values of `values` once sorted, without
// sorting (the maximum-gap bucket method): the largest gap is at least (max - min) / (n - 1),
// wider than a bucket of (max - min) / n, so it always lies between the highest value of one
// non-empty bucket and the lowest of the next. The bucket index is monotonic in the value,
// so those are consecutive values of the sorted order, and their difference is the same
// double the sorted scan computes.
double LargestSortedGap(const std::vector<double>& values) {
  const size_t n = values.size();
  if (n < 2) return 0.0;
  const auto [lo_it, hi_it] = std::minmax_element(values.begin(), values.end());
  const double lo = *lo_it, range = *hi_it - lo;
  if (!(range > 0.0)) return 0.0;
  thread_local std::vector<double> bucket_lo, bucket_hi;
  bucket_lo.assign(n, std::numeric_limits<double>::infinity());
  bucket_hi.assign(n, -std::numeric_limits<double>::infinity());
  const double scale = static_cast<double>(n) / range;
  for (const double v : values) {
    const size_t k = std::min(n - 1, static_cast<size_t>((v - lo) * scale));
    bucket_lo[k] = std::min(bucket_lo[k], v);
    bucket_hi[k] = std::max(bucket_hi[k], v);
  }
  double gap = 0.0, previous_hi = bucket_hi[0];  // bucket 0 holds the minimum
  for (size_t k = 1; k < n; ++k) {
    if (bucket_lo[k] > bucket_hi[k]) continue;  // empty
    gap = std::max(gap, bucket_lo[k] - previous_hi);
    previous_hi = bucket_hi[k];
  }
  return gap;
}

// rms distance of the points to the fitted circle and its angular coverage.
void MeasureArc(const std::vector<cv::Point>& points, ArcFit* fit) {
  thread_local std::vector<double> angles;
  angles.clear();
  double sum2 = 0.0;
  double lowest = std::numeric_limits<double>::infinity();
  double highest = -std::numeric_limits<double>::infinity();
  for (const cv::Point& p : points) {
    const cv::Point2d d = cv::Point2d(p) - fit->centre;
    const double e = std::hypot(d.x, d.y) - fit->radius;
    sum2 += e * e;
    const double angle = std::atan2(d.y, d.x);
    angles.push_back(angle);
    lowest = std::min(lowest, angle);
    highest = std::max(highest, angle);
  }
  fit->rms = std::sqrt(sum2 / points.size());
  const double gap = std::max(2.0 * M_PI - (highest - lowest), LargestSortedGap(angles));
  fit->coverage_deg = 360.0 - gap * 180.0 / M_PI;
}

// |hypot(d) - radius| < tolerance, as std::hypot decides it, without calling it for the
// points far from the band's edges: sqrt of the sum of squares is within a few units in the
// last place of hypot (both within one of the exact distance), so where the two sides differ
// by more than a relative 1e-12 the answer is the same; at the edge, hypot decides.
bool NearCircle(const cv::Point2d& d, double radius, double tolerance) {
  const double distance = std::sqrt(d.x * d.x + d.y * d.y);
  const double margin = std::abs(distance - radius) - tolerance;
  if (std::abs(margin) > 1e-12 * (distance + radius + tolerance)) return margin < 0.0;
  return std::abs(std::hypot(d.x, d.y) - radius) < tolerance;
}

// A circle through an outline whose points may include straight stretches where something
// else hides the object (a barrier's edge): fit, keep the points near the circle, refit.
// `inlier_fraction` reports how much of the outline the final circle explains.
std::optional<ArcFit> FitArc(const std::vector<cv::Point>& points, double* inlier_fraction) {
  std::optional<ArcFit> fit = FitCircle(points);
  thread_local std::vector<cv::Point> inliers, kept;
  inliers = points;
  for (int round = 0; fit && round < 3; ++round) {
    const double tolerance = std::max(1.5, 0.08 * fit->radius);
    kept.clear();
    for (const cv::Point& p : points) {
      if (NearCircle(cv::Point2d(p) - fit->centre, fit->radius, tolerance)) kept.push_back(p);
    }
    if (kept.size() == inliers.size() || kept.size() < 8) break;
    std::swap(inliers, kept);
    fit = FitCircle(inliers);
  }
  *inlier_fraction = points.empty() ? 0.0 : static_cast<double>(inliers.size()) / points.size();
  if (fit) MeasureArc(inliers, &*fit);
  return fit;
}

// The share of a circle's circumference in view (more than 2 px inside the image) along which
// the outline runs on it (within the arc fit's tolerance), in 5-degree steps. A ball's
// outline follows its circle but where something of its colour joins it; a square's, the
// circle fitted to it (between its inscribed and circumscribed ones), about 0.6 of the way.
double CircleOnOutline(const std::vector<cv::Point>& outline, const ArcFit& fit, cv::Size image) {
  constexpr int kSteps = 72;
  std::array<bool, kSteps> on{};
  const double tolerance = std::max(1.5, 0.08 * fit.radius);
  for (const cv::Point& p : outline) {
    const cv::Point2d d = cv::Point2d(p) - fit.centre;
    if (!NearCircle(d, fit.radius, tolerance)) continue;
    const double turn = std::atan2(d.y, d.x) / (2.0 * M_PI) + 0.5;  // 0..1
    on[std::min(kSteps - 1, static_cast<int>(turn * kSteps))] = true;
  }
  int visible = 0, covered = 0;
  for (int k = 0; k < kSteps; ++k) {
    const double angle = ((k + 0.5) / kSteps - 0.5) * 2.0 * M_PI;
    const cv::Point2d p = fit.centre + fit.radius * cv::Point2d(std::cos(angle), std::sin(angle));
    if (p.x <= 2.0 || p.y <= 2.0 || p.x >= image.width - 3.0 || p.y >= image.height - 3.0) continue;
    ++visible;
    covered += on[k];
  }
  return visible > 0 ? static_cast<double>(covered) / visible : 0.0;
}

// Whether every ball SplitSpheres found fills its disc in the image: of the pixels of the
// ball's outline as the camera sees it (its centre projected, radius f r / z; inside the
// image), at least min_fill lie on `mask` (window coordinates, at `window_tl` in the image).
// Two small balls one above another explain a larger sphere's front as well as it does, but
// cover a fraction of its disc; a semi-transparent ball, ragged as its mask is, most of it.
bool BallsFillDiscs(const SphereSplitResult& balls, double radius_m, const CameraModel& camera,
                    const cv::Mat& mask, cv::Point window_tl, cv::Size image, double min_fill) {
  const Eigen::Vector3d eye = camera.CameraToRobot(Eigen::Vector3d::Zero());
  Eigen::Matrix3d robot_from_camera;
  for (int i = 0; i < 3; ++i)
    robot_from_camera.col(i) = camera.CameraToRobot(Eigen::Vector3d::Unit(i)) - eye;
  for (const Eigen::Vector3d& centre : balls.centres) {
    const Eigen::Vector3d in_camera = robot_from_camera.transpose() * (centre - eye);
    if (in_camera.z() <= radius_m) return false;
    const Eigen::Vector2d uv = camera.Project(in_camera);
    const double r_px = camera.config().fx * radius_m / in_camera.z();
    const int r = static_cast<int>(std::ceil(r_px));
    const cv::Rect box = cv::Rect(cvFloor(uv.x()) - r, cvFloor(uv.y()) - r, 2 * r + 2, 2 * r + 2) &
                         cv::Rect(cv::Point(), image);
    int disc = 0, on = 0;
    for (int v = box.y; v < box.y + box.height; ++v) {
      for (int u = box.x; u < box.x + box.width; ++u) {
        if ((u - uv.x()) * (u - uv.x()) + (v - uv.y()) * (v - uv.y()) > r_px * r_px) continue;
        ++disc;
        const cv::Point local(u - window_tl.x, v - window_tl.y);
        on += local.x >= 0 && local.y >= 0 && local.x < mask.cols && local.y < mask.rows &&
              mask.at<uint8_t>(local) != 0;
      }
    }
    if (disc == 0 || on < min_fill * disc) return false;
  }
  return true;
}

// The part of a piece within a circle its outline fits: false, and *piece unchanged, when the
// piece covers less than min_fill of the circle's area in the image.
bool CropToDisc(const ArcFit& fit, cv::Size image, double min_fill, std::vector<cv::Point>* piece) {
  const int r = static_cast<int>(std::ceil(fit.radius)) + 1;
  const cv::Rect disc_box(cvFloor(fit.centre.x) - r, cvFloor(fit.centre.y) - r, 2 * r + 2,
                          2 * r + 2);
  const cv::Rect bounds = (cv::boundingRect(*piece) | disc_box) & cv::Rect(cv::Point(), image);
  if (bounds.empty()) return false;
  cv::Mat inside(bounds.size(), CV_8UC1, cv::Scalar(0));
  FillOutline(*piece, -bounds.tl(), &inside);
  cv::Mat disc(bounds.size(), CV_8UC1, cv::Scalar(0));
  cv::circle(disc, fit.centre - cv::Point2d(bounds.tl()), cvRound(fit.radius), cv::Scalar(255),
             cv::FILLED, cv::LINE_8);
  const int disc_area = cv::countNonZero(disc);
  inside &= disc;
  if (disc_area == 0 || cv::countNonZero(inside) < min_fill * disc_area) return false;
  std::vector<std::vector<cv::Point>> parts;
  FindOuterContours(inside, &parts, bounds.tl());
  if (parts.empty()) return false;
  auto largest = std::max_element(parts.begin(), parts.end(), [](const auto& a, const auto& b) {
    return cv::contourArea(a) < cv::contourArea(b);
  });
  // The part kept must fill the circle itself (not only with a part a seam cuts off).
  cv::Mat kept(bounds.size(), CV_8UC1, cv::Scalar(0));
  FillOutline(*largest, -bounds.tl(), &kept);
  if (cv::countNonZero(kept & disc) < min_fill * disc_area) return false;
  *piece = std::move(*largest);
  return true;
}

// Objects rest on something. Just under the lowest pixels of an object on the floor the camera
// sees the floor in front of its foot (nearer); under one on a goal or another object, what
// holds it; under one whose foot is hidden, what hides it: never much farther than the
// object's own bottom. Under a thing held off the floor with nothing beneath it (a robot's
// bumper) the first rows see the floor behind the gap, farther away. A column of the blob
// floats when the farthest of the `float_below_rows` rows under its lowest pixel lies more
// than `float_margin_m` plus 3 sigma of the depth noise beyond the nearest of its own three
// lowest rows. Returns, per column of `blob_mask`: kFloats, kStands, kUnknown (no readings,
// or the image ends under it) or kEmpty (no blob pixel).
enum ColumnSupport : uint8_t { kStands = 0, kFloats = 1, kUnknown = 2, kEmpty = 3 };
std::vector<uint8_t> FloatingColumns(const cv::Mat& blob_mask, cv::Point offset,
                                     const cv::Mat& depth_mm, const CameraModel& camera,
                                     const DetectOptions& options) {
  constexpr int kOwnRows = 3;
  const int below_rows = options.float_below_rows;
  std::vector<uint8_t> floating(blob_mask.cols, kUnknown);
  for (int u = 0; u < blob_mask.cols; ++u) {
    int bottom = -1;
    for (int v = blob_mask.rows - 1; v >= 0; --v) {
      if (blob_mask.at<uint8_t>(v, u)) {
        bottom = v;
        break;
      }
    }
    if (bottom < 0) {
      floating[u] = kEmpty;
      continue;
    }
    const int x = u + offset.x, y = bottom + offset.y;
    if (y + below_rows >= depth_mm.rows) continue;  // the image ends under it: cannot tell
    double own = std::numeric_limits<double>::infinity();
    for (int v = std::max(0, bottom - kOwnRows + 1); v <= bottom; ++v) {
      const uint16_t raw = depth_mm.at<uint16_t>(v + offset.y, x);
      if (raw && blob_mask.at<uint8_t>(v, u)) own = std::min(own, camera.CorrectDepthM(raw));
    }
    double below = -std::numeric_limits<double>::infinity();
    for (int k = 1; k <= below_rows; ++k) {
      const uint16_t raw = depth_mm.at<uint16_t>(y + k, x);
      if (raw) below = std::max(below, camera.CorrectDepthM(raw));
    }
    if (!std::isfinite(own) || !std::isfinite(below)) continue;
    floating[u] =
        below - own > options.float_margin_m + 3.0 * camera.DepthSigmaM(own) ? kFloats : kStands;
  }
  return floating;
}

// How tall `piece_mask` (at `offset`) stands, from its depth: the spread of its points'
// heights in the robot frame between the 3rd and 97th percentiles (a rim pixel may read what
// lies behind). 0 without readings.
double StandingHeightM(const cv::Mat& piece_mask, cv::Point offset, const cv::Mat& depth_mm,
                       const CameraModel& camera) {
  thread_local std::vector<double> heights;
  heights.clear();
  for (int v = 0; v < piece_mask.rows; ++v) {
    const uint8_t* m = piece_mask.ptr<uint8_t>(v);
    const uint16_t* d = depth_mm.ptr<uint16_t>(v + offset.y) + offset.x;
    for (int u = 0; u < piece_mask.cols; ++u) {
      if (!m[u] || !d[u]) continue;
      heights.push_back(camera
                            .CameraToRobot(camera.BackProject(u + offset.x, v + offset.y,
                                                              camera.CorrectDepthM(d[u])))
                            .z());
    }
  }
  if (heights.size() < 8) return 0.0;
  const size_t cut = static_cast<size_t>(0.03 * (heights.size() - 1));
  std::nth_element(heights.begin(), heights.begin() + cut, heights.end());
  const double low = heights[cut];
  std::nth_element(heights.begin(), heights.end() - 1 - cut, heights.end());
  return heights[heights.size() - 1 - cut] - low;
}

// DetectOptions::depth_cut_min_m (`min_m`): clears, in `mask`, the farther pixel of every pair
// of 8-connected neighbours of it whose depths differ by more than the cut (pixels without a
// reading are left: a line of them still joins what it runs between). Returns how many
// clearings were made (a pixel may be counted more than once): 0 when nothing was cut.
int CutAtDepthEdges(const cv::Mat& depth_mm, const CameraModel& camera,
                    const DetectOptions& options, double min_m, cv::Mat* mask) {
  thread_local std::vector<cv::Point> cleared;
  cleared.clear();
  const int rows = mask->rows, cols = mask->cols;
  // The depth correction is linear in the raw reading (CameraModel::CorrectDepthM).
  const double offset = camera.CorrectDepthM(0.0);
  const double scale = camera.CorrectDepthM(1.0) - offset;
  const auto jumps = [&](uint16_t raw_a, uint16_t raw_b) {
    const double a = offset + scale * raw_a, b = offset + scale * raw_b;
    const double near = std::min(a, b), step = std::abs(a - b);
    return step > min_m && step > options.depth_cut_ratio * near &&
           step > options.depth_cut_sigmas * camera.DepthSigmaM(near);
  };
  const auto farther = [&](uint16_t raw_a, uint16_t raw_b) {
    return (offset + scale * raw_a) > (offset + scale * raw_b);
  };
  for (int v = 0; v < rows; ++v) {
    const uint8_t* m = mask->ptr<uint8_t>(v);
    const uint16_t* d = depth_mm.ptr<uint16_t>(v);
    const bool last = v + 1 == rows;
    const uint8_t* m_next = last ? nullptr : mask->ptr<uint8_t>(v + 1);
    const uint16_t* d_next = last ? nullptr : depth_mm.ptr<uint16_t>(v + 1);
    for (int u = 0; u < cols; ++u) {
      // Most of a colour's mask is empty: skip it eight bytes at a time.
      uint64_t eight;
      while (u + 8 <= cols && (std::memcpy(&eight, m + u, 8), eight == 0)) u += 8;
      if (u >= cols) break;
      if (!m[u] || !d[u]) continue;
      const auto look = [&](int x, int y, uint16_t other) {
        if (other && jumps(d[u], other))
          cleared.push_back(farther(d[u], other) ? cv::Point(u, v) : cv::Point(x, y));
      };
      if (u + 1 < cols && m[u + 1]) look(u + 1, v, d[u + 1]);
      if (last) continue;
      for (int x = std::max(0, u - 1); x <= std::min(cols - 1, u + 1); ++x) {
        if (m_next[x]) look(x, v + 1, d_next[x]);
      }
    }
  }
  for (const cv::Point& p : cleared) mask->at<uint8_t>(p) = 0;
  return static_cast<int>(cleared.size());
}

// How many times smaller the image K-Means clusters is (DetectOptions::kmeans_downsample).
int KMeansFactor(const cv::Mat& bgr, const DetectOptions& options) {
  return options.kmeans_downsample > 0
             ? options.kmeans_downsample
             : std::max(1, static_cast<int>(std::lround(bgr.cols / 256.0)));
}

// Whether the top of `piece_mask` (at `offset` in the image) runs on into what lies over it
// (DetectOptions::attach_margin_ratio). Per column, the top of the piece's colour there
// (`own_colour`, the mask the piece came from, whose outline may lie a pixel or two outside
// the piece's): the mean reading of two of its rows against the farthest of the
// `above_rows` rows over it, one row up (the edge row may read between the two surfaces); the
// two rows are its top two, or for a mask drawn `mask_scale` times coarser than the image
// (K-Means) the two at that depth into it, since its outline may run that far past the
// object's. Not judged: a column whose colour runs on over the piece (an object of its colour
// stacked on it, split off), whose rows over the top carry a target colour (`targets`, every
// target colour's mask: an object of another colour on it) or a shade of the piece's own
// (`bgr`: the dark or highlit part of one of its colour that the mask missed), whose rows over
// it read nothing, or read the floor (under attach_floor_m: it runs on past everything that
// stands on it). True when the median step (over the top minus its own) of the judged
// columns, plus 2 sigma of the median from the depth noise, stays under `margin_m`, with at
// least attach_min_columns, and attach_min_judged of the piece's columns, judged.
bool RunsOnAbove(const cv::Mat& piece_mask, cv::Point offset, const cv::Mat& depth_mm,
                 const cv::Mat& bgr, const ColourClass& colour, const cv::Mat& own_colour,
                 const std::vector<cv::Mat>& targets, const CameraModel& camera,
                 const DetectOptions& options, int mask_scale, double margin_m) {
  // The piece's colour in shade or half in a highlight: its hue, half its saturation and value.
  ColourClass shade = colour;
  shade.min_saturation /= 2;
  shade.min_value /= 2;
  // How far the colour's outline may lie outside the piece's; and a target colour this many
  // rows beyond those read still counts as stacked (K-Means masks, drawn at half resolution
  // and opened, leave a gap of a few rows between colours).
  constexpr int kOutlineRows = 2;
  constexpr int kStackGapRows = 3;
  const int above_rows = options.attach_above_rows;
  std::vector<double> steps;
  double sigma_sum = 0.0;
  int columns = 0;
  for (int u = 0; u < piece_mask.cols; ++u) {
    int top = -1;
    for (int v = 0; v < piece_mask.rows; ++v) {
      if (piece_mask.at<uint8_t>(v, u)) {
        top = v;
        break;
      }
    }
    if (top < 0) continue;
    ++columns;
    const int x = u + offset.x;
    int y = top + offset.y;
    int climbed = 0;
    while (y > 0 && own_colour.at<uint8_t>(y - 1, x) && climbed <= kOutlineRows) --y, ++climbed;
    if (climbed > kOutlineRows) continue;                  // its colour runs on: stacked
    if (y - 1 - above_rows - kStackGapRows < 0) continue;  // the image ends over it
    bool stacked = false;
    for (int k = 1; k <= 1 + above_rows + kStackGapRows && !stacked; ++k)
      stacked = InColourClass(bgr.at<cv::Vec3b>(y - k, x), shade) ||
                std::any_of(targets.begin(), targets.end(),
                            [&](const cv::Mat& m) { return m.at<uint8_t>(y - k, x) != 0; });
    if (stacked) continue;
    double own_sum = 0.0;
    int n_own = 0;
    for (int v = y + mask_scale - 1; v < std::min(depth_mm.rows, y + mask_scale + 1); ++v) {
      const uint16_t raw = depth_mm.at<uint16_t>(v, x);
      if (raw) own_sum += camera.CorrectDepthM(raw), ++n_own;
    }
    if (n_own == 0) continue;
    const double own_m = own_sum / n_own;
    double above = -1.0;
    int above_row = 0;
    for (int k = 2; k <= 1 + above_rows; ++k) {
      const uint16_t raw = depth_mm.at<uint16_t>(y - k, x);
      if (raw && camera.CorrectDepthM(raw) > above)
        above = camera.CorrectDepthM(raw), above_row = y - k;
    }
    if (above < 0.0) continue;
    if (camera.CameraToRobot(camera.BackProject(x, above_row, above)).z() < options.attach_floor_m)
      continue;
    steps.push_back(above - own_m);
    sigma_sum += camera.DepthSigmaM(own_m);
  }
  const int judged = static_cast<int>(steps.size());
  if (judged < options.attach_min_columns || judged < options.attach_min_judged * columns)
    return false;
  std::nth_element(steps.begin(), steps.begin() + judged / 2, steps.end());
  const double median = steps[judged / 2];
  // A step is the difference of two readings (own: the mean of two), sigma x sqrt(1.5); the
  // median of n of them has about 1.25 / sqrt(n) of that.
  const double sigma = 1.25 * std::sqrt(1.5) * (sigma_sum / judged) / std::sqrt(judged);
  return std::abs(median) + 2.0 * sigma <= margin_m;
}

// Clears from `blob_mask` every run of at least `min_run` floating columns (FloatingColumns);
// true when any was cleared. Unknown columns next to floating ones float with them (they show
// nothing standing), and gaps of at most `max_gap` standing columns between floating ones are
// bridged (depth noise; a K-Means mask drawn at half resolution has ragged bottoms).
bool ClearFloatingRuns(std::vector<uint8_t> support, int min_run, int max_gap, cv::Mat* blob_mask) {
  const int n = static_cast<int>(support.size());
  // Unknown runs touching a floating column; then short gaps between floating columns.
  for (int pass = 0; pass < 2; ++pass) {
    for (int u = 0; u < n;) {
      if (support[u] == kFloats) {
        ++u;
        continue;
      }
      int end = u;
      while (end < n && support[end] != kFloats) ++end;
      // Floating on that side (not the blob's end: empty columns are never filled).
      const bool left = u > 0, right = end < n;
      if (std::any_of(support.begin() + u, support.begin() + end,
                      [](uint8_t c) { return c == kEmpty; })) {
        u = end;
        continue;
      }
      bool fill = false;
      if (pass == 0) {
        fill = (left || right) && std::all_of(support.begin() + u, support.begin() + end,
                                              [](uint8_t c) { return c == kUnknown; });
      } else {
        fill = left && right && end - u <= max_gap;
      }
      if (fill) std::fill(support.begin() + u, support.begin() + end, kFloats);
      u = end;
    }
  }
  bool cleared = false;
  for (int u = 0; u < n;) {
    if (support[u] != kFloats) {
      ++u;
      continue;
    }
    int end = u;
    while (end < n && support[end] == kFloats) ++end;
    if (end - u >= min_run) {
      (*blob_mask)(cv::Rect(u, 0, end - u, blob_mask->rows)).setTo(0);
      cleared = true;
    }
    u = end;
  }
  return cleared;
}

// The smallest apparent radius (pixels) of the kinds with a size, each seen `depth_m` in front
// of the camera (its visible surface there); infinity when none has one.
double SmallestApparentRadiusPx(const std::vector<TargetKind>& kinds, double focal_px,
                                double depth_m) {
  double smallest = std::numeric_limits<double>::infinity();
  for (const TargetKind& k : kinds) {
    if (k.radius_m > 0.0)
      smallest = std::min(smallest, focal_px * k.radius_m / (depth_m + k.surface_to_centre_m));
  }
  return smallest;
}

// An object resting on the floor seen without depth: each kind has a range on the ground plane
// (the plane of its centre); the kind whose apparent size fits best at its own range, within
// the size tolerance, sets the detection's kind and measurement. False when none fits.
bool FitOnFloor(const CameraModel& camera, const std::vector<TargetKind>& kinds,
                const DetectOptions& options, Detection* d) {
  double best_ratio = options.size_tolerance;
  for (const TargetKind& k : kinds) {
    if (k.radius_m <= 0.0 || k.centre_height_m <= 0.0) continue;
    std::optional<Measurement> m = GroundPlaneMeasurement(camera, d->centre_px, d->radius_px,
                                                          k.centre_height_m, options.measurement);
    if (!m) continue;
    const double expected = camera.config().fx * k.radius_m / m->depth_m;
    const double ratio = std::max(d->radius_px / expected, expected / d->radius_px);
    if (ratio < best_ratio) best_ratio = ratio, d->kind = k.name, d->measurement = m;
  }
  return d->measurement.has_value();
}

// The extent separation by size uses for a colour's kinds: none when a kind's size is unknown,
// or when its round kinds differ in size (a buckyball beside a large ball). Without round
// kinds the largest kind's extent, so that no one object is ever cut; `kind`: the kind whose
// width it is.
std::optional<ObjectExtent> SizeExtentOf(const std::vector<TargetKind>& kinds,
                                         const DetectOptions& options, const TargetKind** kind) {
  if (kinds.empty()) return std::nullopt;
  const bool all_round =
      std::all_of(kinds.begin(), kinds.end(), [](const TargetKind& k) { return k.round; });
  const bool none_round =
      std::none_of(kinds.begin(), kinds.end(), [](const TargetKind& k) { return k.round; });
  if (!all_round && !none_round) return std::nullopt;
  ObjectExtent extent;
  double widest_m = 0.0;
  for (const TargetKind& k : kinds) {
    if (k.radius_m <= 0.0 || k.centre_height_m <= 0.0) return std::nullopt;
    if (all_round && std::abs(k.radius_m - kinds[0].radius_m) > 0.1 * kinds[0].radius_m)
      return std::nullopt;
    const double reach_m = 2.0 * k.radius_m * options.size_tolerance_horizontal;
    if (reach_m > widest_m) widest_m = reach_m, *kind = &k;
    extent.height_m = std::max(extent.height_m, 2.0 * k.centre_height_m);
    extent.max_stack = std::max(extent.max_stack, k.max_stack);
    extent.rest_heights_m.insert(extent.rest_heights_m.end(), k.rest_heights_m.begin(),
                                 k.rest_heights_m.end());
    extent.rest_max_stack = std::max(extent.rest_max_stack, k.rest_max_stack);
  }
  extent.width_m = 2.0 * (*kind)->radius_m;
  extent.horizontal_limit = widest_m / extent.width_m;
  extent.vertical_limit = options.size_tolerance_vertical;
  return extent;
}

std::vector<TargetKind> KindsOf(const DetectorSetup& setup, const std::string& colour) {
  std::vector<TargetKind> out;
  for (const TargetKind& k : setup.kinds) {
    if (k.colour == colour) out.push_back(k);
  }
  return out;
}

cv::Mat KMeansLabels(const cv::Mat& bgr, const DetectorSetup& setup, const DetectOptions& options,
                     std::vector<int>* cluster_class, cv::Size* small_size) {
  const int ds = KMeansFactor(bgr, options);
  cv::Mat small;
  cv::resize(bgr, small, cv::Size(bgr.cols / ds, bgr.rows / ds), 0, 0, cv::INTER_AREA);
  *small_size = small.size();
  cv::Mat lab;
  cv::cvtColor(small, lab, cv::COLOR_BGR2Lab);
  // Chromatic pixels only: greys (floor, walls, white reflections) carry no hue.
  std::vector<cv::Vec2f> samples;
  std::vector<int> index;
  samples.reserve(lab.total());
  index.reserve(lab.total());
  const float min_chroma2 =
      static_cast<float>(options.kmeans_min_chroma * options.kmeans_min_chroma);
  for (int v = 0; v < lab.rows; ++v) {
    const cv::Vec3b* row = lab.ptr<cv::Vec3b>(v);
    for (int u = 0; u < lab.cols; ++u) {
      const cv::Vec2f ab(row[u][1] - 128.0f, row[u][2] - 128.0f);
      if (ab.dot(ab) >= min_chroma2) samples.push_back(ab), index.push_back(v * lab.cols + u);
    }
  }
  cv::Mat labels_small(small.size(), CV_32SC1, cv::Scalar(-1));
  // Two clusters per colour (lit and shaded sides) plus a few spare, so neighbouring hues
  // (red and orange) do not have to share one.
  const int k = 2 * static_cast<int>(setup.colours.size() + setup.distractors.size()) +
                options.kmeans_extra_clusters;
  cluster_class->assign(k, -1);
  if (static_cast<int>(samples.size()) < k) return labels_small;
  // The centres are learnt on an even subsample (at most kmeans_max_samples); every
  // chromatic pixel then takes its nearest centre.
  const size_t stride = std::max<size_t>(1, samples.size() / options.kmeans_max_samples);
  std::vector<cv::Vec2f> fit_samples;
  for (size_t s = 0; s < samples.size(); s += stride) fit_samples.push_back(samples[s]);
  cv::Mat data(static_cast<int>(fit_samples.size()), 2, CV_32F, fit_samples.data());
  cv::Mat fit_labels, centres;
  cv::theRNG().state = options.seed;  // kmeans++ starts from OpenCV's RNG: seed it
  cv::kmeans(data, k, fit_labels,
             cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT,
                              options.kmeans_iterations, 0.5),
             1, cv::KMEANS_PP_CENTERS, centres);
  std::vector<int> labels(samples.size());
  std::vector<float> centre_a(k), centre_b(k);  // read once, not through cv::Mat::at per sample
  for (int c = 0; c < k; ++c) {
    centre_a[c] = centres.at<float>(c, 0);
    centre_b[c] = centres.at<float>(c, 1);
  }
  for (size_t s = 0; s < samples.size(); ++s) {
    float best = std::numeric_limits<float>::infinity();
    const float a = samples[s][0], b = samples[s][1];
    for (int c = 0; c < k; ++c) {
      const float dx = a - centre_a[c];
      const float dy = b - centre_b[c];
      const float d2 = dx * dx + dy * dy;
      if (d2 < best) best = d2, labels[s] = c;
    }
  }
  // Each cluster joins the class whose hue angle in the a*b* plane is nearest, within a
  // tolerance. The angle, not the distance: a semi-transparent ball has its colour's hue at
  // a fraction of its chroma (the background shows through).
  for (int c = 0; c < k; ++c) {
    const double centre_angle = std::atan2(centres.at<float>(c, 1), centres.at<float>(c, 0));
    double best = options.kmeans_max_angle_deg * M_PI / 180.0;
    const size_t targets = setup.colours.size();
    for (size_t j = 0; j < targets + setup.distractors.size(); ++j) {
      const ColourClass& colour = j < targets ? setup.colours[j] : setup.distractors[j - targets];
      const cv::Vec2f ref = colour.lab_ab - cv::Vec2f(128.0f, 128.0f);
      const double diff =
          std::abs(std::remainder(centre_angle - std::atan2(ref[1], ref[0]), 2.0 * M_PI));
      if (diff < best) best = diff, (*cluster_class)[c] = j < targets ? static_cast<int>(j) : -1;
    }
  }
  int* label_of = labels_small.ptr<int>();  // continuous: index is v * cols + u
  for (size_t s = 0; s < index.size(); ++s) label_of[index[s]] = labels[s];
  return labels_small;
}

// The season's other saturated colours, for K-Means to give their clusters to.
std::vector<ColourClass> Distractors(const field::SeasonConfig& season,
                                     const std::vector<ColourClass>& targets) {
  std::vector<ColourClass> out;
  for (const auto& [name, rgb] : season.colours) {
    if (std::any_of(targets.begin(), targets.end(),
                    [&](const ColourClass& c) { return c.name == name; })) {
      continue;
    }
    try {
      out.push_back(MakeColourClass(name, rgb));
    } catch (const std::invalid_argument&) {
      // A grey: never clustered (below the chroma floor).
    }
  }
  return out;
}

}  // namespace

DetectMethod ParseDetectMethod(const std::string& name) {
  if (name == "threshold") return DetectMethod::kThreshold;
  if (name == "kmeans") return DetectMethod::kKMeans;
  throw std::invalid_argument("unknown detection method '" + name +
                              "': expected threshold or kmeans");
}

const char* ToString(DetectMethod method) {
  return method == DetectMethod::kThreshold ? "threshold" : "kmeans";
}

DetectorSetup ObjectDetectorSetup(const field::SeasonConfig& season,
                                  const field::CameraConfig* camera) {
  DetectorSetup setup;
  setup.colours = ObjectColourClasses(season);
  for (const field::ObjectType& type : season.object_types) {
    for (const std::string& colour : type.colours) {
      TargetKind k;
      k.name = type.name;
      k.colour = colour;
      k.radius_m = type.size_m / 2.0;
      const bool round =
          type.shape == field::ObjectShape::kSphere || type.shape == field::ObjectShape::kTriball;
      // The measured depth is the median over the visible cap of a ball, which lies about
      // r / sqrt(2) in front of its centre (the median of sqrt(1 - rho^2) over a disc); a flat
      // face lies half the smaller extent in front of the centre.
      k.surface_to_centre_m =
          round ? type.size_m / 2.0 / std::sqrt(2.0) : std::min(type.size_m, type.height_m) / 2.0;
      // Round things look round from anywhere; cubes are squares (0.785), rings, stars and
      // blocks seen from a low camera are flat shapes.
      k.min_circularity = round ? 0.6 : 0.3;
      k.round = round;
      k.solid = type.material != field::Material::kSemiTransparent;
      // The tallest stack of this type the season file places (High Stakes' corner rings).
      for (const field::ObjectPlacement& p : season.objects) {
        if (p.type != type.name) continue;
        k.max_stack = std::max(k.max_stack, p.stack_size);
        // (Not round kinds: a ball raised on others, Nothing but Net's bonus balls, rests on
        // no structure, and piles of balls are split by their centres.)
        if (p.z_m > 0.0 && p.stack_level == 0 && !round) {
          k.rest_max_stack = std::max(k.rest_max_stack, p.stack_size);
          if (std::find(k.rest_heights_m.begin(), k.rest_heights_m.end(), p.z_m) ==
              k.rest_heights_m.end())
            k.rest_heights_m.push_back(p.z_m);
        }
      }
      k.centre_height_m = type.height_m / 2.0;
      setup.kinds.push_back(k);
    }
  }
  setup.distractors = Distractors(season, setup.colours);
  if (camera) setup.camera = CameraModel(*camera);
  return setup;
}

DetectorSetup LandmarkDetectorSetup(const field::SeasonConfig& season,
                                    const field::CameraConfig* camera) {
  DetectorSetup setup;
  setup.colours = LandmarkColourClasses(season);
  for (const field::Landmark& l : season.landmarks) {
    TargetKind k;
    k.name = "landmark";
    k.colour = l.colour;
    k.radius_m = l.size_m / 2.0;
    k.surface_to_centre_m =
        l.shape == field::LandmarkShape::kSphere || l.shape == field::LandmarkShape::kCylinder
            ? l.size_m / 2.0
            : 0.0;
    // Discs on a wall seen at an angle are ellipses.
    k.min_circularity = 0.45;
    k.round = false;
    const bool duplicate = std::any_of(
        setup.kinds.begin(), setup.kinds.end(),
        [&](const TargetKind& o) { return o.colour == k.colour && o.radius_m == k.radius_m; });
    if (!duplicate) setup.kinds.push_back(k);
  }
  setup.distractors = Distractors(season, setup.colours);
  if (camera) setup.camera = CameraModel(*camera);
  return setup;
}

DetectorSetup PhotoDetectorSetup(std::vector<ColourClass> colours) {
  DetectorSetup setup;
  setup.colours = std::move(colours);
  for (const ColourClass& c : setup.colours) {
    TargetKind k;
    k.name = "object";
    k.colour = c.name;
    k.min_circularity = 0.6;
    setup.kinds.push_back(k);
  }
  return setup;
}

std::vector<cv::Mat> ColourMasks(const cv::Mat& bgr, const DetectorSetup& setup,
                                 const DetectOptions& options) {
  std::vector<cv::Mat> masks;
  if (options.method == DetectMethod::kThreshold) {
    masks = ThresholdBgr(bgr, setup.colours);  // ThresholdHsv's masks, without the HSV image
  } else {
    std::vector<int> cluster_class;
    cv::Size small_size;
    const cv::Mat labels = KMeansLabels(bgr, setup, options, &cluster_class, &small_size);
    for (size_t j = 0; j < setup.colours.size(); ++j) {
      cv::Mat small(small_size, CV_8UC1, cv::Scalar(0));
      for (int v = 0; v < labels.rows; ++v) {
        const int* l = labels.ptr<int>(v);
        uint8_t* m = small.ptr<uint8_t>(v);
        for (int u = 0; u < labels.cols; ++u) {
          if (l[u] >= 0 && cluster_class[l[u]] == static_cast<int>(j)) m[u] = 255;
        }
      }
      cv::Mat full;
      cv::resize(small, full, bgr.size(), 0, 0, cv::INTER_LINEAR);
      cv::threshold(full, full, 127, 255, cv::THRESH_BINARY);
      masks.push_back(full);
    }
  }
  // Remove speckle only; object-scale cleaning happens per blob, at its depth.
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3));
  for (cv::Mat& m : masks) cv::morphologyEx(m, m, cv::MORPH_OPEN, kernel);
  return masks;
}

std::vector<Detection> Detect(const cv::Mat& bgr, const cv::Mat& depth_mm,
                              const DetectorSetup& setup, const DetectOptions& options,
                              DetectStats* stats) {
  CheckInput(bgr, depth_mm);
  DetectStats local;
  DetectStats& st = stats ? *stats : local;
  const bool have_depth = !depth_mm.empty() && setup.camera.has_value();
  const double focal = setup.camera ? setup.camera->config().fx : 0.0;
  const std::vector<cv::Mat> masks = ColourMasks(bgr, setup, options);
  std::vector<Detection> out;

  for (size_t j = 0; j < setup.colours.size(); ++j) {
    const ColourClass& colour = setup.colours[j];
    const std::vector<TargetKind> kinds = KindsOf(setup, colour.name);
    if (kinds.empty()) continue;
    double min_circularity = 1.0;
    for (const TargetKind& k : kinds)
      min_circularity = std::min(min_circularity, k.min_circularity);
    const bool all_solid =
        std::all_of(kinds.begin(), kinds.end(), [](const TargetKind& k) { return k.solid; });
    const bool none_round =
        std::none_of(kinds.begin(), kinds.end(), [](const TargetKind& k) { return k.round; });
    const bool all_round =
        std::all_of(kinds.begin(), kinds.end(), [](const TargetKind& k) { return k.round; });
    const bool semi_round = all_round && !all_solid;  // a semi-transparent ball among them
    // The semi-transparent ball among them (the largest, if more than one), for the depth's
    // test of a ragged one (DetectOptions::semi_sphere_pieces; K-Means only, unless asked).
    const TargetKind* semi_kind = nullptr;
    if (options.semi_sphere_pieces &&
        (options.method == DetectMethod::kKMeans || options.semi_sphere_threshold)) {
      for (const TargetKind& k : kinds) {
        if (k.round && !k.solid && (!semi_kind || k.radius_m > semi_kind->radius_m)) semi_kind = &k;
      }
    }

    std::vector<std::vector<cv::Point>> blobs;
    // Cut at depth edges, a blob's region may hold another's (an object framed by the poster
    // behind it): each 8-connected region is then outlined on its own, and a blob's filled
    // outline leaves out the regions it holds (blob_label: the region of each blob found).
    cv::Mat labels;
    std::vector<int> blob_label;
    if (have_depth && all_solid && options.depth_cut_min_m > 0.0) {
      cv::Mat cut = masks[j].clone();
      const double cut_min_m = none_round && options.depth_cut_min_flat_m > 0.0
                                   ? options.depth_cut_min_flat_m
                                   : options.depth_cut_min_m;
      if (CutAtDepthEdges(depth_mm, *setup.camera, options, cut_min_m, &cut) > 0) {
        cv::Mat region_stats, centroids;
        const int regions =
            cv::connectedComponentsWithStats(cut, labels, region_stats, centroids, 8, CV_32S);
        std::vector<std::vector<cv::Point>> outline;
        for (int r = 1; r < regions; ++r) {
          // A region smaller than any blob kept (a speck the cut left) is not outlined.
          if (region_stats.at<int>(r, cv::CC_STAT_AREA) < options.min_area_px) {
            ++st.rejected_small;
            continue;
          }
          const cv::Rect roi(region_stats.at<int>(r, cv::CC_STAT_LEFT),
                             region_stats.at<int>(r, cv::CC_STAT_TOP),
                             region_stats.at<int>(r, cv::CC_STAT_WIDTH),
                             region_stats.at<int>(r, cv::CC_STAT_HEIGHT));
          FindOuterContours(labels(roi) == r, &outline, roi.tl());
          for (std::vector<cv::Point>& o : outline) {
            blobs.push_back(std::move(o));
            blob_label.push_back(r);
          }
        }
      }
    }
    if (labels.empty()) FindOuterContours(masks[j], &blobs);  // leaves the mask as it is
    // Blobs found in the mask; what is left of one after its floating part is cleared is
    // appended, and not tested again.
    const size_t found_blobs = blobs.size();
    for (size_t b = 0; b < blobs.size(); ++b) {
      const std::vector<cv::Point>& blob = blobs[b];
      const double blob_area = cv::contourArea(blob);
      if (blob_area < options.min_area_px) {
        ++st.rejected_small;
        continue;
      }
      ++st.blobs;
      // The blob, filled (highlights and reflections inside it are part of the object), in
      // a padded window of its own.
      const cv::Rect blob_box = cv::boundingRect(blob);
      const cv::Rect box = blob_box & cv::Rect(0, 0, bgr.cols, bgr.rows);
      const cv::Rect window =
          (box + cv::Size(8, 8) - cv::Point(4, 4)) & cv::Rect(0, 0, bgr.cols, bgr.rows);
      cv::Mat blob_mask(window.size(), CV_8UC1, cv::Scalar(0));
      FillOutline(blob, -window.tl(), &blob_mask);
      if (b < blob_label.size() && blob_label[b] > 0) {
        for (int v = 0; v < window.height; ++v) {
          const int* region = labels.ptr<int>(window.y + v) + window.x;
          uint8_t* m = blob_mask.ptr<uint8_t>(v);
          for (int u = 0; u < window.width; ++u) {
            if (region[u] > 0 && region[u] != blob_label[b]) m[u] = 0;
          }
        }
      }
      // The outline filled (after a split by size, eroded by a pixel, as it was measured
      // with), until a closing changes it.
      bool blob_mask_is_fill = true;

      // At its depth, how big should it be? Too small for every kind: noise (not eroded
      // away at a fixed size, which erased far balls in the thesis).
      double expected_radius_px = 0.0;
      double largest_extent_px = 0.0;  // the widest any one kind of this colour can look here
      double blob_depth_m = 0.0;       // corrected median depth (0: none)
      if (have_depth) {
        const double raw =
            MedianDepthMm(depth_mm(window), blob_mask, cv::Rect(cv::Point(), window.size()));
        if (raw > 0.0) {
          const double z = setup.camera->CorrectDepthM(raw);
          blob_depth_m = z;
          for (const TargetKind& k : kinds) {
            largest_extent_px = std::max(
                largest_extent_px, focal * std::hypot(2.0 * k.radius_m, 2.0 * k.centre_height_m) /
                                       (z + k.surface_to_centre_m));
          }
          for (const TargetKind& k : kinds) {
            if (k.radius_m > 0.0)
              expected_radius_px =
                  std::max(expected_radius_px, focal * k.radius_m / (z + k.surface_to_centre_m));
          }
          const double smallest = SmallestApparentRadiusPx(kinds, focal, z);
          if (std::isfinite(smallest) &&
              blob_area < options.min_expected_area_ratio * M_PI * smallest * smallest) {
            ++st.rejected_small;
            continue;
          }
          // K-Means masks have gaps at reflections on the rim: close them at the object's scale.
          if (options.method == DetectMethod::kKMeans && expected_radius_px > 6.0) {
            const int k = std::max(3, static_cast<int>(0.15 * expected_radius_px) | 1);
            blob_mask_is_fill = false;
            CloseBinary(&blob_mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
          }
        }
      }

      // Nothing floats: the part of a blob held off the floor over nothing (a robot's bumper,
      // alone or touching an object of its colour) is not an object, and is cleared; what is
      // left is looked at as blobs of its own. Only for solid kinds (depth reads their
      // surface) with a flat base, not round ones (a ball or a triball shows the floor under
      // its curve; the bulge test judges those).
      if (options.drop_floating && b < found_blobs && blob_depth_m > 0.0 && all_solid &&
          none_round) {
        cv::Mat kept = blob_mask.clone();
        // A run narrower than this may be the overhang of an object on a thin support (a cube
        // on a post): left.
        const int min_run = std::max(
            options.float_min_columns,
            static_cast<int>(std::ceil(options.float_min_run_widths * 2.0 * expected_radius_px)));
        if (ClearFloatingRuns(
                FloatingColumns(blob_mask, window.tl(), depth_mm, *setup.camera, options), min_run,
                std::max(2, min_run / 4), &kept)) {
          ++st.rejected_floating;
          std::vector<std::vector<cv::Point>> rest;
          FindOuterContours(kept, &rest, window.tl());
          // What is left keeps the blob's region: its filled outline still leaves out the
          // regions the blob holds.
          const int region = b < blob_label.size() ? blob_label[b] : 0;
          for (std::vector<cv::Point>& r : rest) {
            blobs.push_back(std::move(r));  // `blob` dangles
            if (region > 0) {
              blob_label.resize(blobs.size() - 1, 0);
              blob_label.push_back(region);
            }
          }
          continue;
        }
      }

      // Touching objects: one piece each. A blob that fills its convex hull is one object
      // (two balls overlapping by 45 % of a diameter still fill only 97.8 %).
      // Kinds that are not round (rings, cubes, stars, blocks) have concave outlines of their
      // own: with depth, when none of the colour's kinds is round, a blob no wider and no
      // taller than one of them can look (its diagonal) is that one object, never cut.
      const bool one_object = none_round && largest_extent_px > 0.0 &&
                              box.width <= largest_extent_px + options.extent_margin_px &&
                              box.height <= largest_extent_px + options.extent_margin_px;
      // With depth, objects of a known size are split by it: every blob of a colour with no
      // round kind (rings, stacks, blocks), and piles of round objects of one size.
      const TargetKind* size_kind = nullptr;
      std::optional<ObjectExtent> size_extent;
      if (options.split_by_size && blob_depth_m > 0.0) {
        size_extent = SizeExtentOf(kinds, options, &size_kind);
        if (size_extent && all_round && !options.split_piles_by_size) size_extent.reset();
        if (size_extent && all_round) {
          const double metres_per_px = blob_depth_m / focal;
          const double object_area_m2 = M_PI * size_kind->radius_m * size_kind->radius_m;
          if (blob_area * metres_per_px * metres_per_px < options.pile_area_ratio * object_area_m2)
            size_extent.reset();
        }
      }
      SizeSplitResult sized;
      // Solid balls of one size (spheres, and triballs, which are near enough) are counted by
      // their centres; other kinds of the colour (a semi-transparent ball) may share the blob,
      // which the balls then do not explain (SplitSpheres finds none).
      const TargetKind* ball_kind = nullptr;
      if (options.split_spheres && blob_depth_m > 0.0) {
        for (const TargetKind& k : kinds) {
          if (!k.solid || !k.round) continue;
          if (ball_kind && std::abs(k.radius_m - ball_kind->radius_m) > 0.1 * ball_kind->radius_m) {
            ball_kind = nullptr;
            break;
          }
          if (!ball_kind) ball_kind = &k;
        }
      }
      // Tried again on a piece of the cut that is no ball (below), whatever the blob.
      const TargetKind* const piece_ball_kind = options.split_sphere_pieces ? ball_kind : nullptr;
      // A blob that fills its convex hull is one ball (or a ball with a sliver of one behind);
      // so is one no larger than a ball and a tenth looks at its depth.
      if (ball_kind) {
        const double ball_px =
            focal * ball_kind->radius_m / (blob_depth_m + ball_kind->surface_to_centre_m);
        if (blob_area < options.sphere_split_min_area * M_PI * ball_px * ball_px ||
            blob_area >= options.single_object_solidity * ConvexHullArea(blob, blob_box))
          ball_kind = nullptr;
      }
      if (ball_kind) {
        SphereSplitResult balls =
            SplitSpheres(blob_mask, depth_mm(window), window.tl(), *setup.camera,
                         ball_kind->radius_m, options.sphere_split);
        if (balls.objects > 1) {
          ++st.split_spheres;
          sized.objects = balls.objects;
          sized.pieces = std::move(balls.pieces);
          size_extent.reset();
        }
      }
      if (size_extent) {
        // Piles of round objects are clustered whole: a ball half hidden behind another shows
        // a cap whose footprint lies apart from the front ball's crescent, and taking the
        // footprint apart there cost Nothing but Net's arena precision 0.954 -> 0.939.
        // Nor are slivers of round objects dropped from their piles: one refuses the pile (with
        // them dropped, Nothing but Net's arena precision fell 0.959 -> 0.900 for recall 0.712
        // -> 0.744: balls are cut into more pieces by size than by their arcs).
        SizeSplitOptions split_options = options.size_split;
        if (all_round) {
          split_options.link_fraction = 0.0;
          split_options.sliver_fraction = 0.0;
          split_options.min_top_depth = split_options.min_top_depth_round;
          // Grown over each other, a pile's balls keep the pieces the bulge, curvature and
          // attach tests were measured on (kept apart, more of Over Under's bumper pieces
          // passed those tests, and its piles were counted worse).
          split_options.exclusive_growth = false;
        }
        sized = SplitBySize(blob_mask, depth_mm(window), window.tl(), *setup.camera, *size_extent,
                            split_options);
        if (sized.objects > 1) ++st.split_by_size;
        // What follows (the defect cut, the shape tests, the measurement) sees the blob
        // without its rim, as it was measured with.
        if (split_options.erode_px > 0) {
          cv::erode(blob_mask, blob_mask, cv::Mat(), cv::Point(-1, -1), split_options.erode_px);
        }
      }
      const bool convex =
          sized.objects == 1 ||
          (sized.objects == 0 && (one_object || blob_area >= options.single_object_solidity *
                                                                 ConvexHullArea(blob, blob_box)));
      SeparationResult separated;
      // Pieces whose kind is already known (a semi-transparent ball found by its depth), by
      // index into separated.pieces.
      std::map<size_t, const TargetKind*> piece_kinds;
      // A semi-transparent ball shows what lies behind it through its face: a buckyball, a
      // highlight or the floor's seams notch its mask, and the cut at concave defects takes it
      // apart there. When the blob's own outline (not the image border) is in good part a
      // circle the blob fills, that disc is one piece, and what lies outside it is separated
      // on its own.
      std::vector<cv::Point> disc;
      double disc_radius_px = 0.0;
      if (sized.objects <= 1 && !convex && semi_round && options.min_disc_fill > 0.0) {
        std::vector<cv::Point> arc;
        for (const cv::Point& p : blob) {
          if (p.x > 1 && p.y > 1 && p.x < bgr.cols - 2 && p.y < bgr.rows - 2) arc.push_back(p);
        }
        double inliers = 0.0;
        const std::optional<ArcFit> fit = FitArc(arc, &inliers);
        if (fit && fit->rms <= options.max_arc_rms_ratio * fit->radius &&
            fit->coverage_deg >= options.min_arc_coverage_deg &&
            fit->radius <= 2.0 * std::sqrt(blob_area / M_PI) + 2.0 &&
            CircleOnOutline(arc, *fit, bgr.size()) >= options.min_disc_outline) {
          disc = blob;
          if (!CropToDisc(*fit, bgr.size(), options.min_disc_fill, &disc)) disc.clear();
          disc_radius_px = fit->radius;
        }
      }
      // The balls found whole (a disc, or semi-transparent balls by their depth, below) are
      // the first pieces; the rest of the blob, 2 px clear of them (their rims are theirs),
      // goes on as pieces of its own, not cut further (cut at its concave defects, Toss Up's
      // arena views lost groups, 0.682 -> 0.667 of 66, measured with min_disc_outline 0.6).
      const auto add_rest = [&](double ball_radius_px) {
        cv::Mat balls_mask(window.size(), CV_8UC1, cv::Scalar(0));
        for (const std::vector<cv::Point>& ball : separated.pieces)
          FillOutline(ball, cv::Point(), &balls_mask);
        cv::dilate(balls_mask, balls_mask, cv::Mat(), cv::Point(-1, -1), 2);
        cv::Mat rest = blob_mask.clone();
        rest.setTo(0, balls_mask);
        // Slivers along the rim (the outline outside the circle, a highlight's edge) are the
        // ball's: what is thinner than a seventh of its radius goes.
        const int k = std::max(3, static_cast<int>(0.15 * ball_radius_px) | 1);
        cv::morphologyEx(rest, rest, cv::MORPH_OPEN,
                         cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
        std::vector<std::vector<cv::Point>> parts;
        FindOuterContours(rest, &parts);
        for (std::vector<cv::Point>& part : parts) {
          if (cv::contourArea(part) >= options.min_area_px) {
            separated.pieces.push_back(std::move(part));
          }
        }
      };
      if (!disc.empty()) {
        ++st.semi_discs;
        for (cv::Point& p : disc) p -= window.tl();
        separated.pieces.push_back(std::move(disc));
        add_rest(disc_radius_px);
      } else if (sized.objects > 1) {
        separated.pieces = std::move(sized.pieces);
      } else if (convex) {
        std::vector<cv::Point> shifted = blob;
        for (cv::Point& p : shifted) p -= window.tl();
        separated.pieces.push_back(std::move(shifted));
      } else if (blob_mask.total() > options.separation_max_pixels) {
        // Large blobs are separated at a reduced scale: the cut positions need no more
        // than a few hundred pixels across the blob.
        const double scale =
            std::sqrt(static_cast<double>(options.separation_max_pixels) / blob_mask.total());
        cv::Mat small;
        // cv::resize(INTER_AREA) and a threshold at 127, byte for byte
        ShrinkMaskLike(blob_mask, scale, &small);
        separated = SeparateTouching(small, options.separation, options.separation_options);
        for (std::vector<cv::Point>& piece : separated.pieces) {
          for (cv::Point& p : piece) {
            p = cv::Point(static_cast<int>(std::lround((p.x + 0.5) / scale - 0.5)),
                          static_cast<int>(std::lround((p.y + 0.5) / scale - 0.5)));
          }
        }
      } else {
        separated = SeparateTouching(blob_mask, options.separation, options.separation_options);
      }
      bool split = separated.pieces.size() > 1;
      const bool by_size = sized.objects > 1;
      // Left whole: the one piece is the blob's own outline (convex, or nothing to cut).
      bool whole =
          convex ||
          (separated.pieces.size() == 1 &&
           std::equal(
               blob.begin(), blob.end(), separated.pieces[0].begin(), separated.pieces[0].end(),
               [&](const cv::Point& b, const cv::Point& p) { return b == p + window.tl(); }));
      // The blob's own outline (not cuts, not the image border): where arcs of objects show.
      // Not needed for a blob left whole: every point of its piece is on the outline.
      const auto blob_outline = [&]() {
        cv::Mat out(window.size(), CV_8UC1, cv::Scalar(0));
        for (const cv::Point& p : blob) out.at<uint8_t>(p - window.tl()) = 255;
        DilateLike(out, cv::Mat(), &out);  // 3x3: a piece's outline may shift by a pixel
        return out;
      };
      cv::Mat outline;
      if (all_round && !whole && !by_size) outline = blob_outline();
      // Round objects: a circle through the visible arcs of a piece's outline (image
      // coordinates) gives the centre and radius even when a cut, another object or the image
      // border hides part of it; nothing when no circle fits them.
      const auto fit_arc = [&](const std::vector<cv::Point>& piece,
                               double area_px) -> std::optional<ArcFit> {
        std::vector<cv::Point> arc;
        for (const cv::Point& p : piece) {
          const cv::Point local = p - window.tl();
          const bool on_border = p.x <= 1 || p.y <= 1 || p.x >= bgr.cols - 2 || p.y >= bgr.rows - 2;
          if (!on_border && (whole || outline.at<uint8_t>(local))) arc.push_back(p);
        }
        double inliers = 0.0;
        std::optional<ArcFit> fit = FitArc(arc, &inliers);
        if (!fit || inliers < options.min_arc_inlier_fraction ||
            fit->rms > options.max_arc_rms_ratio * fit->radius ||
            fit->coverage_deg < options.min_arc_coverage_deg ||
            fit->radius > 2.0 * std::sqrt(area_px / M_PI) + 2.0) {
          return std::nullopt;
        }
        return fit;
      };
      // A semi-transparent ball the cut took apart (notched where what lies behind shows
      // through it) or left whole but ragged: when a piece of the blob fits no circle, the
      // blob's depth may lie on the front of a ball (or two) of the kind's size that explains
      // it and fills its disc in the image; those balls are then the pieces, and the rest of
      // the blob goes on apart. (Asked only when a piece fits no circle: most blobs are balls
      // the cut parts well, and the depth's test costs.)
      const double semi_px =
          semi_kind ? focal * semi_kind->radius_m / (blob_depth_m + semi_kind->surface_to_centre_m)
                    : 0.0;
      if (semi_kind && have_depth && blob_depth_m > 0.0 && disc.empty() && !by_size && all_round &&
          blob_area >= options.semi_sphere_min_area * M_PI * semi_px * semi_px &&
          std::any_of(separated.pieces.begin(), separated.pieces.end(),
                      [&](const std::vector<cv::Point>& local) {
                        std::vector<cv::Point> piece = local;
                        for (cv::Point& p : piece) p += window.tl();
                        const double area = cv::contourArea(piece);
                        return area >= options.min_area_px && !fit_arc(piece, area);
                      })) {
        SphereSplitResult balls =
            SplitSpheres(blob_mask, depth_mm(window), window.tl(), *setup.camera,
                         semi_kind->radius_m, options.semi_sphere_split);
        if (balls.objects >= 1 &&
            BallsFillDiscs(balls, semi_kind->radius_m, *setup.camera, blob_mask, window.tl(),
                           bgr.size(), options.semi_sphere_min_fill)) {
          ++st.semi_spheres;
          separated.pieces = std::move(balls.pieces);
          for (size_t b = 0; b < separated.pieces.size(); ++b) piece_kinds[b] = semi_kind;
          add_rest(semi_px);
          split = separated.pieces.size() > 1;
          whole = false;
          if (outline.empty()) outline = blob_outline();  // for the rest's arcs
        }
      }
      // Pieces from a piece of the cut that no circle fits, split by the balls' centres, are
      // appended from here on.
      const size_t first_ball_piece = separated.pieces.size();
      for (size_t piece_index = 0; piece_index < separated.pieces.size(); ++piece_index) {
        std::vector<cv::Point> piece = separated.pieces[piece_index];
        const bool piece_sized =
            by_size || piece_index >= first_ball_piece || piece_kinds.count(piece_index) > 0;
        ++st.pieces;
        for (cv::Point& p : piece) p += window.tl();
        Detection d;
        d.colour = colour.name;
        d.split = split || piece_sized;
        d.sized = piece_sized;
        d.area_px = cv::contourArea(piece);
        if (d.area_px < options.min_area_px) {
          ++st.rejected_small;
          continue;
        }
        const double perimeter = cv::arcLength(piece, true);
        d.circularity = perimeter > 0.0 ? 4.0 * M_PI * d.area_px / (perimeter * perimeter) : 0.0;
        d.box = cv::boundingRect(piece);
        if (all_round && !piece_sized) {
          const std::optional<ArcFit> fit = fit_arc(piece, d.area_px);
          if (!fit) {
            // Balls of a size in the piece, by their centres (vision/sphere_split.h), as pieces
            // of their own from here on (of `kind`, when given).
            const cv::Rect bounds =
                (d.box + cv::Size(4, 4) - cv::Point(2, 2)) & cv::Rect(0, 0, bgr.cols, bgr.rows);
            cv::Mat piece_mask;
            const auto balls_in_piece = [&](double radius_m, const SphereSplitOptions& split) {
              if (piece_mask.empty()) {
                piece_mask = cv::Mat(bounds.size(), CV_8UC1, cv::Scalar(0));
                FillOutline(piece, -bounds.tl(), &piece_mask);
              }
              return SplitSpheres(piece_mask, depth_mm(bounds), bounds.tl(), *setup.camera,
                                  radius_m, split);
            };
            const auto add_balls = [&](SphereSplitResult* balls, const TargetKind* kind) {
              for (std::vector<cv::Point>& ball : balls->pieces) {
                for (cv::Point& p : ball) p += bounds.tl() - window.tl();
                if (kind) piece_kinds[separated.pieces.size()] = kind;
                separated.pieces.push_back(std::move(ball));
              }
            };
            // Two balls or more that the cut left together (one behind another, or beside
            // a larger object of their colour the whole blob's split could not explain).
            const double piece_ball_px =
                piece_ball_kind ? focal * piece_ball_kind->radius_m /
                                      (blob_depth_m + piece_ball_kind->surface_to_centre_m)
                                : 0.0;
            if (piece_ball_kind && have_depth &&
                d.area_px >= options.sphere_split_min_area * M_PI * piece_ball_px * piece_ball_px) {
              SphereSplitResult balls =
                  balls_in_piece(piece_ball_kind->radius_m, options.sphere_split);
              if (balls.objects > 1) {
                ++st.split_spheres;
                add_balls(&balls, nullptr);
                continue;  // split, not rejected
              }
            }
            // A semi-transparent ball: its depth on the front of one ball of its size.
            if (semi_kind && have_depth && blob_depth_m > 0.0 &&
                d.area_px >= options.semi_sphere_min_area * M_PI * semi_px * semi_px) {
              SphereSplitResult balls =
                  balls_in_piece(semi_kind->radius_m, options.semi_sphere_split);
              if (balls.objects >= 1 &&
                  BallsFillDiscs(balls, semi_kind->radius_m, *setup.camera, piece_mask, bounds.tl(),
                                 bgr.size(), options.semi_sphere_min_fill)) {
                ++st.semi_spheres;
                add_balls(&balls, semi_kind);
                continue;  // found, not rejected
              }
            }
            ++st.rejected_shape;
            continue;
          }
          d.centre_px = fit->centre;
          d.radius_px = fit->radius;
          d.score =
              std::clamp(1.0 - fit->rms / (options.max_arc_rms_ratio * fit->radius), 0.0, 1.0) *
              std::min(1.0, fit->coverage_deg / 360.0 + 0.25);
        } else {
          if (!piece_sized && d.circularity < min_circularity) {
            ++st.rejected_shape;
            continue;
          }
          const cv::Moments m = cv::moments(piece);
          d.centre_px = cv::Point2d(m.m10 / m.m00, m.m01 / m.m00);
          d.radius_px = std::sqrt(d.area_px / M_PI);
          d.score = std::min(1.0, d.circularity / 0.785);
        }
        d.contour = piece;

        if (have_depth) {
          // The piece's own window: measuring never needs the whole image.
          const int pad = options.measurement.erode_px + 2;
          const cv::Rect roi = (d.box + cv::Size(2 * pad, 2 * pad) - cv::Point(pad, pad)) &
                               cv::Rect(0, 0, bgr.cols, bgr.rows);
          cv::Mat piece_mask;
          if (whole && !piece_sized && blob_mask_is_fill && roi == window) {
            piece_mask = blob_mask;  // the same contour in the same window: no redraw
          } else {
            piece_mask = cv::Mat(roi.size(), CV_8UC1, cv::Scalar(0));
            FillOutline(piece, -roi.tl(), &piece_mask);
          }
          const cv::Mat depth_roi = depth_mm(roi);
          // The kind whose size fits best.
          const std::optional<BlobSurface> surface =
              MeasureBlobSurface(depth_roi, piece_mask, *setup.camera, options.measurement);
          if (!surface) {
            // No reading on it (too near or far, black, glare): kept when it has the size of
            // a kind resting on the floor at the ground-plane range, typed but not ranged.
            Detection on_floor = d;
            if (!FitOnFloor(*setup.camera, kinds, options, &on_floor) && on_floor.kind.empty() &&
                std::any_of(kinds.begin(), kinds.end(),
                            [](const TargetKind& k) { return k.centre_height_m > 0.0; })) {
              ++st.rejected_size;
              continue;
            }
            d.kind = on_floor.kind;
            ++st.without_depth;
          } else {
            if (piece_sized && options.min_sized_area_ratio > 0.0) {
              // ... but not a strip of its rim under a tenth of the smallest kind's area at
              // its depth (mixed readings there cluster apart on the floor).
              const double smallest = SmallestApparentRadiusPx(kinds, focal, surface->depth_m);
              if (std::isfinite(smallest) &&
                  d.area_px < options.min_sized_area_ratio * M_PI * smallest * smallest) {
                ++st.rejected_small;
                continue;
              }
            }
            // A piece split off by size is an object: only its kind is in question.
            const TargetKind* best = nullptr;
            double best_ratio =
                piece_sized ? std::numeric_limits<double>::infinity() : options.size_tolerance;
            for (const TargetKind& k : kinds) {
              if (k.radius_m <= 0.0) continue;
              const double expected =
                  focal * k.radius_m / (surface->depth_m + k.surface_to_centre_m);
              const double ratio = std::max(d.radius_px / expected, expected / d.radius_px);
              if (ratio < best_ratio) best_ratio = ratio, best = &k;
            }
            // (Not a piece the image's edge cuts: its box is not the object's.)
            const bool at_edge = d.box.x <= 0 || d.box.y <= 0 || d.box.br().x >= bgr.cols ||
                                 d.box.br().y >= bgr.rows;
            if (!best && options.flat_side_pieces && !piece_sized && !at_edge) {
              // The side of a flat kind whose top is hidden: by its width and its height.
              for (const TargetKind& k : kinds) {
                if (k.round || k.radius_m <= 0.0 || k.centre_height_m <= 0.0 ||
                    4.0 * k.centre_height_m >= 2.0 * k.radius_m) {
                  continue;
                }
                const double at_m = surface->depth_m + k.surface_to_centre_m;
                const double width_px = focal * 2.0 * k.radius_m / at_m;
                const double thick_px = focal * 2.0 * k.centre_height_m / at_m;
                const double w = d.box.width, h = d.box.height;
                const double ratio = std::max(w / width_px, width_px / w);
                if (ratio < best_ratio && h >= 0.5 * thick_px &&
                    h <= options.size_tolerance * thick_px) {
                  best_ratio = ratio, best = &k;
                }
              }
            }
            if (!best) {
              ++st.rejected_size;
              continue;
            }
            if (options.type_height_ratio > 0.0) {
              // Kinds that fit by size but stand at clearly different heights: by the height.
              std::vector<const TargetKind*> fitting;
              double lowest = std::numeric_limits<double>::infinity(), highest = 0.0;
              for (const TargetKind& k : kinds) {
                if (k.radius_m <= 0.0 || k.centre_height_m <= 0.0) continue;
                const double expected =
                    focal * k.radius_m / (surface->depth_m + k.surface_to_centre_m);
                if (std::max(d.radius_px / expected, expected / d.radius_px) >
                    options.size_tolerance)
                  continue;
                fitting.push_back(&k);
                lowest = std::min(lowest, 2.0 * k.centre_height_m);
                highest = std::max(highest, 2.0 * k.centre_height_m);
              }
              // (Not with a semi-transparent kind among them: depth reads through it.)
              const bool all_solid_fit = std::all_of(fitting.begin(), fitting.end(),
                                                     [](const TargetKind* k) { return k->solid; });
              if (fitting.size() > 1 && all_solid_fit &&
                  highest >= options.type_height_ratio * lowest) {
                const double height =
                    StandingHeightM(piece_mask, roi.tl(), depth_mm, *setup.camera);
                double nearest = std::numeric_limits<double>::infinity();
                for (const TargetKind* k : fitting) {
                  const double off = height > 0.0
                                         ? std::abs(std::log(height / (2.0 * k->centre_height_m)))
                                         : nearest;
                  if (off < nearest) nearest = off, best = k;
                }
              }
            }
            if (const auto known = piece_kinds.find(piece_index); known != piece_kinds.end())
              best = known->second;
            if (options.drop_too_tall && !piece_sized && !best->round) {
              // Taller than the kind can stand, on its edge (its width) or in the tallest
              // stack the season places: an upright bar or panel of its colour.
              const double tallest = std::max(
                  2.0 * best->radius_m, 2.0 * best->centre_height_m * std::max(1, best->max_stack));
              if (StandingHeightM(piece_mask, roi.tl(), depth_mm, *setup.camera) >
                  options.size_tolerance_vertical * tallest) {
                ++st.rejected_size;
                continue;
              }
            }
            if (best->round && best->solid && options.min_bulge_ratio > 0.0) {
              // The bands at the kind's apparent radius at this depth, not the piece's own: a
              // ball partly hidden behind others shows a smaller piece of the same curve.
              const double apparent_px =
                  focal * best->radius_m / (surface->depth_m + best->surface_to_centre_m);
              // Flat: within the noise of no bulge either way (a piece whose centre reads
              // deeper than its rims is something else: two objects at different depths),
              // across the rows or across the columns (a box's edge curves one way only).
              const auto flat = [&](bool along_columns) {
                std::optional<SurfaceBulge> bulge = MeasureSurfaceBulge(
                    depth_roi, piece_mask, d.centre_px - cv::Point2d(roi.tl()),
                    std::max(d.radius_px, apparent_px), *setup.camera, along_columns);
                // A piece narrower than the kind (a bumper cut to its size) has no rims that
                // far out: its own extent then.
                if (!bulge)
                  bulge = MeasureSurfaceBulge(depth_roi, piece_mask,
                                              d.centre_px - cv::Point2d(roi.tl()), d.radius_px,
                                              *setup.camera, along_columns);
                return bulge && std::abs(bulge->bulge_m) + 3.0 * bulge->sigma_m <
                                    options.min_bulge_ratio * best->radius_m;
              };
              if (flat(false) || flat(true)) {
                ++st.rejected_flat;
                continue;
              }
              if (options.flat_curvature_ratio > 0.0) {
                const std::optional<LeastCurvature> least = MeasureLeastCurvature(
                    depth_roi, piece_mask, roi.tl(), *setup.camera, surface->depth_m,
                    best->radius_m, options.measurement.erode_px);
                // Signed: a ball curves away from the camera every way, so the lowest
                // curvature is judged (not the one nearest zero): a piece curving towards it
                // along some direction (a saddle where a bumper meets its chassis, a hollow)
                // is not one, however strongly it curves either way.
                const double curvature = !least                     ? 0.0
                                         : options.convex_curvature ? least->lowest
                                                                    : std::abs(least->curvature);
                const double sigma = !least                     ? 0.0
                                     : options.convex_curvature ? least->lowest_sigma
                                                                : least->sigma;
                if (least && curvature + options.flat_curvature_sigmas * sigma <
                                 options.flat_curvature_ratio / best->radius_m) {
                  ++st.rejected_flat;
                  continue;
                }
              }
            }
            if (best->round && best->solid && options.attach_margin_ratio > 0.0) {
              // The least step anything touching the object from behind can show over its
              // top, seen down at alpha (the ray through the piece's top): r (1 - sin alpha)
              // / cos alpha; r when seen level or from below.
              const CameraModel& camera = *setup.camera;
              const Eigen::Vector3d ray =
                  camera.CameraToRobot(camera.BackProject(d.centre_px.x, d.box.y, 1.0)) -
                  camera.CameraToRobot(Eigen::Vector3d::Zero());
              const double alpha =
                  std::max(0.0, std::atan2(-ray.z(), std::hypot(ray.x(), ray.y())));
              const double least_step = best->radius_m * (1.0 - std::sin(alpha)) / std::cos(alpha);
              const bool drop = RunsOnAbove(
                  piece_mask, roi.tl(), depth_mm, bgr, colour, masks[j], masks, camera, options,
                  options.method == DetectMethod::kKMeans ? KMeansFactor(bgr, options) : 1,
                  options.attach_margin_ratio * least_step);
              if (drop) {
                ++st.rejected_attached;
                continue;
              }
            }
            d.kind = best->name;
            d.measurement = MeasureFromSurface(*surface, d.centre_px, best->surface_to_centre_m,
                                               d.radius_px, *setup.camera, options.measurement);
          }
        } else if (setup.camera && depth_mm.empty()) {
          if (!FitOnFloor(*setup.camera, kinds, options, &d)) ++st.without_depth;
        }
        out.push_back(std::move(d));
      }
    }
  }
  return out;
}

cv::Mat DrawDetections(const cv::Mat& bgr, const std::vector<Detection>& detections) {
  cv::Mat out = bgr.clone();
  for (const Detection& d : detections) {
    const cv::Scalar colour = d.split ? cv::Scalar(0, 255, 255) : cv::Scalar(0, 255, 0);
    cv::drawContours(out, std::vector<std::vector<cv::Point>>{d.contour}, 0, colour, 2,
                     cv::LINE_AA);
    cv::circle(out, d.centre_px, 3, cv::Scalar(255, 255, 255), cv::FILLED, cv::LINE_AA);
    char text[96];
    if (d.measurement) {
      std::snprintf(text, sizeof(text), "%s %s %.2fm %.0fdeg", d.colour.c_str(), d.kind.c_str(),
                    d.measurement->range_m, d.measurement->bearing_rad * 180.0 / M_PI);
    } else {
      std::snprintf(text, sizeof(text), "%s", d.colour.c_str());
    }
    const cv::Point at(static_cast<int>(d.box.x), std::max(12, d.box.y - 4));
    cv::putText(out, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(out, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 255, 255), 1,
                cv::LINE_AA);
  }
  return out;
}

}  // namespace slamo::vision
