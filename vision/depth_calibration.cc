#include "vision/depth_calibration.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include <Eigen/SVD>

#include "platform/camera_geometry.h"

namespace slamo::vision {
namespace {

using platform::kPi;

// Plane through the points' centroid with the normal of least variance (SVD of the scatter
// matrix): the least-squares plane in point-to-plane distance.
Eigen::Vector4d LeastSquaresPlane(const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<int>& indices) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i : indices) centroid += points[i];
  centroid /= static_cast<double>(indices.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i : indices) {
    const Eigen::Vector3d q = points[i] - centroid;
    scatter += q * q.transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(scatter, Eigen::ComputeFullU);
  const Eigen::Vector3d normal = svd.matrixU().col(2);
  return Eigen::Vector4d(normal.x(), normal.y(), normal.z(), -normal.dot(centroid));
}

// The same plane with its normal facing the camera (the origin on the positive side, d > 0).
Eigen::Vector4d FacingCamera(const Eigen::Vector4d& plane) {
  const bool flip = plane.w() < 0 || (plane.w() == 0 && plane.z() > 0);
  return flip ? Eigen::Vector4d(-plane) : plane;
}

std::vector<int> Inliers(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector4d& plane,
                         double threshold_m) {
  std::vector<int> inliers;
  const Eigen::Vector3d n = plane.head<3>();
  for (size_t i = 0; i < points.size(); ++i) {
    if (std::abs(n.dot(points[i]) + plane.w()) <= threshold_m) {
      inliers.push_back(static_cast<int>(i));
    }
  }
  return inliers;
}

std::string Trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

std::string TypeName(int type) {
  const char* depths[] = {"8U", "8S", "16U", "16S", "32S", "32F", "64F", "16F"};
  return std::string(depths[CV_MAT_DEPTH(type)]) + "C" + std::to_string(CV_MAT_CN(type));
}

}  // namespace

// MRPT ships a generic RANSAC (mrpt::math::RANSAC_Template, ransac_detect_3D_planes), but the
// thesis's constraint on the normal is easier to see, and to test, in this short loop.
std::optional<PlaneFit> FitPlaneRansac(const std::vector<Eigen::Vector3d>& points,
                                       const PlaneFitOptions& options) {
  const int n = static_cast<int>(points.size());
  if (n < std::max(3, options.min_inliers)) return std::nullopt;
  const double min_abs_cos = std::cos(options.max_normal_angle_deg * kPi / 180.0);
  const auto meets_constraint = [min_abs_cos](const Eigen::Vector3d& normal) {
    return std::abs(normal.z()) >= min_abs_cos;
  };

  // Sample: three distinct points, a model when its normal is close enough to the axis.
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  Eigen::Vector4d plane = Eigen::Vector4d::Zero();
  std::vector<int> inliers;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    const int i = pick(rng);
    int j = pick(rng), k = pick(rng);
    if (i == j || i == k || j == k) continue;
    Eigen::Vector3d normal = (points[j] - points[i]).cross(points[k] - points[i]);
    if (normal.norm() < 1e-12) continue;  // collinear
    normal.normalize();
    if (!meets_constraint(normal)) continue;
    // Score: the number of points within the threshold.
    const Eigen::Vector4d sample(normal.x(), normal.y(), normal.z(), -normal.dot(points[i]));
    int count = 0;
    for (const Eigen::Vector3d& p : points) {
      count += std::abs(normal.dot(p) + sample.w()) <= options.inlier_threshold_m;
    }
    if (count <= static_cast<int>(inliers.size()) || count < options.min_inliers) continue;
    // Refine a new best: least squares on its inliers, twice (the refined plane gathers its
    // own inliers). It counts only if the refined normal keeps the constraint: three points
    // of a post or a ball's rim can span a plane facing the camera, their inliers cannot.
    std::vector<int> refined_inliers = Inliers(points, sample, options.inlier_threshold_m);
    Eigen::Vector4d refined = sample;
    for (int pass = 0; pass < 2 && static_cast<int>(refined_inliers.size()) >= 3; ++pass) {
      refined = FacingCamera(LeastSquaresPlane(points, refined_inliers));
      refined_inliers = Inliers(points, refined, options.inlier_threshold_m);
    }
    if (meets_constraint(refined.head<3>()) && refined_inliers.size() > inliers.size() &&
        static_cast<int>(refined_inliers.size()) >= options.min_inliers) {
      plane = refined;
      inliers = std::move(refined_inliers);
    }
  }
  if (inliers.empty()) return std::nullopt;

  PlaneFit fit;
  fit.plane = plane;
  fit.distance_m = std::abs(plane.w());
  fit.inliers = static_cast<int>(inliers.size());
  fit.points = n;
  double sum2 = 0;
  for (int i : inliers) sum2 += std::pow(plane.head<3>().dot(points[i]) + plane.w(), 2);
  fit.rms_m = std::sqrt(sum2 / fit.inliers);
  return fit;
}

std::vector<Eigen::Vector3d> DepthToPoints(const cv::Mat& depth_mm, const CameraModel& camera,
                                           bool apply_correction, int stride) {
  if (depth_mm.empty()) throw std::invalid_argument("depth image is empty");
  if (depth_mm.type() != CV_16UC1) {
    throw std::invalid_argument(
        "depth image must be 16-bit millimetres with one channel (16UC1), got " +
        TypeName(depth_mm.type()));
  }
  const field::CameraConfig& config = camera.config();
  if (depth_mm.cols != config.width_px || depth_mm.rows != config.height_px) {
    throw std::invalid_argument("depth image is " + std::to_string(depth_mm.cols) + "x" +
                                std::to_string(depth_mm.rows) + " but the camera (" + config.model +
                                ") is " + std::to_string(config.width_px) + "x" +
                                std::to_string(config.height_px));
  }
  if (stride < 1) throw std::invalid_argument("stride must be at least 1");

  std::vector<Eigen::Vector3d> points;
  for (int v = 0; v < depth_mm.rows; v += stride) {
    const uint16_t* row = depth_mm.ptr<uint16_t>(v);
    for (int u = 0; u < depth_mm.cols; u += stride) {
      if (row[u] == 0) continue;
      const double z_m = apply_correction ? camera.CorrectDepthM(row[u]) : row[u] / 1000.0;
      // Pixel centres, as the renderer casts its rays.
      points.push_back(camera.BackProject(u + 0.5, v + 0.5, z_m));
    }
  }
  return points;
}

Eigen::Matrix3d LevelledFromCamera(const CameraModel& camera) {
  // Levelled axes in the robot frame (x forward, y left, z up): right, down, forward.
  Eigen::Matrix3d levelled_from_robot;
  levelled_from_robot << 0, -1, 0,  //
      0, 0, -1,                     //
      1, 0, 0;
  const Eigen::Matrix3d robot_from_camera =
      platform::RobotFromCamera(camera.config().mount).linear();
  return levelled_from_robot * robot_from_camera;
}

std::vector<Eigen::Vector3d> LevelAboveFloor(const std::vector<Eigen::Vector3d>& points_camera,
                                             const CameraModel& camera, double min_height_m) {
  const Eigen::Matrix3d rotation = LevelledFromCamera(camera);
  std::vector<Eigen::Vector3d> levelled;
  levelled.reserve(points_camera.size());
  for (const Eigen::Vector3d& p : points_camera) {
    if (camera.CameraToRobot(p).z() >= min_height_m) levelled.push_back(rotation * p);
  }
  return levelled;
}

LinearCorrection FitLinearCorrection(
    const std::vector<std::pair<double, double>>& measured_true_mm) {
  const int n = static_cast<int>(measured_true_mm.size());
  double mean_measured = 0, mean_true = 0;
  for (const auto& [measured, truth] : measured_true_mm) {
    if (!std::isfinite(measured) || !std::isfinite(truth)) {
      throw std::invalid_argument("depth pairs: a value is not a finite number");
    }
    mean_measured += measured;
    mean_true += truth;
  }
  const bool distinct =
      n >= 2 && std::any_of(measured_true_mm.begin(), measured_true_mm.end(),
                            [&](const auto& p) { return p.second != measured_true_mm[0].second; });
  if (!distinct) {
    throw std::invalid_argument(
        "depth pairs: a linear fit needs at least two distinct true distances, got " +
        std::to_string(n) + " pair(s)");
  }
  mean_measured /= n;
  mean_true /= n;
  double sxy = 0, sxx = 0;
  for (const auto& [measured, truth] : measured_true_mm) {
    sxy += (truth - mean_true) * (measured - mean_measured);
    sxx += (truth - mean_true) * (truth - mean_true);
  }
  LinearCorrection fit;
  fit.a = sxy / sxx;
  if (!(fit.a > 0)) {
    throw std::invalid_argument("depth pairs: the fitted slope a = " + std::to_string(fit.a) +
                                " is not positive (measured depth must grow with the distance)");
  }
  fit.b_mm = mean_measured - fit.a * mean_true;
  fit.pairs = n;
  double sum2 = 0;
  for (const auto& [measured, truth] : measured_true_mm) {
    sum2 += std::pow(measured - (fit.a * truth + fit.b_mm), 2);
  }
  fit.rms_mm = std::sqrt(sum2 / n);
  return fit;
}

double AccumulatedError(const std::vector<std::vector<double>>& measured_m_per_set,
                        const std::vector<double>& true_m) {
  if (measured_m_per_set.empty()) {
    throw std::invalid_argument("accumulated error: no sets of measurements");
  }
  if (measured_m_per_set.size() != true_m.size()) {
    throw std::invalid_argument("accumulated error: " + std::to_string(measured_m_per_set.size()) +
                                " sets of measurements but " + std::to_string(true_m.size()) +
                                " true distances");
  }
  double sum2 = 0;
  for (size_t i = 0; i < true_m.size(); ++i) {
    for (double d : measured_m_per_set[i]) sum2 += (d - true_m[i]) * (d - true_m[i]);
  }
  return std::sqrt(sum2) / static_cast<double>(true_m.size());
}

std::vector<std::pair<double, double>> ReadDepthPairsCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open the depth pairs file");
  const auto error = [&path](int line, const std::string& what) {
    return std::invalid_argument(path + ":" + std::to_string(line) + ": " + what);
  };

  // Header: the unit of both columns.
  std::string line;
  int line_number = 1;
  if (!std::getline(in, line))
    throw error(1, "empty file, expected the header measured_mm,true_mm");
  std::string header = Trim(line);
  header.erase(std::remove(header.begin(), header.end(), ' '), header.end());
  double scale_to_mm = 0;
  if (header == "measured_mm,true_mm") {
    scale_to_mm = 1.0;
  } else if (header == "measured_m,true_m") {
    scale_to_mm = 1000.0;
  } else {
    throw error(1, "expected the header measured_mm,true_mm or measured_m,true_m, got '" +
                       Trim(line) + "'");
  }

  // Rows: two positive numbers.
  std::vector<std::pair<double, double>> pairs;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string row = Trim(line);
    if (row.empty() || row[0] == '#') continue;
    std::stringstream fields(row);
    std::string field;
    std::vector<double> values;
    while (std::getline(fields, field, ',')) {
      const std::string text = Trim(field);
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (text.empty() || *end != '\0' || !std::isfinite(value)) {
        throw error(line_number, "'" + text + "' is not a number (row '" + row + "')");
      }
      if (value <= 0) {
        throw error(line_number, "depths must be positive, got " + text + " (row '" + row + "')");
      }
      values.push_back(value * scale_to_mm);
    }
    if (values.size() != 2 || row.back() == ',') {
      throw error(line_number, "expected two comma-separated values, got '" + row + "'");
    }
    pairs.emplace_back(values[0], values[1]);
  }
  if (pairs.empty()) throw error(line_number, "no data rows after the header");
  return pairs;
}

}  // namespace slamo::vision
