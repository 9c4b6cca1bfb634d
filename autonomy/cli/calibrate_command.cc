// `slamo calibrate`: depth calibration (thesis ch. 3). `calibrate plane` measures the
// camera-to-plane distance of a wall or board in one depth image; `calibrate depth` fits the
// linear correction d_c = (d - b) / a to (measured, true) pairs and reports the accumulated
// error E (eq. 3-1) before and after.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "autonomy/cli/commands.h"
#include "field_configs/loader.h"
#include "vision/camera_model.h"
#include "vision/depth_calibration.h"

namespace slamo::autonomy {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

struct CalibrateArgs {
  std::string depth;
  std::string robot = field::kDefaultRobot;
  bool raw = false;
  double max_angle_deg = 10.0;
  double min_height_m = 0.03;
  double half_width_m = 0.0;  // 0: no limit
  int stride = 1;
  std::string pairs;
};

int Plane(const CalibrateArgs& args) {
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  const vision::CameraModel camera(robot.camera);
  if (!std::filesystem::is_regular_file(args.depth)) {
    std::cerr << "error: " << args.depth << ": no such file\n";
    return 2;
  }
  const cv::Mat depth = cv::imread(args.depth, cv::IMREAD_UNCHANGED);
  if (depth.empty()) {
    std::cerr << "error: " << args.depth << ": not an image OpenCV can read\n";
    return 2;
  }
  std::vector<Eigen::Vector3d> points;
  try {
    points = vision::DepthToPoints(depth, camera, !args.raw, args.stride);
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << args.depth << ": " << e.what() << "\n";
    return 2;
  }
  std::vector<Eigen::Vector3d> levelled =
      vision::LevelAboveFloor(points, camera, args.min_height_m);
  if (args.half_width_m > 0) {
    const auto aside = [&args](const Eigen::Vector3d& p) {
      return std::abs(p.x()) > args.half_width_m;
    };
    levelled.erase(std::remove_if(levelled.begin(), levelled.end(), aside), levelled.end());
  }
  vision::PlaneFitOptions options;
  options.max_normal_angle_deg = args.max_angle_deg;
  const std::optional<vision::PlaneFit> fit = vision::FitPlaneRansac(levelled, options);

  const field::DepthCorrection& c = robot.camera.depth_correction;
  std::printf("%s: %dx%d, %zu points with depth, %zu at least %.3f m above the floor",
              args.depth.c_str(), depth.cols, depth.rows, points.size(), levelled.size(),
              args.min_height_m);
  if (args.half_width_m > 0) std::printf(" within %.3f m of the heading", args.half_width_m);
  std::printf("\n");
  if (args.raw) {
    std::printf("depth: raw\n");
  } else {
    std::printf("depth: corrected with %s's depth_correction {a: %g, b_mm: %g}\n",
                robot.name.c_str(), c.a, c.b_mm);
  }
  if (!fit) {
    std::printf(
        "no plane with %d inliers within %.3f m and its normal within %g deg of the "
        "robot's heading\n",
        options.min_inliers, options.inlier_threshold_m, args.max_angle_deg);
    return 1;
  }
  const Eigen::Vector3d normal_levelled = fit->plane.head<3>();
  const Eigen::Vector3d normal_camera =
      vision::LevelledFromCamera(camera).transpose() * normal_levelled;
  std::printf("distance_m: %.4f\n", fit->distance_m);
  std::printf(
      "normal (camera frame): [%.4f, %.4f, %.4f], %.1f deg from the optical axis, "
      "%.1f deg from the robot's heading\n",
      normal_camera.x(), normal_camera.y(), normal_camera.z(),
      std::acos(std::min(1.0, std::abs(normal_camera.z()))) * kRadToDeg,
      std::acos(std::min(1.0, std::abs(normal_levelled.z()))) * kRadToDeg);
  std::printf("inliers: %d / %d (%.1f %%)\n", fit->inliers, fit->points,
              100.0 * fit->inliers / fit->points);
  std::printf("rms_mm: %.2f\n", fit->rms_m * 1000.0);
  return 0;
}

int Depth(const CalibrateArgs& args) {
  std::vector<std::pair<double, double>> pairs;
  vision::LinearCorrection fit;
  try {
    pairs = vision::ReadDepthPairsCsv(args.pairs);  // its messages name the file
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  try {
    fit = vision::FitLinearCorrection(pairs);
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << args.pairs << ": " << e.what() << "\n";
    return 2;
  }
  const auto corrected_mm = [&fit](double measured_mm) { return (measured_mm - fit.b_mm) / fit.a; };

  // Group by true distance (to the micrometre) for eq. 3-1.
  std::map<long long, std::vector<std::pair<double, double>>> sets;
  for (const auto& pair : pairs) sets[std::llround(pair.second * 1000.0)].push_back(pair);
  std::vector<std::vector<double>> before_m, after_m;
  std::vector<double> true_m;
  double sum2_before = 0, sum2_after = 0;
  std::printf("%s: %d pairs at %zu true distances\n", args.pairs.c_str(), fit.pairs, sets.size());
  std::printf("%10s %4s %14s %15s\n", "true_mm", "n", "mean_error_mm", "after_corr_mm");
  for (const auto& [key, set] : sets) {
    true_m.push_back(set.front().second / 1000.0);
    before_m.emplace_back();
    after_m.emplace_back();
    double error_before = 0, error_after = 0;
    for (const auto& [measured, truth] : set) {
      before_m.back().push_back(measured / 1000.0);
      after_m.back().push_back(corrected_mm(measured) / 1000.0);
      error_before += measured - truth;
      error_after += corrected_mm(measured) - truth;
      sum2_before += std::pow(measured - truth, 2);
      sum2_after += std::pow(corrected_mm(measured) - truth, 2);
    }
    std::printf("%10.1f %4zu %14.2f %15.2f\n", set.front().second, set.size(),
                error_before / set.size(), error_after / set.size());
  }
  std::printf("depth_correction: {a: %.5f, b_mm: %.4f}\n", fit.a, fit.b_mm);
  std::printf("fit rms (measured - (a * true + b)): %.2f mm\n", fit.rms_mm);
  std::printf("rms error: before %.2f mm, after correction %.2f mm\n",
              std::sqrt(sum2_before / fit.pairs), std::sqrt(sum2_after / fit.pairs));
  std::printf("accumulated error E (eq. 3-1): before %.5f m, after correction %.5f m\n",
              vision::AccumulatedError(before_m, true_m),
              vision::AccumulatedError(after_m, true_m));
  return 0;
}

}  // namespace

void RegisterCalibrateCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* calibrate =
      app.add_subcommand("calibrate",
                         "Depth calibration (thesis ch. 3): plane distance, linear correction.   "
                         "e.g. slamo calibrate depth --pairs pairs.csv");
  calibrate->require_subcommand(1);

  CLI::App* plane = calibrate->add_subcommand(
      "plane",
      "Camera-to-plane distance of the wall or board the robot faces in a 16-bit depth PNG.   "
      "e.g. slamo calibrate plane --depth DIR/depth.png");
  plane->add_option("--depth", args->depth, "depth PNG, uint16 millimetres, 0 = no reading")
      ->required();
  plane->add_option("--robot", args->robot, "robot name or .yaml file (camera, mount, correction)")
      ->capture_default_str();
  plane->add_flag("--raw", args->raw, "do not apply the robot's depth correction");
  plane
      ->add_option("--max-angle-deg", args->max_angle_deg,
                   "largest angle between the plane's normal and the robot's heading")
      ->check(CLI::Range(0.0, 90.0))
      ->capture_default_str();
  plane
      ->add_option("--min-height-m", args->min_height_m,
                   "ignore points lower than this above the floor (by the camera mount)")
      ->capture_default_str();
  plane
      ->add_option("--half-width-m", args->half_width_m,
                   "ignore points farther than this to the side of the heading (0: no limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  plane->add_option("--stride", args->stride, "use every N-th row and column")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  plane->callback([action, args] { *action = [args] { return Plane(*args); }; });

  CLI::App* depth = calibrate->add_subcommand(
      "depth",
      "Fit depth_correction {a, b_mm} (measured = a * true + b) to a CSV of pairs.   "
      "e.g. slamo calibrate depth --pairs pairs.csv");
  depth
      ->add_option("--pairs", args->pairs,
                   "CSV with the header measured_mm,true_mm (or measured_m,true_m)")
      ->required();
  depth->callback([action, args] { *action = [args] { return Depth(*args); }; });
}

}  // namespace slamo::autonomy
