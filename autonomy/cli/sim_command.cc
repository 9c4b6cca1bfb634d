// `slamo sim`: the simulated field on its own. `sim render` writes what the robot's RGB-D
// camera sees from a pose, with ground truth; `sim drive` runs a drive script and shows how
// far encoder odometry drifts from the truth.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "autonomy/cli/commands.h"
#include "autonomy/cli/options.h"
#include "field_configs/config_error.h"
#include "field_configs/loader.h"
#include "platform/drive_script.h"
#include "platform/field_geometry.h"
#include "platform/sim/sim_drive.h"
#include "platform/sim/sim_drive_script.h"
#include "platform/sim/sim_field.h"
#include "platform/sim/sim_renderer.h"
#include "platform/sim/sim_world.h"

namespace slamo::autonomy {
namespace {

using platform::kPi;
using platform::Pose2D;

struct SimArgs {
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  uint64_t seed = 1;
  std::string pose;  // "X,Y,THETA_DEG"; empty: the first red starting tile
  std::string out = "sim_render";
  bool baseline = false;
  bool no_noise = false;
  bool arena = false;
  std::string script = "forward 0.3; turn 90; forward 0.6";
};

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
nlohmann::json Box(const cv::Rect& r) {
  return {{"x", r.x}, {"y", r.y}, {"w", r.width}, {"h", r.height}};
}

int Render(const SimArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  const Pose2D pose = PoseOrFirstStart(season, args.pose);
  const platform::SimWorld world = platform::CreateWorld(season, args.seed);
  platform::RenderOptions options;
  options.colour_depth_baseline = args.baseline;
  if (args.no_noise) options.depth_noise = options.colour_noise = false;
  options.arena = args.arena;
  platform::SimRenderer renderer(season, robot.camera, options, args.seed);
  platform::FrameTruth truth;
  const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, &truth);

  std::filesystem::create_directories(args.out);
  const std::string colour_path = args.out + "/colour.png";
  const std::string depth_path = args.out + "/depth.png";
  if (!cv::imwrite(colour_path, frame.colour) || !cv::imwrite(depth_path, frame.depth_mm)) {
    std::cerr << "error: could not write images in " << args.out << "\n";
    return 1;
  }
  nlohmann::json j;
  j["season"] = season.season;
  j["seed"] = args.seed;
  j["robot_pose"] = {
      {"x_m", pose.x_m}, {"y_m", pose.y_m}, {"theta_deg", pose.theta_rad * 180.0 / kPi}};
  const Eigen::Isometry3d& cam = truth.world_from_camera;
  j["camera"] = {{"position_m", Vec(cam.translation())},
                 {"rotation_world_from_camera",
                  {Vec(cam.linear().col(0)), Vec(cam.linear().col(1)), Vec(cam.linear().col(2))}},
                 {"fx", robot.camera.fx},
                 {"fy", robot.camera.fy},
                 {"cx", robot.camera.cx},
                 {"cy", robot.camera.cy},
                 {"depth_png", "uint16 millimetres along the optical axis, 0 = no reading"}};
  j["objects"] = nlohmann::json::array();
  for (const auto& o : truth.objects) {
    j["objects"].push_back({{"id", o.id},
                            {"type", o.type},
                            {"colour", o.colour},
                            {"position_m", Vec(o.position_m)},
                            {"position_cam_m", Vec(o.position_cam_m)},
                            {"pixels", o.pixels},
                            {"box", Box(o.box)}});
  }
  j["landmarks"] = nlohmann::json::array();
  for (const auto& l : truth.landmarks) {
    j["landmarks"].push_back({{"index", l.index},
                              {"colour", season.landmarks[l.index].colour},
                              {"position_m", Vec(l.position_m)},
                              {"position_cam_m", Vec(l.position_cam_m)},
                              {"pixels", l.pixels},
                              {"box", Box(l.box)}});
  }
  std::ofstream(args.out + "/truth.json") << j.dump(2) << "\n";
  std::cout << "wrote " << colour_path << ", " << depth_path << ", " << args.out << "/truth.json ("
            << truth.objects.size() << " objects and " << truth.landmarks.size()
            << " landmarks in view)\n";
  return 0;
}

int Drive(const SimArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  const Pose2D start = ParsePose(args.pose.empty() ? "-0.9,-0.6,0" : args.pose);
  if (!platform::FootprintIsFree(season, start, robot.length_m, robot.width_m, robot.height_m)) {
    std::cerr << "error: --pose " << args.pose
              << ": the robot does not fit there (wall or structure)\n";
    return 2;
  }
  std::vector<platform::DriveStep> steps;
  try {
    steps = platform::ParseDriveScript(args.script);
  } catch (const platform::DriveScriptError& e) {
    std::cerr << "error: --script: " << e.what() << "\n";
    return 2;
  }
  // The whole field: the robot pushes objects, opponents follow their paths.
  platform::SimField field(season, robot, field::Alliance::kRed, args.seed, start,
                           platform::SimDriveOptionsFor(robot.drive));
  const platform::SimWorld before = field.world();
  platform::SimClock clock;
  const std::vector<platform::DriveStepResult> results =
      platform::RunDriveScript(steps, platform::DriveControllerOptionsFor(robot.drive),
                               &field.drive(), &clock, [&field](double dt_s) { field.Step(dt_s); });
  std::printf("%s on %s, seed %llu, start (%.3f, %.3f, %.1f deg)\n", robot.name.c_str(),
              season.season.c_str(), static_cast<unsigned long long>(args.seed), start.x_m,
              start.y_m, start.theta_rad * 180.0 / kPi);
  std::printf("%-16s %7s  %-24s %-24s %9s %9s\n", "step", "t_s", "true x, y, th(deg)",
              "odometry x, y, th(deg)", "pos_err_m", "th_err_deg");
  for (const auto& r : results) {
    const Pose2D& t = r.true_pose;
    const Pose2D& o = r.odometry_pose;
    const double pos_err = std::hypot(t.x_m - o.x_m, t.y_m - o.y_m);
    const double th_err = platform::WrapAngleRad(o.theta_rad - t.theta_rad) * 180.0 / kPi;
    std::printf("%-16s %7.2f  %6.3f, %6.3f, %7.2f   %6.3f, %6.3f, %7.2f   %9.3f %9.2f%s\n",
                r.step.text.c_str(), r.end_time_s, t.x_m, t.y_m, t.theta_rad * 180 / kPi, o.x_m,
                o.y_m, o.theta_rad * 180 / kPi, pos_err, th_err,
                r.status == platform::DriveStepStatus::kTimedOut ? "  (timed out)" : "");
  }
  int pushed = 0;
  for (size_t i = 0; i < before.objects.size(); ++i) {
    pushed += (field.world().objects[i].center_m - before.objects[i].center_m).norm() > 0.005;
  }
  std::printf("objects moved by robots: %d; score now red %d, blue %d\n", pushed,
              field.Score(field::Alliance::kRed), field.Score(field::Alliance::kBlue));
  return 0;
}

}  // namespace

void RegisterSimCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<SimArgs>();
  CLI::App* sim = app.add_subcommand(
      "sim",
      "The simulated field: render camera frames, drive scripts.   e.g. slamo sim render --seed 1");
  sim->require_subcommand(1);

  CLI::App* render = sim->add_subcommand(
      "render",
      "Write colour.png, depth.png (uint16 mm) and truth.json seen from a pose.   "
      "e.g. slamo sim render --pose -1.5,0.3,0 --out DIR");
  AddSeasonRobotOptions(render, &args->season, &args->robot);
  render->add_option("--seed", args->seed, "random seed (object regions, lighting, noise)")
      ->capture_default_str();
  render->add_option("--pose", args->pose,
                     "robot pose X,Y,THETA in m, m, deg (default: first red start tile)");
  render->add_option("--out,-o", args->out, "output directory")->capture_default_str();
  render->add_flag("--baseline", args->baseline,
                   "render colour from the colour camera's own position");
  render->add_flag("--no-noise", args->no_noise, "no depth or colour noise");
  render->add_flag("--arena", args->arena,
                   "an arena beyond the perimeter (crowd, posters, lights) and opponents with "
                   "bumpers in their alliance colour");
  render->callback([action, args] { *action = [args] { return Render(*args); }; });

  CLI::App* drive = sim->add_subcommand(
      "drive",
      "Drive a script; print true and encoder-odometry poses after each step.   "
      "e.g. slamo sim drive --seed 3 --script \"forward 0.3; turn 90\"");
  AddSeasonRobotOptions(drive, &args->season, &args->robot);
  drive->add_option("--pose", args->pose,
                    "start pose X,Y,THETA in m, m, deg (default -0.9,-0.6,0: open floor)");
  drive->add_option("--seed", args->seed, "random seed (wheel slip)")->capture_default_str();
  drive->add_option("--script", args->script, "statements: forward M; back M; turn DEG; wait S")
      ->capture_default_str();
  drive->callback([action, args] { *action = [args] { return Drive(*args); }; });
}

}  // namespace slamo::autonomy
