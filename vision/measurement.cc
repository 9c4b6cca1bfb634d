#include "vision/measurement.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "vision/span_morphology.h"

namespace slamo::vision {

Eigen::Vector2d RangeBearing(const CameraModel& camera, double u, double v, double z_m) {
  const Eigen::Vector3d p = camera.CameraToRobot(camera.BackProject(u, v, z_m));
  return Eigen::Vector2d(std::hypot(p.x(), p.y()), std::atan2(p.y(), p.x()));
}

std::optional<Measurement> MeasureBlob(const cv::Mat& depth_mm, const cv::Mat& blob_mask,
                                       const cv::Point2d& centre_px, double surface_to_centre_m,
                                       double radius_px, const CameraModel& camera,
                                       const MeasurementOptions& options) {
  const std::optional<BlobSurface> surface =
      MeasureBlobSurface(depth_mm, blob_mask, camera, options);
  if (!surface) return std::nullopt;
  return MeasureFromSurface(*surface, centre_px, surface_to_centre_m, radius_px, camera, options);
}

std::optional<LeastCurvature> MeasureLeastCurvature(const cv::Mat& depth_mm, const cv::Mat& mask,
                                                    cv::Point offset, const CameraModel& camera,
                                                    double depth_m, double band_m, int erode_px,
                                                    int min_readings) {
  if (depth_mm.empty() || depth_mm.type() != CV_16UC1 || mask.size() != depth_mm.size()) {
    return std::nullopt;
  }
  cv::Mat inner;  // its own pixels: the caller's mask is left as it is
  if (erode_px > 0) {
    ErodeLike(
        mask,
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * erode_px + 1, 2 * erode_px + 1)),
        &inner);
  } else {
    inner = mask;
  }
  // One pass: the sums of the monomials the normal equations need, in metres about the
  // middle of the mask's pixels at depth_m.
  const field::CameraConfig& c = camera.config();
  const int pixels = cv::countNonZero(inner);
  if (pixels < min_readings) return std::nullopt;
  const cv::Rect box = cv::boundingRect(inner);  // its middle: near enough the centroid
  const double u0 = offset.x + box.x + 0.5 * (box.width - 1);
  const double v0 = offset.y + box.y + 0.5 * (box.height - 1);
  const double near_m = depth_m - band_m, far_m = depth_m + band_m;
  double m[5][5] = {};  // m[i][j]: sum of x^i y^j, i + j <= 4
  double w[3][3] = {};  // w[i][j]: sum of (z - depth_m) x^i y^j, i + j <= 2
  int count = 0;
  // Every other row and column of a piece of more than 400 pixels: a quadric needs no more,
  // and the sigma below grows with fewer readings (on the detector benchmark's view this
  // costs 0.05 ms a frame, all of them 0.11 ms).
  const int step = pixels > 400 ? 2 : 1;
  // CorrectDepthM, z = (raw - b) / a / 1000, as one multiply-add per reading.
  const double m_per_raw = 0.001 / c.depth_correction.a;
  const double m_at_zero = -c.depth_correction.b_mm * m_per_raw;
  const double inv_fx = 1.0 / c.fx, inv_fy = 1.0 / c.fy;
  for (int v = 0; v < inner.rows; v += step) {
    const uint8_t* mv = inner.ptr<uint8_t>(v);
    const uint16_t* d = depth_mm.ptr<uint16_t>(v);
    const double row_y = (v + offset.y - v0) * inv_fy;
    for (int u = 0; u < inner.cols; u += step) {
      if (!mv[u] || !d[u]) continue;
      const double z = d[u] * m_per_raw + m_at_zero;
      if (!(z > 0.0) || z < near_m || z > far_m) continue;
      const double x = (u + offset.x - u0) * inv_fx * z, y = row_y * z;
      const double dz = z - depth_m;
      const double xx = x * x, xy = x * y, yy = y * y;
      m[0][0] += 1.0, m[1][0] += x, m[0][1] += y;
      m[2][0] += xx, m[1][1] += xy, m[0][2] += yy;
      m[3][0] += xx * x, m[2][1] += xx * y, m[1][2] += x * yy, m[0][3] += yy * y;
      m[4][0] += xx * xx, m[3][1] += xx * xy, m[2][2] += xx * yy, m[1][3] += xy * yy,
          m[0][4] += yy * yy;
      w[0][0] += dz, w[1][0] += dz * x, w[0][1] += dz * y;
      w[2][0] += dz * xx, w[1][1] += dz * xy, w[0][2] += dz * yy;
      ++count;
    }
  }
  if (count < min_readings) return std::nullopt;
  // Basis 1, x, y, x^2, xy, y^2 as exponents (i, j).
  constexpr int kI[6] = {0, 1, 0, 2, 1, 0}, kJ[6] = {0, 0, 1, 0, 1, 2};
  Eigen::Matrix<double, 6, 6> normal;
  Eigen::Matrix<double, 6, 1> rhs;
  for (int a = 0; a < 6; ++a) {
    for (int b = 0; b < 6; ++b) normal(a, b) = m[kI[a] + kI[b]][kJ[a] + kJ[b]];
    rhs(a) = w[kI[a]][kJ[a]];
  }
  // Solved on coordinates scaled to the piece's size, where every basis function is of order
  // one: a piece whose readings do not spread both ways (a strip, a line) leaves a pivot near
  // zero, and its curvature along the missing direction is not known.
  const double spread =
      std::sqrt(std::max(1e-12, (m[2][0] + m[0][2]) / m[0][0] -
                                    (m[1][0] * m[1][0] + m[0][1] * m[0][1]) / (m[0][0] * m[0][0])));
  Eigen::Matrix<double, 6, 1> scale;
  for (int a = 0; a < 6; ++a) scale(a) = std::pow(spread, -(kI[a] + kJ[a]));
  const Eigen::Matrix<double, 6, 6> scaled = scale.asDiagonal() * normal * scale.asDiagonal();
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(scaled);
  if (solver.info() != Eigen::Success) return std::nullopt;
  const Eigen::VectorXd pivots = solver.vectorD().cwiseAbs();
  if (!(pivots.minCoeff() > 1e-6 * pivots.maxCoeff())) return std::nullopt;
  const Eigen::Matrix<double, 6, 1> q = scale.asDiagonal() * solver.solve(scale.asDiagonal() * rhs);
  Eigen::Matrix2d hessian;
  hessian << 2.0 * q(3), q(4), q(4), 2.0 * q(5);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(hessian);
  // The curvature nearest zero (a ball: both about 1/R; an edge or a noodle, convex or
  // concave: about 0 along it).
  const int least = std::abs(eigen.eigenvalues()(0)) <= std::abs(eigen.eigenvalues()(1)) ? 0 : 1;
  // Its uncertainty from the camera's depth noise (the robot file's model) at this depth,
  // through the fit's covariance, along that direction v (d lambda = v' dH v).
  const double noise = camera.DepthSigmaM(depth_m);
  const auto sigma_along = [&](int k) {
    const Eigen::Vector2d v = eigen.eigenvectors().col(k);
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    g(3) = 2.0 * v.x() * v.x();
    g(4) = 2.0 * v.x() * v.y();
    g(5) = 2.0 * v.y() * v.y();
    const Eigen::Matrix<double, 6, 1> gs = scale.asDiagonal() * g;
    return std::sqrt(std::max(0.0, noise * noise * gs.dot(solver.solve(gs))));
  };
  // The eigenvalues come in increasing order: the lowest is the first.
  return LeastCurvature{eigen.eigenvalues()(least), sigma_along(least), eigen.eigenvalues()(0),
                        sigma_along(0)};
}

size_t MaskedReadings(const cv::Mat& depth_mm, const cv::Mat& mask, const cv::Rect& box,
                      std::vector<uint16_t>* readings) {
  // Every pixel's reading is written at `count` (kept or overwritten), at most one per pixel.
  const size_t room = static_cast<size_t>(box.area());
  if (readings->size() < room) readings->resize(room);
  uint16_t* out = readings->data();
  size_t count = 0;
  for (int v = box.y; v < box.y + box.height; ++v) {
    const uint8_t* m = mask.ptr<uint8_t>(v);
    const uint16_t* d = depth_mm.ptr<uint16_t>(v);
    int u = box.x;
    const int end = box.x + box.width;
#if defined(__SSE2__)
    const __m128i zero = _mm_setzero_si128();
    for (; u + 16 <= end; u += 16) {
      const __m128i set = _mm_cmpeq_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(m + u)),
                                         zero);  // 0xff where the mask is 0
      const int background = _mm_movemask_epi8(set);
      if (background == 0xffff) continue;
      if (background == 0) {
        const __m128i d0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(d + u));
        const __m128i d1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(d + u + 8));
        const __m128i no_reading =
            _mm_or_si128(_mm_cmpeq_epi16(d0, zero), _mm_cmpeq_epi16(d1, zero));
        if (_mm_movemask_epi8(no_reading) == 0) {
          _mm_storeu_si128(reinterpret_cast<__m128i*>(out + count), d0);
          _mm_storeu_si128(reinterpret_cast<__m128i*>(out + count + 8), d1);
          count += 16;
          continue;
        }
      }
      for (int k = u; k < u + 16; ++k) {
        out[count] = d[k];
        count += (m[k] != 0) & (d[k] != 0);
      }
    }
#endif
    for (; u < end; ++u) {
      out[count] = d[u];
      count += (m[u] != 0) & (d[u] != 0);
    }
  }
  return count;
}

uint16_t MedianReading(const std::vector<uint16_t>& readings) {
  return MedianReading(readings.data(), readings.size());
}

uint16_t MedianReading(const uint16_t* r, size_t n) {
  size_t rank = n / 2;
  // Four interleaved counts: neighbouring readings of one surface share their high byte, and
  // with a single table each increment would wait for the one before it.
  uint32_t high[4][256] = {};
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    ++high[0][r[i] >> 8];
    ++high[1][r[i + 1] >> 8];
    ++high[2][r[i + 2] >> 8];
    ++high[3][r[i + 3] >> 8];
  }
  for (; i < n; ++i) ++high[0][r[i] >> 8];
  unsigned h = 0;
  for (;; ++h) {
    const size_t count = size_t{high[0][h]} + high[1][h] + high[2][h] + high[3][h];
    if (rank < count) break;
    rank -= count;
  }
  // Every reading adds to the bin of its low byte: one if its high byte is h, else zero (no
  // branch, and no single bin that every other reading would wait on).
  uint32_t low[4][256] = {};
  const auto in_h = [h](uint16_t reading) { return static_cast<uint32_t>((reading >> 8) == h); };
  for (i = 0; i + 4 <= n; i += 4) {
    low[0][r[i] & 0xff] += in_h(r[i]);
    low[1][r[i + 1] & 0xff] += in_h(r[i + 1]);
    low[2][r[i + 2] & 0xff] += in_h(r[i + 2]);
    low[3][r[i + 3] & 0xff] += in_h(r[i + 3]);
  }
  for (; i < n; ++i) low[0][r[i] & 0xff] += in_h(r[i]);
  unsigned l = 0;
  for (;; ++l) {
    const size_t count = size_t{low[0][l]} + low[1][l] + low[2][l] + low[3][l];
    if (rank < count) break;
    rank -= count;
  }
  return static_cast<uint16_t>(h << 8 | l);
}

std::optional<BlobSurface> MeasureBlobSurface(const cv::Mat& depth_mm, const cv::Mat& blob_mask,
                                              const CameraModel& camera,
                                              const MeasurementOptions& options) {
  if (depth_mm.empty() || depth_mm.type() != CV_16UC1 || blob_mask.size() != depth_mm.size()) {
    return std::nullopt;
  }
  // Valid readings inside the (eroded) blob; fall back to the whole blob when erosion
  // leaves too few (small, far objects).
  cv::Mat inner = blob_mask;
  if (options.erode_px > 0) {
    cv::Mat eroded;
    ErodeLike(blob_mask,
              cv::getStructuringElement(
                  cv::MORPH_ELLIPSE, cv::Size(2 * options.erode_px + 1, 2 * options.erode_px + 1)),
              &eroded);
    if (cv::countNonZero(eroded) >= options.min_depth_pixels) inner = eroded;
  }
  const cv::Rect box = cv::boundingRect(inner);
  thread_local std::vector<uint16_t> readings;  // reused: no allocation per blob
  const size_t count = MaskedReadings(depth_mm, inner, box, &readings);
  if (static_cast<int>(count) < options.min_depth_pixels) return std::nullopt;
  if (count < options.min_depth_fraction * cv::countNonZero(inner)) return std::nullopt;
  const double surface_m = camera.CorrectDepthM(MedianReading(readings.data(), count));
  if (!(surface_m > 0.0)) return std::nullopt;
  return BlobSurface{surface_m, static_cast<int>(count)};
}

std::optional<SurfaceBulge> MeasureSurfaceBulge(const cv::Mat& depth_mm, const cv::Mat& blob_mask,
                                                const cv::Point2d& centre_px, double radius_px,
                                                const CameraModel& camera, bool along_columns) {
  constexpr int kMinReadings = 4;
  if (depth_mm.empty() || depth_mm.type() != CV_16UC1 || blob_mask.size() != depth_mm.size() ||
      !(radius_px > 0.0)) {
    return std::nullopt;
  }
  // `across` runs through the rims (u along rows, v along columns), `along` is the band's
  // width.
  const double across_c = along_columns ? centre_px.y : centre_px.x;
  const double along_c = along_columns ? centre_px.x : centre_px.y;
  const int across_n = along_columns ? depth_mm.rows : depth_mm.cols;
  const int along_n = along_columns ? depth_mm.cols : depth_mm.rows;
  std::vector<uint16_t> bands[3];  // one rim, centre, other rim
  const int a0 = std::max(0, static_cast<int>(std::ceil(along_c - 0.35 * radius_px)));
  const int a1 = std::min(along_n - 1, static_cast<int>(std::floor(along_c + 0.35 * radius_px)));
  const int c0 = std::max(0, static_cast<int>(std::ceil(across_c - 0.85 * radius_px)));
  const int c1 = std::min(across_n - 1, static_cast<int>(std::floor(across_c + 0.85 * radius_px)));
  for (int a = a0; a <= a1; ++a) {
    for (int c = c0; c <= c1; ++c) {
      const int u = along_columns ? a : c, v = along_columns ? c : a;
      const uint16_t d = depth_mm.at<uint16_t>(v, u);
      if (!blob_mask.at<uint8_t>(v, u) || !d) continue;
      const double x = (c - across_c) / radius_px;
      if (std::abs(x) <= 0.3) {
        bands[1].push_back(d);
      } else if (std::abs(x) >= 0.55) {
        bands[x < 0.0 ? 0 : 2].push_back(d);
      }
    }
  }
  double depth[3], variance[3];
  for (int b = 0; b < 3; ++b) {
    if (static_cast<int>(bands[b].size()) < kMinReadings) return std::nullopt;
    depth[b] = camera.CorrectDepthM(MedianReading(bands[b].data(), bands[b].size()));
    if (!(depth[b] > 0.0)) return std::nullopt;
    // The median of n readings: about 1.25 sigma / sqrt(n).
    const double s = 1.25 * camera.DepthSigmaM(depth[b]);
    variance[b] = s * s / static_cast<double>(bands[b].size());
  }
  // In inverse depth, which is linear across the image for any plane (depth itself is not: a
  // face turned well away from the camera would read as curved), scaled back to metres.
  SurfaceBulge out;
  out.bulge_m = depth[1] * depth[1] * (1.0 / depth[1] - (1.0 / depth[0] + 1.0 / depth[2]) / 2.0);
  out.sigma_m = std::sqrt(variance[1] + (variance[0] + variance[2]) / 4.0);
  return out;
}

Measurement MeasureFromSurface(const BlobSurface& surface, const cv::Point2d& centre_px,
                               double surface_to_centre_m, double radius_px,
                               const CameraModel& camera, const MeasurementOptions& options) {
  const double surface_m = surface.depth_m;
  Measurement m;
  m.depth_m = surface_m;
  m.depth_pixels = surface.pixels;
  // The centre lies about one radius behind the visible surface, along the ray.
  const double z = surface_m + surface_to_centre_m;
  m.position_camera_m = camera.BackProject(centre_px.x, centre_px.y, z);
  m.position_robot_m = camera.CameraToRobot(m.position_camera_m);
  const Eigen::Vector2d rb = RangeBearing(camera, centre_px.x, centre_px.y, z);
  m.range_m = rb.x();
  m.bearing_rad = rb.y();

  // Covariance: first-order propagation of the pixel and depth uncertainty (numerical
  // Jacobian of (u, v, z) -> (range, bearing)).
  const double sigma_px = options.pixel_sigma_px + options.pixel_sigma_ratio * radius_px;
  const double sigma_z = std::hypot(camera.DepthSigmaM(z), options.model_sigma_m);
  Eigen::Matrix<double, 2, 3> jacobian;
  const double steps[3] = {0.5, 0.5, 1e-3};
  for (int k = 0; k < 3; ++k) {
    double plus[3] = {centre_px.x, centre_px.y, z}, minus[3] = {centre_px.x, centre_px.y, z};
    plus[k] += steps[k];
    minus[k] -= steps[k];
    jacobian.col(k) = (RangeBearing(camera, plus[0], plus[1], plus[2]) -
                       RangeBearing(camera, minus[0], minus[1], minus[2])) /
                      (2.0 * steps[k]);
  }
  const Eigen::Vector3d variances(sigma_px * sigma_px, sigma_px * sigma_px, sigma_z * sigma_z);
  m.covariance = jacobian * variances.asDiagonal() * jacobian.transpose();
  return m;
}

}  // namespace slamo::vision
