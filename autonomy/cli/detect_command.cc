// `slamo detect`: colour detection on one image (a rendered frame or an ordinary photo),
// with range and bearing when a registered depth image is given; without one, objects resting
// on the floor are typed and ranged on the ground plane through the robot's camera mount.
#include <cstdio>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "autonomy/cli/commands.h"
#include "field_configs/loader.h"
#include "vision/detector.h"

namespace slamo::autonomy {
namespace {

struct DetectArgs {
  std::string colour_path;
  std::string depth_path;
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  std::string colours_file;
  std::string method = "threshold";
  std::string separate = "defects";
  bool landmarks = false;
  std::string out;
  bool json = false;
};

int Run(const DetectArgs& args) {
  vision::DetectOptions options;
  try {
    options.method = vision::ParseDetectMethod(args.method);
    options.separation = vision::ParseSeparationMethod(args.separate);
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  const cv::Mat colour = cv::imread(args.colour_path, cv::IMREAD_COLOR);
  if (colour.empty()) {
    std::cerr << "error: --color " << args.colour_path << ": not a readable image\n";
    return 2;
  }
  cv::Mat depth;
  if (!args.depth_path.empty()) {
    depth = cv::imread(args.depth_path, cv::IMREAD_UNCHANGED);
    if (depth.empty()) {
      std::cerr << "error: --depth " << args.depth_path << ": not a readable image\n";
      return 2;
    }
  }

  vision::DetectorSetup setup;
  if (!args.colours_file.empty()) {
    setup = vision::PhotoDetectorSetup(vision::LoadColourClasses(args.colours_file));
    if (!depth.empty()) {
      setup.camera = vision::CameraModel(field::LoadRobotConfig(args.robot).camera);
    }
  } else {
    const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
    const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
    setup = args.landmarks ? vision::LandmarkDetectorSetup(season, &robot.camera)
                           : vision::ObjectDetectorSetup(season, &robot.camera);
  }
  // The robot file describes the depth camera; an image of another size is the same camera
  // at another resolution.
  if (setup.camera && (setup.camera->config().width_px != colour.cols ||
                       setup.camera->config().height_px != colour.rows)) {
    setup.camera = setup.camera->Scaled(colour.cols, colour.rows);
  }

  std::vector<vision::Detection> detections;
  vision::DetectStats stats;
  try {
    detections = vision::Detect(colour, depth, setup, options, &stats);
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }

  if (args.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const vision::Detection& d : detections) {
      nlohmann::json j = {
          {"colour", d.colour},       {"kind", d.kind},
          {"u", d.centre_px.x},       {"v", d.centre_px.y},
          {"radius_px", d.radius_px}, {"box", {d.box.x, d.box.y, d.box.width, d.box.height}},
          {"area_px", d.area_px},     {"score", d.score},
          {"split", d.split}};
      if (d.measurement) {
        const vision::Measurement& m = *d.measurement;
        j["range_m"] = m.range_m;
        j["bearing_deg"] = m.bearing_rad * 180.0 / M_PI;
        j["x_m"] = m.position_robot_m.x();
        j["y_m"] = m.position_robot_m.y();
        j["z_m"] = m.position_robot_m.z();
        j["covariance"] = {m.covariance(0, 0), m.covariance(0, 1), m.covariance(1, 1)};
        j["ground_plane"] = m.depth_pixels == 0;
      }
      out.push_back(j);
    }
    std::cout << out.dump(2) << "\n";
  } else {
    for (const vision::Detection& d : detections) {
      std::printf("%-8s %-11s centre (%6.1f, %6.1f) r %5.1f px  area %7.0f  score %.2f%s",
                  d.colour.c_str(), d.kind.empty() ? "-" : d.kind.c_str(), d.centre_px.x,
                  d.centre_px.y, d.radius_px, d.area_px, d.score, d.split ? "  split" : "");
      if (d.measurement) {
        const vision::Measurement& m = *d.measurement;
        std::printf("  range %.3f m  bearing %6.1f deg  robot (%.3f, %.3f, %.3f) m%s", m.range_m,
                    m.bearing_rad * 180.0 / M_PI, m.position_robot_m.x(), m.position_robot_m.y(),
                    m.position_robot_m.z(), m.depth_pixels == 0 ? "  (ground plane)" : "");
      } else if (!depth.empty()) {
        std::printf("  no valid depth");
      }
      std::printf("\n");
    }
    std::printf(
        "%zu detections (%s, separation %s); blobs %d, rejected: small %d, shape %d, size %d; "
        "without depth %d\n",
        detections.size(), args.method.c_str(), args.separate.c_str(), stats.blobs,
        stats.rejected_small, stats.rejected_shape, stats.rejected_size, stats.without_depth);
  }
  if (!args.out.empty()) {
    if (!cv::imwrite(args.out, vision::DrawDetections(colour, detections))) {
      std::cerr << "error: could not write " << args.out << "\n";
      return 1;
    }
    if (!args.json) std::printf("wrote %s\n", args.out.c_str());
  }
  return 0;
}

}  // namespace

void RegisterDetectCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<DetectArgs>();
  CLI::App* detect = app.add_subcommand(
      "detect",
      "Find coloured objects in an image; with depth, their range and bearing.   "
      "e.g. slamo detect --color colour.png --depth depth.png --out seen.png");
  detect
      ->add_option("--color,--colour", args->colour_path, "colour image (any format OpenCV reads)")
      ->required();
  detect->add_option("--depth", args->depth_path, "registered 16-bit depth image, millimetres");
  detect->add_option("--season", args->season, "season whose object colours to look for")
      ->capture_default_str();
  detect->add_option("--colours", args->colours_file,
                     "colours file instead of a season (for photos; see vision/README.md)");
  detect->add_option("--robot", args->robot, "robot file: the camera model for depth")
      ->capture_default_str();
  detect->add_option("--method", args->method, "threshold | kmeans")->capture_default_str();
  detect->add_option("--separate", args->separate, "defects | watershed | none")
      ->capture_default_str();
  detect->add_flag("--landmarks", args->landmarks, "look for the season's landmarks instead");
  detect->add_option("--out,-o", args->out, "write the annotated picture here");
  detect->add_flag("--json", args->json, "print a JSON array instead of lines");
  detect->callback([action, args] { *action = [args] { return Run(*args); }; });
}

}  // namespace slamo::autonomy
