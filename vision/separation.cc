#include "vision/separation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "platform/drive_base.h"
#include "vision/contour_fill.h"
#include "vision/contour_trace.h"

namespace slamo::vision {
namespace {

using platform::kPi;
// Below this a convexity defect is digitisation noise, whatever the blob's size.
constexpr double kMinDefectDepthPx = 2.0;
// approxPolyDP tolerance before convexityDefects: removes the staircase of the pixel contour.
constexpr double kApproxEpsilonPx = 1.0;
// |cos| of the angle between a cut and the long side of the min-area rectangle: at most
// 0.5, i.e. the cut is within 30 deg of perpendicular.
constexpr double kMaxCutSkewCos = 0.5;
// Long side / short side of the min-area rectangle below which the blob has no meaningful
// orientation (a triangle of three balls): the perpendicular check is skipped.
constexpr double kMinElongationForAxis = 1.2;
// The single-defect rule cuts only blobs at least this elongated, so that a lone ball with
// a notch (an occluder in front of it) is not cut in two.
constexpr double kMinElongationForSingleDefect = 1.25;
// Fraction of the samples along a cut that must be object pixels.
constexpr double kMinCutInsideFraction = 0.95;
constexpr int kCutThicknessPx = 3;
// Two defects closer than this are one pinch point (a neck a pixel or two wide).
constexpr double kPinchWidthPx = 4.0;
// Cuts are extended this far beyond both ends so that they reach the background.
constexpr double kCutOvershootPx = 2.0;

using Contour = std::vector<cv::Point>;

// 255 where the mask is non-zero; throws on input that is not a single-channel 8-bit image.
cv::Mat Binarize(const cv::Mat& mask) {
  if (mask.empty()) throw std::invalid_argument("SeparateTouching: the mask is empty");
  if (mask.channels() != 1) {
    throw std::invalid_argument("SeparateTouching: the mask has " +
                                std::to_string(mask.channels()) +
                                " channels; expected one channel (CV_8UC1)");
  }
  if (mask.depth() != CV_8U) {
    throw std::invalid_argument("SeparateTouching: the mask has OpenCV depth " +
                                std::to_string(mask.depth()) +
                                "; expected 8-bit unsigned (CV_8UC1)");
  }
  cv::Mat binary;
  cv::compare(mask, 0, binary, cv::CMP_NE);
  return binary;
}

std::vector<Contour> ExternalContours(const cv::Mat& binary) {
  std::vector<Contour> contours;
  FindOuterContours(binary, &contours);
  return contours;
}

cv::Point2d Unit(cv::Point2d v) {
  const double n = std::hypot(v.x, v.y);
  return n > 0.0 ? v / n : cv::Point2d(0.0, 0.0);
}

bool IsObject(const cv::Mat& binary, cv::Point2d p) {
  const cv::Point q(cvRound(p.x), cvRound(p.y));
  return q.x >= 0 && q.y >= 0 && q.x < binary.cols && q.y < binary.rows && binary.at<uchar>(q) != 0;
}

// The blob's orientation: its min-area rectangle and centroid.
struct BlobFrame {
  cv::Point2d centroid;
  cv::Point2d long_axis;  // unit vector along the long side
  double width_px = 0.0;  // the short side
  double elongation = 1.0;
};

// The centroid alone (from the moments) when the contour has area; nullopt otherwise, when
// FrameOf falls back to the min-area rectangle's centre.
std::optional<cv::Point2d> MomentCentroid(const Contour& contour) {
  const cv::Moments m = cv::moments(contour);
  if (!(m.m00 > 0.0)) return std::nullopt;
  return cv::Point2d(m.m10 / m.m00, m.m01 / m.m00);
}

// The points of an outline that can lie on its convex hull, in the outline's order: those
// that are the leftmost or rightmost of their row (or on the top or bottom row, a convex
// outline's only horizontal edges) and the topmost or bottommost of their column (or on the
// leftmost or rightmost column, its only vertical edges). The rest are inside the hull, and
// cv::convexHull (which starts the hull where the input's order says) gives the same hull
// for these as for the whole outline.
const Contour& HullCandidates(const Contour& contour) {
  thread_local Contour candidates;
  thread_local std::vector<int> left, right, top, bottom;
  const cv::Rect box = cv::boundingRect(contour);
  left.assign(box.height, std::numeric_limits<int>::max());
  right.assign(box.height, std::numeric_limits<int>::min());
  top.assign(box.width, std::numeric_limits<int>::max());
  bottom.assign(box.width, std::numeric_limits<int>::min());
  for (const cv::Point& p : contour) {
    const int row = p.y - box.y, column = p.x - box.x;
    left[row] = std::min(left[row], p.x);
    right[row] = std::max(right[row], p.x);
    top[column] = std::min(top[column], p.y);
    bottom[column] = std::max(bottom[column], p.y);
  }
  candidates.clear();
  for (const cv::Point& p : contour) {
    const int row = p.y - box.y, column = p.x - box.x;
    const bool row_end = row == 0 || row == box.height - 1 || p.x == left[row] || p.x == right[row];
    const bool column_end =
        column == 0 || column == box.width - 1 || p.y == top[column] || p.y == bottom[column];
    if (row_end && column_end) candidates.push_back(p);
  }
  return candidates;
}

// `centroid`: MomentCentroid(contour), when the caller has it already.
BlobFrame FrameOf(const Contour& contour, const std::optional<cv::Point2d>& centroid) {
  BlobFrame frame;
  // The min-area rectangle is found on the convex hull: its candidate points are enough.
  const cv::RotatedRect rect = cv::minAreaRect(HullCandidates(contour));
  cv::Point2f corners[4];
  rect.points(corners);
  const cv::Point2d side_a = corners[1] - corners[0], side_b = corners[2] - corners[1];
  const double len_a = std::hypot(side_a.x, side_a.y), len_b = std::hypot(side_b.x, side_b.y);
  frame.long_axis = Unit(len_a >= len_b ? side_a : side_b);
  frame.width_px = std::min(len_a, len_b);
  frame.elongation = frame.width_px > 0.0 ? std::max(len_a, len_b) / frame.width_px : 1.0;
  frame.centroid = centroid ? *centroid : cv::Point2d(rect.center.x, rect.center.y);
  return frame;
}

struct Defect {
  int index = 0;  // into the simplified polygon
  cv::Point point;
  double depth_px = 0.0;
};

// Convexity defects deeper than min_depth_px, ordered as the thesis takes them: anticlockwise
// on screen, starting from the lower left of the blob. OpenCV throws on self-intersecting
// polygons (non-monotonic hull indices); those count as having no defects.
std::vector<Defect> FindDefects(const Contour& polygon, const cv::Point2d& centroid,
                                double min_depth_px) {
  std::vector<Defect> defects;
  if (polygon.size() < 4) return defects;
  std::vector<int> hull;
  std::vector<cv::Vec4i> raw;
  try {
    cv::convexHull(polygon, hull, /*clockwise=*/false, /*returnPoints=*/false);
    if (hull.size() < 3) return defects;
    cv::convexityDefects(polygon, hull, raw);
  } catch (const cv::Exception&) {
    return defects;
  }
  // OpenCV reports only the deepest point under each hull edge; one edge can span several
  // concavities (the top of three balls in a row), so split its depth profile into runs
  // deeper than the threshold, separated by stretches shallower than half of it.
  const int size = static_cast<int>(polygon.size());
  for (const cv::Vec4i& d : raw) {
    if (d[3] / 256.0 <= min_depth_px) continue;
    const cv::Point2d hull_a(polygon[d[0]]), hull_b(polygon[d[1]]);
    const cv::Point2d edge = Unit(hull_b - hull_a);
    std::optional<Defect> run;
    for (int k = d[0];; k = (k + 1) % size) {
      const cv::Point2d p(polygon[k]);
      const double depth_px = std::abs((p - hull_a).cross(edge));
      if (depth_px > min_depth_px && (!run || depth_px > run->depth_px)) {
        run = Defect{k, polygon[k], depth_px};
      } else if (run && depth_px < 0.5 * min_depth_px) {
        defects.push_back(*run);
        run.reset();
      }
      if (k == d[1]) break;
    }
    if (run) defects.push_back(*run);
  }
  // Screen angle with y up, measured anticlockwise from the lower-left direction (225 deg).
  auto key = [&](const Defect& d) {
    const double angle = std::atan2(-(d.point.y - centroid.y), d.point.x - centroid.x);
    return std::fmod(angle - 1.25 * kPi + 4.0 * kPi, 2.0 * kPi);
  };
  std::sort(defects.begin(), defects.end(),
            [&](const Defect& a, const Defect& b) { return key(a) < key(b); });
  return defects;
}

// Where a cut meets the outline: a point on the polygon edge from vertex `edge` to the next.
struct CutEnd {
  int edge = 0;
  cv::Point2d point;
};

CutEnd AtVertex(const Contour& polygon, int i) { return {i, cv::Point2d(polygon[i])}; }

// The point of the outline nearest to p.
CutEnd OnNearestEdge(const Contour& polygon, cv::Point2d p) {
  CutEnd best;
  double best_d2 = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(polygon.size());
  for (int k = 0; k < n; ++k) {
    const cv::Point2d a(polygon[k]), b(polygon[(k + 1) % n]);
    const cv::Point2d ab = b - a;
    const double len2 = ab.dot(ab);
    const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const cv::Point2d q = a + t * ab;
    const double d2 = (p - q).dot(p - q);
    if (d2 < best_d2) best_d2 = d2, best = {k, q};
  }
  return best;
}

// A cut from one end on the outline to the other, through `via` (inside the blob), and the
// line drawn to make it (the same polyline, except across a pinch).
struct Cut {
  CutEnd a, b;
  std::vector<cv::Point2d> via;
  std::vector<cv::Point2d> line;
};

// The two polygons a cut splits the outline into.
struct Split {
  double area_1 = 0.0, area_2 = 0.0;
  cv::Point2d centroid_1, centroid_2;
};

Split SplitAlong(const Contour& polygon, const Cut& cut) {
  const int n = static_cast<int>(polygon.size());
  // from -> outline vertices after from.edge up to to.edge -> to -> back along the cut.
  auto side = [&](const CutEnd& from, const CutEnd& to, bool via_forward) {
    std::vector<cv::Point2f> points = {cv::Point2f(from.point)};
    for (int k = (from.edge + 1) % n, steps = (to.edge - from.edge + n) % n; steps > 0;
         k = (k + 1) % n, --steps) {
      points.emplace_back(polygon[k]);
    }
    points.emplace_back(to.point);
    if (via_forward) {
      for (const cv::Point2d& v : cut.via) points.emplace_back(v);
    } else {
      for (auto v = cut.via.rbegin(); v != cut.via.rend(); ++v) points.emplace_back(*v);
    }
    return points;
  };
  auto measure = [](const std::vector<cv::Point2f>& points, double* area, cv::Point2d* centroid) {
    if (points.size() < 3) return;
    *area = cv::contourArea(points);
    const cv::Moments m = cv::moments(points);
    if (m.m00 != 0.0) *centroid = cv::Point2d(m.m10 / m.m00, m.m01 / m.m00);
  };
  Split split;
  measure(side(cut.a, cut.b, false), &split.area_1, &split.centroid_1);
  measure(side(cut.b, cut.a, true), &split.area_2, &split.centroid_2);
  return split;
}

double InsideFraction(const cv::Mat& binary, cv::Point2d a, cv::Point2d b) {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  const int samples = std::max(3, static_cast<int>(length / 2.0));
  int inside = 0;
  for (int s = 1; s <= samples; ++s) {
    // Interior samples only: the ends sit on the boundary.
    const double t = 0.05 + 0.9 * s / (samples + 1.0);
    inside += IsObject(binary, a + t * (b - a)) ? 1 : 0;
  }
  return static_cast<double>(inside) / samples;
}

double Length(const std::vector<cv::Point2d>& line) {
  double length = 0.0;
  for (size_t k = 1; k < line.size(); ++k) {
    length += std::hypot(line[k].x - line[k - 1].x, line[k].y - line[k - 1].y);
  }
  return length;
}

// A cut is acceptable when every segment runs through the object, it leaves two pieces of
// at least min_piece_area_px and, if straight in an elongated blob, it is roughly
// perpendicular to the blob's long side.
bool CutIsAcceptable(const cv::Mat& binary, const Contour& polygon, const BlobFrame& frame,
                     const Cut& cut, double min_piece_area_px) {
  for (size_t k = 1; k < cut.line.size(); ++k) {
    if (cut.line[k] == cut.line[k - 1]) return false;
    if (InsideFraction(binary, cut.line[k - 1], cut.line[k]) < kMinCutInsideFraction) {
      return false;
    }
  }
  if (cut.via.empty() && frame.elongation >= kMinElongationForAxis &&
      std::abs(Unit(cut.b.point - cut.a.point).dot(frame.long_axis)) > kMaxCutSkewCos) {
    return false;
  }
  const Split split = SplitAlong(polygon, cut);
  return split.area_1 >= min_piece_area_px && split.area_2 >= min_piece_area_px;
}

// Two outline vertices at (nearly) the same pixel: the blob narrows to a neck a pixel or two
// wide (tangent balls, a thin bridge). Cut across the neck, perpendicular to the line joining
// the centroids of the two sides.
std::optional<Cut> PinchCut(const Contour& polygon, int i, int j, double min_piece_area_px) {
  Cut cut{AtVertex(polygon, i), AtVertex(polygon, j), {}, {}};
  const Split split = SplitAlong(polygon, cut);
  if (split.area_1 < min_piece_area_px || split.area_2 < min_piece_area_px) return std::nullopt;
  const cv::Point2d along = Unit(split.centroid_2 - split.centroid_1);
  const cv::Point2d across(-along.y, along.x);
  const cv::Point2d pinch = 0.5 * (cut.a.point + cut.b.point);
  cut.line = {pinch - kPinchWidthPx * across, pinch + kPinchWidthPx * across};
  return cut;
}

// The outline vertex across a thin neck from vertex i: the nearest one in space that is not
// a neighbour of i along the outline, if it is within a pinch width.
std::optional<int> AcrossNeck(const Contour& polygon, int i) {
  const int n = static_cast<int>(polygon.size());
  std::optional<int> best;
  double best_d = kPinchWidthPx;
  for (int k = 0; k < n; ++k) {
    const int steps = std::min((k - i + n) % n, (i - k + n) % n);
    if (steps < 2) continue;
    const double d = std::hypot(polygon[k].x - polygon[i].x, polygon[k].y - polygon[i].y);
    if (d < best_d) best_d = d, best = k;
  }
  return best;
}

// The thesis's 'locating missing defects': from the defect straight across the blob,
// perpendicular to its long side, to where the object ends.
std::optional<Cut> SingleDefectCut(const cv::Mat& binary, const Contour& polygon,
                                   const BlobFrame& frame, const Defect& defect,
                                   double min_piece_area_px) {
  const cv::Point2d start(defect.point);
  cv::Point2d normal(-frame.long_axis.y, frame.long_axis.x);
  // Into the object, not out into the concavity.
  auto inward_hits = [&](cv::Point2d n) {
    int hits = 0;
    for (double t = 2.0; t <= 5.0; t += 1.0) hits += IsObject(binary, start + t * n) ? 1 : 0;
    return hits;
  };
  const int hits_plus = inward_hits(normal), hits_minus = inward_hits(-normal);
  if (hits_minus > hits_plus ||
      (hits_minus == hits_plus && (frame.centroid - start).dot(normal) < 0.0)) {
    normal = -normal;
  }
  const double max_length = 2.0 * std::hypot(binary.cols, binary.rows);
  double last_inside = 0.0;
  for (double t = 1.0; t < max_length; t += 1.0) {
    if (IsObject(binary, start + t * normal)) {
      last_inside = t;
    } else if (t - last_inside > 2.0) {
      break;  // two pixels of background: the far side of the blob
    }
  }
  if (last_inside < 2.0) {
    // No width across the defect: it sits on a thin neck.
    const std::optional<int> across = AcrossNeck(polygon, defect.index);
    if (!across) return std::nullopt;
    return PinchCut(polygon, defect.index, *across, min_piece_area_px);
  }
  const CutEnd end = OnNearestEdge(polygon, start + last_inside * normal);
  Cut cut{AtVertex(polygon, defect.index), end, {}, {start, end.point}};
  if (!CutIsAcceptable(binary, polygon, frame, cut, min_piece_area_px)) return std::nullopt;
  return cut;
}

// One cut for one blob: the thesis's defect pairs, then the shortest acceptable pair, then
// the single-defect rule. nullopt when the blob looks like one object.
std::optional<Cut> ChooseCut(const cv::Mat& binary, const Contour& contour,
                             const SeparationOptions& options, double min_piece_area_px) {
  const double area = cv::contourArea(contour);
  if (area <= 0.0) return std::nullopt;
  const double equivalent_radius_px = std::sqrt(area / kPi);
  Contour polygon;
  cv::approxPolyDP(contour, polygon, kApproxEpsilonPx, /*closed=*/true);
  // Defects first (they need only the centroid): most blobs have none, and then the
  // min-area rectangle (a convex hull of every outline pixel) is not needed.
  const std::optional<cv::Point2d> centroid = MomentCentroid(contour);
  const double min_depth_px =
      std::max(kMinDefectDepthPx, options.min_defect_depth_ratio * equivalent_radius_px);
  std::optional<BlobFrame> early_frame;
  if (!centroid) early_frame = FrameOf(contour, centroid);
  const std::vector<Defect> defects =
      FindDefects(polygon, centroid ? *centroid : early_frame->centroid, min_depth_px);
  if (defects.empty()) return std::nullopt;
  const BlobFrame frame = early_frame ? *early_frame : FrameOf(contour, centroid);
  const int n = static_cast<int>(defects.size());

  // A compact cluster (three or more defects, no long side) is cut along two necks that meet
  // at its centre: a V that follows the boundaries between the balls, where a straight cut
  // between two necks would slice off the neighbours too.
  const bool compact_cluster = n >= 3 && frame.elongation < kMinElongationForAxis;
  auto pair_cut = [&](int p, int q) -> std::optional<Cut> {
    const cv::Point2d a(defects[p].point), b(defects[q].point);
    if (std::hypot(b.x - a.x, b.y - a.y) < kPinchWidthPx) {
      return PinchCut(polygon, defects[p].index, defects[q].index, min_piece_area_px);
    }
    Cut cut{AtVertex(polygon, defects[p].index), AtVertex(polygon, defects[q].index), {}, {}};
    if (compact_cluster) {
      cut.via = {frame.centroid};
      cut.line = {a, frame.centroid, b};
      if (CutIsAcceptable(binary, polygon, frame, cut, min_piece_area_px)) return cut;
      cut.via.clear();
    }
    cut.line = {a, b};
    if (!CutIsAcceptable(binary, polygon, frame, cut, min_piece_area_px)) return std::nullopt;
    return cut;
  };

  // Thesis pairs: first with last, else second with second-to-last.
  if (n >= 2) {
    if (auto cut = pair_cut(0, n - 1)) return cut;
  }
  if (n >= 4) {
    if (auto cut = pair_cut(1, n - 2)) return cut;
  }
  // Any pair: the shortest cut relative to the blob's width.
  std::optional<Cut> best;
  double best_ratio = std::numeric_limits<double>::infinity();
  for (int p = 0; p < n; ++p) {
    for (int q = p + 1; q < n; ++q) {
      if (auto cut = pair_cut(p, q)) {
        const double ratio = Length(cut->line) / std::max(frame.width_px, 1.0);
        if (ratio < best_ratio) best_ratio = ratio, best = cut;
      }
    }
  }
  if (best) return best;
  // One defect left (the other hidden by occlusion): cut straight across from the deepest.
  if (frame.elongation < kMinElongationForSingleDefect) return std::nullopt;
  std::vector<Defect> by_depth = defects;
  std::sort(by_depth.begin(), by_depth.end(),
            [](const Defect& a, const Defect& b) { return a.depth_px > b.depth_px; });
  for (const Defect& defect : by_depth) {
    if (auto cut = SingleDefectCut(binary, polygon, frame, defect, min_piece_area_px)) return cut;
  }
  return std::nullopt;
}

void DrawCut(const Cut& cut, cv::Mat* binary) {
  std::vector<cv::Point2d> line = cut.line;
  line.front() -= kCutOvershootPx * Unit(line[1] - line[0]);
  line.back() += kCutOvershootPx * Unit(line.back() - line[line.size() - 2]);
  for (size_t k = 1; k < line.size(); ++k) {
    cv::line(*binary, cv::Point(cvRound(line[k - 1].x), cvRound(line[k - 1].y)),
             cv::Point(cvRound(line[k].x), cvRound(line[k].y)), cv::Scalar(0), kCutThicknessPx,
             cv::LINE_8);
  }
}

SeparationResult SeparateByDefects(const cv::Mat& binary, const SeparationOptions& options) {
  SeparationResult result;
  // Holes are gaps enclosed by a ring of touching balls (or reflections inside one): fill
  // them so that cuts may cross them.
  cv::Mat work = cv::Mat::zeros(binary.size(), CV_8U);
  std::vector<Contour> blobs = ExternalContours(binary);
  const size_t blob_count = blobs.size();
  FillOutlines(blobs, cv::Point(), &work);
  // Each piece is measured against the (filled) blob it came from. One blob (a detector's
  // window) fills one 8-connected region: its area is the pixel count, no labelling needed.
  cv::Mat labels, stats, centroids;
  double single_blob_area = 0.0;
  if (blob_count == 1) {
    single_blob_area = static_cast<double>(cv::countNonZero(work));
  } else {
    cv::connectedComponentsWithStats(work, labels, stats, centroids, 8, CV_32S);
  }
  auto blob_area = [&](const Contour& piece) {
    if (blob_count == 1) return single_blob_area;
    return static_cast<double>(stats.at<int>(labels.at<int>(piece.front()), cv::CC_STAT_AREA));
  };
  // The outlines of `work` as it is now: after a pass that cuts nothing they are the final ones.
  // Filling changed nothing (no holes, the usual case): they are the blobs' own outlines.
  std::vector<Contour> contours;
  bool contours_current = false;
  const bool filled_is_binary = binary.isContinuous() && work.isContinuous() &&
                                std::equal(binary.datastart, binary.dataend, work.datastart);
  if (filled_is_binary) contours = std::move(blobs), contours_current = true;
  for (int pass = 0; pass < options.max_passes; ++pass) {
    // Find every blob's cut first, then draw them: one cut per blob per pass.
    std::vector<Cut> cuts;
    if (!contours_current) contours = ExternalContours(work);
    contours_current = true;
    for (const Contour& contour : contours) {
      const double min_piece_area_px = options.min_piece_area_ratio * blob_area(contour);
      if (cv::contourArea(contour) < 2.0 * min_piece_area_px) continue;
      if (auto cut = ChooseCut(work, contour, options, min_piece_area_px)) cuts.push_back(*cut);
    }
    if (cuts.empty()) break;  // the thesis's flag: nothing left to separate
    for (const Cut& cut : cuts) DrawCut(cut, &work);
    contours_current = false;
    ++result.passes;
    result.cuts += static_cast<int>(cuts.size());
  }
  if (!contours_current) contours = ExternalContours(work);
  for (Contour& contour : contours) {
    if (cv::contourArea(contour) >= options.min_piece_area_ratio * blob_area(contour)) {
      result.pieces.push_back(std::move(contour));
    }
  }
  return result;
}

SeparationResult SeparateByWatershed(const cv::Mat& binary, const SeparationOptions& options) {
  SeparationResult result;
  result.passes = 1;
  // Markers: the peaks of the distance transform, each blob against its own maximum.
  cv::Mat distance;
  cv::distanceTransform(binary, distance, cv::DIST_L2, cv::DIST_MASK_5);
  cv::Mat blob_labels;
  const int blob_count = cv::connectedComponents(binary, blob_labels, 8, CV_32S);
  std::vector<float> blob_max(blob_count, 0.0f);
  for (int y = 0; y < binary.rows; ++y) {
    for (int x = 0; x < binary.cols; ++x) {
      float& m = blob_max[blob_labels.at<int>(y, x)];
      m = std::max(m, distance.at<float>(y, x));
    }
  }
  cv::Mat peaks = cv::Mat::zeros(binary.size(), CV_8U);
  for (int y = 0; y < binary.rows; ++y) {
    for (int x = 0; x < binary.cols; ++x) {
      const int blob = blob_labels.at<int>(y, x);
      if (blob != 0 && distance.at<float>(y, x) >= options.watershed_peak_ratio * blob_max[blob]) {
        peaks.at<uchar>(y, x) = 255;
      }
    }
  }
  cv::Mat markers;
  const int marker_count = cv::connectedComponents(peaks, markers, 8, CV_32S);
  // Labels: 1 = background (known exactly from the mask), 2.. = peaks, 0 = to flood.
  markers += 1;
  markers.setTo(0, (binary != 0) & (peaks == 0));

  cv::Mat image;
  cv::cvtColor(binary, image, cv::COLOR_GRAY2BGR);
  cv::watershed(image, markers);

  for (int label = 2; label <= marker_count; ++label) {
    const cv::Mat region = markers == label;
    std::vector<Contour> contours = ExternalContours(region);
    if (contours.empty()) continue;
    auto largest = std::max_element(
        contours.begin(), contours.end(),
        [](const Contour& a, const Contour& b) { return cv::contourArea(a) < cv::contourArea(b); });
    result.pieces.push_back(std::move(*largest));
  }
  return result;
}

}  // namespace

SeparationResult SeparateTouching(const cv::Mat& mask, SeparationMethod method,
                                  const SeparationOptions& options) {
  const cv::Mat binary = Binarize(mask);
  if (cv::countNonZero(binary) == 0) return {};
  switch (method) {
    case SeparationMethod::kNone: {
      SeparationResult result;
      result.pieces = ExternalContours(binary);
      return result;
    }
    case SeparationMethod::kConcaveDefects:
      return SeparateByDefects(binary, options);
    case SeparationMethod::kWatershed:
      return SeparateByWatershed(binary, options);
  }
  throw std::invalid_argument("SeparateTouching: unknown SeparationMethod");
}

SeparationMethod ParseSeparationMethod(const std::string& name) {
  if (name == "defects") return SeparationMethod::kConcaveDefects;
  if (name == "watershed") return SeparationMethod::kWatershed;
  if (name == "none") return SeparationMethod::kNone;
  throw std::invalid_argument("unknown separation method '" + name +
                              "'; expected one of: defects, watershed, none");
}

}  // namespace slamo::vision
