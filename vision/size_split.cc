#include "vision/size_split.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "vision/contour_trace.h"

namespace slamo::vision {
namespace {

// The extent of `values` between the trim quantiles (values is reordered); `low`, if given,
// gets the lower quantile.
double TrimmedExtent(std::vector<float>* values, double trim, double* low = nullptr) {
  if (values->size() < 2) return 0.0;
  const size_t n = values->size();
  const size_t lo = static_cast<size_t>(trim * (n - 1)), hi = n - 1 - lo;
  std::nth_element(values->begin(), values->begin() + lo, values->end());
  const float bottom = (*values)[lo];
  if (low) *low = bottom;
  std::nth_element(values->begin(), values->begin() + hi, values->end());
  return (*values)[hi] - bottom;
}

// Connected components of footprint cells (cell centres, `cell` apart on a grid): two cells
// are linked when at most `link` cells apart along both axes. Labels 0..n-1, by first cell.
std::vector<int> FootprintComponents(const std::vector<cv::Point2f>& cells, double cell, int link) {
  std::map<std::pair<int, int>, int> index;
  std::vector<std::pair<int, int>> at(cells.size());
  for (size_t i = 0; i < cells.size(); ++i) {
    at[i] = {static_cast<int>(std::lround(cells[i].x / cell - 0.5)),
             static_cast<int>(std::lround(cells[i].y / cell - 0.5))};
    index[at[i]] = static_cast<int>(i);
  }
  std::vector<int> label(cells.size(), -1), stack;
  int next = 0;
  for (size_t seed = 0; seed < cells.size(); ++seed) {
    if (label[seed] >= 0) continue;
    label[seed] = next;
    stack.assign(1, static_cast<int>(seed));
    while (!stack.empty()) {
      const auto [x, y] = at[stack.back()];
      stack.pop_back();
      // The cells of columns x - link .. x + link, rows y - link .. y + link.
      for (int dx = -link; dx <= link; ++dx) {
        auto it = index.lower_bound({x + dx, y - link});
        for (; it != index.end() && it->first.first == x + dx && it->first.second <= y + link;
             ++it) {
          if (label[it->second] < 0) {
            label[it->second] = next;
            stack.push_back(it->second);
          }
        }
      }
    }
    ++next;
  }
  return label;
}

// Whether the blob's lower edge is hidden: in at least `fraction` of its columns, the pixels
// just under it (up to `reach_px` rows) see something standing above the floor (higher than
// `min_height_m`) at least `min_gap_m` nearer the camera, on the floor, than the blob's lowest
// point there. `depth_mm` is a view into the whole depth image (read beyond its rows).
bool LowerEdgeHidden(const cv::Mat& mask, const cv::Mat& depth_mm, cv::Point offset,
                     const CameraModel& camera, int reach_px, double min_height_m, double min_gap_m,
                     double fraction) {
  cv::Mat below = depth_mm;  // the same pixels, with the rows under it
  below.adjustROI(0, reach_px + 1, 0, 0);
  const Eigen::Vector3d eye = camera.CameraToRobot(Eigen::Vector3d::Zero());
  const auto robot_point = [&](int u, int v, uint16_t raw) -> std::optional<Eigen::Vector3d> {
    if (raw == 0) return std::nullopt;  // no reading
    const double z = camera.CorrectDepthM(raw);
    if (!(z > 0.0)) return std::nullopt;
    return camera.CameraToRobot(camera.BackProject(u + offset.x, v + offset.y, z));
  };
  int columns = 0, hidden = 0;
  for (int u = 0; u < mask.cols; ++u) {
    int lowest = -1;
    for (int v = mask.rows - 1; v >= 0; --v) {
      if (mask.at<uint8_t>(v, u)) {
        lowest = v;
        break;
      }
    }
    if (lowest < 0) continue;
    ++columns;
    // The blob's lowest point with a reading in this column (its rim may read past it).
    std::optional<Eigen::Vector3d> own;
    for (int v = lowest; v >= std::max(0, lowest - 3) && !own; --v) {
      if (mask.at<uint8_t>(v, u)) own = robot_point(u, v, depth_mm.at<uint16_t>(v, u));
    }
    if (!own) continue;
    const double own_range = std::hypot(own->x() - eye.x(), own->y() - eye.y());
    const int last = std::min(below.rows - 1, lowest + reach_px);
    for (int v = lowest + 1; v <= last; ++v) {
      const std::optional<Eigen::Vector3d> p = robot_point(u, v, below.at<uint16_t>(v, u));
      if (p && p->z() > min_height_m &&
          std::hypot(p->x() - eye.x(), p->y() - eye.y()) < own_range - min_gap_m) {
        ++hidden;
        break;
      }
    }
  }
  return columns > 0 && hidden >= fraction * columns;
}

}  // namespace

cv::Mat RimlessCore(const cv::Mat& mask, int erode_px, int min_pixels) {
  if (erode_px <= 0) return mask;
  cv::Mat core;
  cv::erode(mask, core, cv::Mat(), cv::Point(-1, -1), erode_px);
  return cv::countNonZero(core) < min_pixels ? mask : core;
}

SizeSplitResult SplitBySize(const cv::Mat& mask, const cv::Mat& depth_mm, cv::Point offset,
                            const CameraModel& camera, const ObjectExtent& extent,
                            const SizeSplitOptions& options) {
  SizeSplitResult result;
  if (mask.empty() || extent.width_m <= 0.0 || extent.height_m <= 0.0) return result;
  // Points: the blob without its rim, where depth may read what lies behind the object.
  const cv::Mat core = RimlessCore(mask, options.erode_px, 16);
  std::vector<cv::Point> pixels;
  std::vector<cv::Vec3f> points;  // robot frame, in units of the object's width and height
  for (int v = 0; v < core.rows; ++v) {
    const uint8_t* m = core.ptr<uint8_t>(v);
    const uint16_t* d = depth_mm.ptr<uint16_t>(v);
    for (int u = 0; u < core.cols; ++u) {
      if (!m[u] || !d[u]) continue;
      const double z = camera.CorrectDepthM(d[u]);
      if (!(z > 0.0)) continue;
      const Eigen::Vector3d p =
          camera.CameraToRobot(camera.BackProject(u + offset.x, v + offset.y, z));
      pixels.emplace_back(u, v);
      points.emplace_back(static_cast<float>(p.x() / extent.width_m),
                          static_cast<float>(p.y() / extent.width_m),
                          static_cast<float>(p.z() / extent.height_m));
    }
  }
  if (points.size() < 8) return result;

  // Taller than the tallest stack, or flatter than one object: not objects of this size.
  // Nor a blob whose bottom is off the floor: a raised structure of the objects' colour (a
  // goal's frame, a bar) seen from the side is not a pile. A trade-off: piles off the floor
  // (rings on a stake, blocks in a raised goal, balls on a stash) or whose lower part is below
  // the image are not split by size either; those whose lower part is hidden behind something
  // nearer (a low bar) are (LowerEdgeHidden).
  std::vector<float> heights(points.size());
  for (size_t i = 0; i < points.size(); ++i) heights[i] = points[i][2];
  double bottom = 0.0;
  const double height_units = TrimmedExtent(&heights, options.trim_fraction, &bottom);
  // Objects resting on something the season places them on (a goal's top) stand on it as on
  // the floor: their heights are counted from it.
  // (support: that height, in object heights; 0 on the floor.)
  double support = 0.0;
  // Only when the floor does not explain it (top faces of a stack on the floor do).
  const bool on_floor =
      bottom <= options.floor_tolerance ||
      (options.top_faces && height_units < extent.min_vertical && std::round(bottom) >= 1.0 &&
       std::round(bottom) <= std::max(1, extent.max_stack) &&
       std::abs(bottom - std::round(bottom)) <= options.top_tolerance);
  if (options.rest_on_supports && !on_floor) {
    for (const double h : extent.rest_heights_m) {
      const double units = h / extent.height_m;
      if (std::abs(bottom - units) < std::abs(bottom - support)) support = units;
    }
  }
  if (support > 0.0 && std::abs(bottom - support) <= options.floor_tolerance) {
    for (cv::Vec3f& q : points) q[2] -= static_cast<float>(support);
    for (float& h : heights) h -= static_cast<float>(support);
    bottom -= support;
  } else {
    support = 0.0;
  }
  // On a support, stacks no taller than the season places there.
  const int max_stack = support > 0.0 ? extent.rest_max_stack : extent.max_stack;
  // Objects whose sides are hidden show just their top faces: a flat blob at a whole number of
  // object heights (the top check below), not a floor marking or a low bar.
  const bool top_faces = options.top_faces && height_units < extent.min_vertical &&
                         std::round(bottom) >= 1.0 &&
                         std::round(bottom) <= std::max(1, max_stack) &&
                         std::abs(bottom - std::round(bottom)) <= options.top_tolerance;
  if (height_units > extent.vertical_limit * std::max(1, max_stack)) return result;
  // A blob whose lower edge is hidden (behind a low bar) may show only the upper part of its
  // objects: its bottom is not where they rest.
  const auto lower_edge_hidden = [&] {
    if (options.hidden_fraction <= 0.0) return false;
    double depth_m = 0.0;  // the blob's typical depth, for the reach in rows
    {
      std::vector<float> zs;
      for (const cv::Point& p : pixels)
        zs.push_back(camera.CorrectDepthM(depth_mm.at<uint16_t>(p)));
      std::nth_element(zs.begin(), zs.begin() + zs.size() / 2, zs.end());
      depth_m = zs[zs.size() / 2];
    }
    const int reach = std::max(3, static_cast<int>(std::ceil(camera.config().fy * extent.height_m /
                                                             std::max(depth_m, 0.1))));
    return LowerEdgeHidden(mask, depth_mm, offset, camera, reach,
                           options.hidden_min_height * extent.height_m,
                           options.hidden_min_gap * extent.width_m, options.hidden_fraction);
  };
  const bool bottom_hidden =
      !top_faces && (height_units < extent.min_vertical || bottom > options.floor_tolerance) &&
      bottom < options.hidden_max_bottom && lower_edge_hidden();
  if (!top_faces && !bottom_hidden &&
      (height_units < extent.min_vertical || bottom > options.floor_tolerance)) {
    return result;
  }
  // Objects rest on the floor or on one another, so the top of the blob lies at a whole
  // number of object heights (a robot's bumper, 0.02-0.14 m, does not for rings or blocks).
  double top_units = 0.0;
  {
    const size_t top_rank =
        heights.size() - 1 - static_cast<size_t>(options.trim_fraction * (heights.size() - 1));
    std::nth_element(heights.begin(), heights.begin() + top_rank, heights.end());
    top_units = heights[top_rank];
    if (std::round(top_units) < 1.0 ||
        std::abs(top_units - std::round(top_units)) > options.top_tolerance)
      return result;
  }

  // Objects rest on the floor or on one another: a point's level in a stack is the number of
  // object heights below it (a top face, at the height of the object it covers, belongs to
  // that object: hence the slack).
  // (A blob with a hidden lower edge: as many levels as its top stands object heights high.)
  int levels = std::max(1, static_cast<int>(std::ceil(height_units - options.level_slack)));
  if (bottom_hidden) levels = std::max(levels, static_cast<int>(std::lround(top_units)));
  const auto level_of = [&](const cv::Vec3f& q) {
    return std::clamp(static_cast<int>(std::floor(q[2] - options.level_slack)), 0, levels - 1);
  };
  // Per level, the footprint as occupied cells (each object's share by the floor area it
  // covers, not by its pixels: a face turned to the camera has many, a top face seen at a
  // grazing angle few); a cell needs two points (a lone rim pixel seeing past is none).
  std::vector<std::vector<cv::Point2f>> level_points(levels);
  {
    std::vector<std::map<std::pair<int, int>, int>> cells(levels);
    const double cell = options.cell_size;
    for (const cv::Vec3f& q : points) {
      ++cells[level_of(q)][{static_cast<int>(std::floor(q[0] / cell)),
                            static_cast<int>(std::floor(q[1] / cell))}];
    }
    for (int level = 0; level < levels; ++level) {
      for (const auto& [at, count] : cells[level]) {
        if (count >= 2)
          level_points[level].emplace_back((at.first + 0.5) * cell, (at.second + 0.5) * cell);
      }
    }
  }

  // Per level, the fewest groups whose footprint each fits one object: the rectangle round
  // it (turned as it lies: a block at 45 degrees is no wider), between the trim quantiles.
  std::vector<cv::Point2f> footprint;
  std::vector<float> xs, ys;
  const auto fits = [&](const std::vector<cv::Point2f>& pts, const std::vector<int>& labels,
                        int k) {
    for (int c = 0; c < k; ++c) {
      xs.clear();
      ys.clear();
      for (size_t i = 0; i < pts.size(); ++i) {
        if (labels[i] == c) xs.push_back(pts[i].x), ys.push_back(pts[i].y);
      }
      if (xs.size() < 3) continue;
      const size_t m = xs.size(), cut = static_cast<size_t>(options.trim_fraction * (m - 1));
      std::nth_element(xs.begin(), xs.begin() + cut, xs.end());
      const float x_lo = xs[cut];
      std::nth_element(xs.begin(), xs.begin() + (m - 1 - cut), xs.end());
      const float x_hi = xs[m - 1 - cut];
      std::nth_element(ys.begin(), ys.begin() + cut, ys.end());
      const float y_lo = ys[cut];
      std::nth_element(ys.begin(), ys.begin() + (m - 1 - cut), ys.end());
      const float y_hi = ys[m - 1 - cut];
      footprint.clear();
      for (size_t i = 0; i < pts.size(); ++i) {
        const cv::Point2f& q = pts[i];
        if (labels[i] == c && q.x >= x_lo && q.x <= x_hi && q.y >= y_lo && q.y <= y_hi)
          footprint.push_back(q);
      }
      if (footprint.size() < 3) continue;
      const cv::RotatedRect rect = cv::minAreaRect(footprint);
      if (std::max(rect.size.width, rect.size.height) > extent.horizontal_limit) return false;
    }
    return true;
  };
  // Footprints apart on the floor are different objects, however they overlap in the image:
  // each level's cells are linked into components (cells within link_fraction x the width of
  // each other), and the fewest groups are sought within each component.
  const int link_cells =
      std::max(1, static_cast<int>(std::ceil(options.link_fraction / options.cell_size - 1e-9)));
  std::vector<std::vector<cv::Point2f>> level_centres(levels);
  std::vector<cv::Point2f> part;
  int k_total = 0;
  for (int level = 0; level < levels && k_total < options.max_objects; ++level) {
    const std::vector<cv::Point2f>& cells = level_points[level];
    if (static_cast<int>(cells.size()) < options.min_level_points) continue;
    const std::vector<int> component =
        options.link_fraction > 0.0 ? FootprintComponents(cells, options.cell_size, link_cells)
                                    : std::vector<int>(cells.size(), 0);
    const int components = *std::max_element(component.begin(), component.end()) + 1;
    for (int c = 0; c < components && k_total < options.max_objects; ++c) {
      part.clear();
      for (size_t i = 0; i < cells.size(); ++i) {
        if (component[i] == c) part.push_back(cells[i]);
      }
      // Too few cells for an object of its own: its points join the nearest group.
      if (static_cast<int>(part.size()) < options.min_level_points) continue;
      std::vector<int> labels(part.size(), 0);
      cv::Point2f mean(0, 0);
      for (const cv::Point2f& q : part) mean += q;
      std::vector<cv::Point2f> centres{mean * (1.0f / part.size())};
      const cv::Mat data(static_cast<int>(part.size()), 2, CV_32F, part.data());
      const int most = std::min(options.max_objects - k_total, static_cast<int>(part.size()));
      int k = 1;
      while (!fits(part, labels, k) && k < most) {
        ++k;
        cv::Mat fit_labels, fit_centres;
        cv::theRNG().state = 0x5eed + k;  // k-means++ seeding: the same groups for the same blob
        cv::kmeans(data, k, fit_labels,
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT,
                                    options.kmeans_iterations, 1e-3),
                   1, cv::KMEANS_PP_CENTERS, fit_centres);
        for (size_t i = 0; i < part.size(); ++i)
          labels[i] = fit_labels.at<int>(static_cast<int>(i));
        centres.assign(k, cv::Point2f());
        for (int j = 0; j < k; ++j) centres[j] = fit_centres.at<cv::Point2f>(j);
      }
      level_centres[level].insert(level_centres[level].end(), centres.begin(), centres.end());
      k_total += k;
    }
  }
  if (k_total == 0) return result;
  // The top level is seen from above (the camera is higher than any stack): each of its
  // objects shows a top face or cap, not just a thin upright face (a wall, a poster, a bar).
  // A blob with sliver_fraction of its top level's groups such faces is not these objects;
  // fewer, in a pile, are slivers of objects hidden behind others or cut by the image's edge:
  // their pixels go to no piece (one sliver refused a pile of twenty cubes before).
  std::vector<std::pair<int, cv::Point2f>> all_centres;  // (level, centre)
  std::vector<uint8_t> sliver;                           // per centre: a thin top-level group
  for (int level = 0; level < levels; ++level) {
    for (const cv::Point2f& c : level_centres[level]) all_centres.emplace_back(level, c);
  }
  sliver.assign(all_centres.size(), 0);
  for (int level = levels - 1; level >= 0; --level) {
    const std::vector<cv::Point2f>& centres = level_centres[level];
    if (centres.empty()) continue;
    std::vector<std::vector<cv::Point2f>> groups(centres.size());
    for (const cv::Point2f& q : level_points[level]) {
      size_t best = 0;
      for (size_t c = 1; c < centres.size(); ++c) {
        if (cv::norm(q - centres[c]) < cv::norm(q - centres[best])) best = c;
      }
      groups[best].push_back(q);
    }
    size_t first = 0;  // the level's first centre in all_centres
    for (int l = 0; l < level; ++l) first += level_centres[l].size();
    int thin = 0;
    for (size_t c = 0; c < groups.size(); ++c) {
      const std::vector<cv::Point2f>& g = groups[c];
      if (g.size() < 3) continue;
      const cv::RotatedRect rect = cv::minAreaRect(g);
      // Cells are points at their centres: one cell more across.
      if (std::min(rect.size.width, rect.size.height) + options.cell_size < options.min_top_depth)
        sliver[first + c] = 1, ++thin;
    }
    // Raised onto a support (a goal's top) near the camera's height, the top faces are seen
    // edge on, a pixel or less deep: they cannot show, and are not asked for.
    if (support > 0.0) {
      const Eigen::Vector3d lens = camera.CameraToRobot(Eigen::Vector3d::Zero());
      double range_m = 0.0;
      for (const cv::Point2f& c : centres)
        range_m += std::hypot(c.x * extent.width_m - lens.x(), c.y * extent.width_m - lens.y());
      range_m /= static_cast<double>(centres.size());
      const double top_m = (support + top_units) * extent.height_m;
      const double top_px = camera.config().fy * extent.width_m *
                            (camera.config().mount.height_m - top_m) /
                            std::max(range_m * range_m, 1e-6);
      if (top_px < options.min_top_face_px) {
        std::fill(sliver.begin(), sliver.end(), uint8_t{0});
        thin = 0;
      }
    }
    if (thin > 0 && thin >= options.sliver_fraction * static_cast<int>(groups.size()))
      return result;
    break;
  }
  result.objects = k_total - static_cast<int>(std::count(sliver.begin(), sliver.end(), uint8_t{1}));

  // Every point to the nearest centre of its level (of any level when its own has none);
  // each group's pixels, grown back over the rim.
  const int k = static_cast<int>(all_centres.size());
  std::vector<cv::Mat> group_masks(k);
  for (cv::Mat& g : group_masks) g = cv::Mat::zeros(mask.size(), CV_8UC1);
  for (size_t i = 0; i < points.size(); ++i) {
    const int level = level_of(points[i]);
    const bool own_level = !level_centres[level].empty();
    int best = 0;
    float best_d2 = std::numeric_limits<float>::infinity();
    for (int c = 0; c < k; ++c) {
      if (own_level && all_centres[c].first != level) continue;
      const float dx = points[i][0] - all_centres[c].second.x;
      const float dy = points[i][1] - all_centres[c].second.y;
      const float dz = own_level ? 0.0f : static_cast<float>(level - all_centres[c].first);
      const float d2 = dx * dx + dy * dy + dz * dz;
      if (d2 < best_d2) best_d2 = d2, best = c;
    }
    group_masks[best].at<uint8_t>(pixels[i]) = 255;
  }
  for (int c = 0; c < k; ++c) {
    if (sliver[c]) group_masks[c].release();
  }
  const cv::Mat grow = cv::getStructuringElement(
      cv::MORPH_ELLIPSE, cv::Size(2 * options.erode_px + 3, 2 * options.erode_px + 3));
  // Grown back over the rim, a group stops at the pixels given to another
  // (SizeSplitOptions::exclusive_growth).
  cv::Mat assigned = cv::Mat::zeros(mask.size(), CV_8UC1);
  for (const cv::Mat& g : group_masks) {
    if (options.exclusive_growth && !g.empty()) assigned |= g;
  }
  cv::Mat free_for;  // its own buffer: assigning to a Mat that shares mask's would write there
  for (cv::Mat& g : group_masks) {
    if (g.empty()) continue;                                           // a sliver's
    if (options.exclusive_growth) free_for = mask & ~(assigned & ~g);  // not the others' own
    cv::morphologyEx(g, g, cv::MORPH_CLOSE, grow);
    cv::dilate(g, g, grow);
    g &= options.exclusive_growth ? free_for : mask;
    std::vector<std::vector<cv::Point>> contours;
    FindOuterContours(g, &contours);
    if (contours.empty()) continue;
    const auto largest = std::max_element(
        contours.begin(), contours.end(),
        [](const auto& a, const auto& b) { return cv::contourArea(a) < cv::contourArea(b); });
    result.pieces.push_back(std::move(*largest));
  }
  return result;
}

}  // namespace slamo::vision
