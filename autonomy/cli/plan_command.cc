// `slamo plan`: a path for the robot across a season's field with its starting objects (as
// the simulator places them from the seed), planned with OMPL on the object map's 2D grid.
// Prints the status, length, estimated travel time and the observation stops, and can draw
// the plan over the field and export it as a LemLib / PATH.JERRYIO path file. Exit status: 0
// with a path, 1 without one (or when a file cannot be written), 2 on bad input.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "autonomy/cli/commands.h"
#include "autonomy/cli/options.h"
#include "autonomy/reports/field_picture.h"
#include "field_configs/loader.h"
#include "mapping/object_map.h"
#include "planning/export.h"
#include "planning/planner.h"
#include "platform/sim/sim_world.h"

namespace slamo::autonomy {
namespace {

struct PlanArgs {
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  std::string from;
  std::string to;
  std::string planner = "rrtconnect";
  double budget_s = 0.05;
  uint64_t seed = 1;
  double stop_spacing_m = 0.3;
  bool no_objects = false;  // plan on the walls and structures only
  std::string out;
  std::string export_file;  // LemLib path file (PATH.JERRYIO's LemLib v0.4 format)
};

// "X,Y,TH_DEG" as (x, y, heading in degrees); the program exits 2 naming `option` otherwise.
Eigen::Vector3d PoseDeg(const std::string& text, const std::string& option) {
  const platform::Pose2D pose = ParsePose(text, option);
  return Eigen::Vector3d(pose.x_m, pose.y_m, pose.theta_rad * 180.0 / platform::kPi);
}

// The field, the inflated obstacles lightly, the objects, the path and the stops.
cv::Mat DrawPlan(const field::SeasonConfig& season, const planning::Planner& planner,
                 const std::vector<mapping::MappedObject>& objects,
                 const planning::PlanRequest& request, const planning::PlanResult& result) {
  FieldPictureOptions options;
  options.draw_objects = false;
  FieldCanvas canvas(season, options);
  canvas.DrawFloorAndWalls();
  // Inflated obstacles: where the robot's centre may not go.
  cv::Mat& image = canvas.image();
  cv::Mat overlay = image.clone();
  const mapping::OccupancyGrid2D& grid = planner.grid();
  const int cell_px = std::max(1, canvas.ToPixels(grid.cell_m));
  for (int row = 0; row < grid.height; ++row) {
    for (int col = 0; col < grid.width; ++col) {
      if (!planner.blocked()[static_cast<size_t>(row) * grid.width + col]) continue;
      const cv::Point p = canvas.ToPixel(grid.origin_m.x() + col * grid.cell_m,
                                         grid.origin_m.y() + (row + 1) * grid.cell_m);
      cv::rectangle(overlay, cv::Rect(p.x, p.y, cell_px, cell_px), cv::Scalar(120, 120, 255),
                    cv::FILLED);
    }
  }
  cv::addWeighted(overlay, 0.3, image, 0.7, 0.0, image);
  canvas.DrawStructures();
  canvas.DrawGoals();
  for (const mapping::MappedObject& o : objects) {
    cv::circle(image, canvas.ToPixel(o.centre_m.x(), o.centre_m.y()),
               std::max(2, canvas.ToPixels(o.radius_m)), cv::Scalar(90, 90, 90), 1, cv::LINE_AA);
  }
  // Path and stops (a tick shows the heading).
  for (size_t i = 1; i < result.path.size(); ++i) {
    cv::line(image, canvas.ToPixel(result.path[i - 1].x(), result.path[i - 1].y()),
             canvas.ToPixel(result.path[i].x(), result.path[i].y()), cv::Scalar(0, 140, 0), 3,
             cv::LINE_AA);
  }
  for (const Eigen::Vector3d& stop : result.stops) {
    const double heading_rad = stop.z() * M_PI / 180.0;
    const cv::Point p = canvas.ToPixel(stop.x(), stop.y());
    cv::circle(image, p, 6, cv::Scalar(0, 90, 200), cv::FILLED, cv::LINE_AA);
    cv::line(image, p,
             canvas.ToPixel(stop.x() + 0.1 * std::cos(heading_rad),
                            stop.y() + 0.1 * std::sin(heading_rad)),
             cv::Scalar(0, 90, 200), 2, cv::LINE_AA);
  }
  cv::circle(image, canvas.ToPixel(request.start_x_m, request.start_y_m), 9, cv::Scalar(0, 0, 0), 2,
             cv::LINE_AA);
  cv::drawMarker(image, canvas.ToPixel(request.goal_x_m, request.goal_y_m), cv::Scalar(0, 0, 0),
                 cv::MARKER_CROSS, 18, 2);
  canvas.DrawScaleBar();
  return image;
}

int Plan(const PlanArgs& args) {
  const Eigen::Vector3d from = PoseDeg(args.from, "--from");
  const Eigen::Vector3d to = PoseDeg(args.to, "--to");
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);

  // The map: the season with its starting objects.
  // Objects under the robot's footprint at the start (Toss Up's preloads lie on the starting
  // tiles) are the robot's own: left out, or the start would always be blocked.
  const platform::SimWorld world = platform::CreateWorld(season, args.seed);
  const double footprint_radius_m = std::hypot(robot.length_m, robot.width_m) / 2;
  std::vector<mapping::MappedObject> objects;
  for (const platform::SimObject& o : world.objects) {
    if (o.held || args.no_objects) continue;
    if (std::hypot(o.center_m.x() - from.x(), o.center_m.y() - from.y()) < footprint_radius_m) {
      continue;
    }
    objects.push_back(
        {o.id, o.type->name, o.colour, o.center_m, o.type->size_m / 2, o.type->height_m, 1.0});
  }
  planning::PlannerOptions options;
  options.stop_spacing_m = args.stop_spacing_m;
  mapping::ObjectMapOptions map_options;
  map_options.resolution_m = options.grid_cell_m;
  mapping::ObjectMap map(season, map_options);
  map.SetObjects(objects);
  planning::Planner planner(robot, options);
  planner.SetMap(map);

  // Plan.
  planning::SeedPlanners(args.seed);
  planning::PlanRequest request;
  request.start_x_m = from.x();
  request.start_y_m = from.y();
  request.start_heading_deg = from.z();
  request.goal_x_m = to.x();
  request.goal_y_m = to.y();
  request.goal_heading_deg = to.z();
  request.planner = args.planner;
  request.time_budget_s = args.budget_s;
  const planning::PlanResult result = planner.Plan(request);

  std::printf("%s (%s), seed %llu, %zu objects; robot %s, clearance %.3f m (inflation %.3f m)\n",
              season.name.c_str(), season.season.c_str(),
              static_cast<unsigned long long>(args.seed), objects.size(), robot.name.c_str(),
              options.clearance_m, planner.inflation_radius_m());
  std::printf("plan %s (%.3f s): %s\n", args.planner.c_str(), args.budget_s,
              planning::PlanStatusName(result.status));
  const bool has_path = !result.path.empty();
  if (has_path) {
    std::printf("length: %.3f m, %zu waypoints\n", result.length_m, result.path.size());
    std::printf("estimated time: %.1f s (turn in place at %.0f deg/s, drive at %.3f m/s)\n",
                result.travel_time_s, robot.drive.turn_rate_dps, robot.drive.cruise_speed_mps);
    std::printf("stops (every %.2f m): %zu\n", args.stop_spacing_m, result.stops.size());
    for (size_t i = 0; i < result.stops.size(); ++i) {
      std::printf("  %2zu: x %+.3f  y %+.3f  heading %+7.1f deg\n", i + 1, result.stops[i].x(),
                  result.stops[i].y(), result.stops[i].z());
    }
  }
  if (!args.out.empty()) {
    if (!cv::imwrite(args.out, DrawPlan(season, planner, objects, request, result))) {
      std::cerr << "error: " << args.out << ": cannot write the picture\n";
      return 1;
    }
    std::printf("wrote %s\n", args.out.c_str());
  }
  if (!args.export_file.empty()) {
    if (!has_path) {
      std::cerr << "error: --export: no path to export\n";
      return 1;
    }
    planning::LemLibExportOptions export_options;
    export_options.robot_width_in = robot.width_m / planning::kMetresPerInch;
    export_options.robot_length_in = robot.length_m / planning::kMetresPerInch;
    export_options.start_heading_deg = from.z();
    export_options.goal_heading_deg = to.z();
    export_options.name = "slamo " + season.season;
    try {
      planning::WriteLemLibPath(args.export_file, result.path, export_options);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 1;
    }
    std::printf("wrote %s (%zu points, LemLib v0.4 / PATH.JERRYIO, inches)\n",
                args.export_file.c_str(),
                planning::LemLibPoints(result.path, export_options).size());
  }
  return has_path ? 0 : 1;
}

}  // namespace

void RegisterPlanCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<PlanArgs>();
  CLI::App* plan = app.add_subcommand(
      "plan",
      "Plan a path across the field with its starting objects; print length, time and stops.   "
      "e.g. slamo plan --no-objects --from -0.8955,1.40,0 --to 0.3,-1.2,90 --out plan.png");
  AddSeasonRobotOptions(plan, &args->season, &args->robot);
  plan->add_option("--from", args->from, "start pose X,Y,TH_DEG (metres, degrees)")->required();
  plan->add_option("--to", args->to, "goal pose X,Y,TH_DEG (metres, degrees)")->required();
  plan->add_option("--planner", args->planner, "OMPL planner")
      ->check(CLI::IsMember(planning::PlannerNames()))
      ->capture_default_str();
  plan->add_option("--budget", args->budget_s, "planning time budget in seconds")
      ->check(CLI::Range(0.001, 60.0))
      ->capture_default_str();
  plan->add_option("--seed", args->seed, "random seed (objects and planner)")
      ->capture_default_str();
  plan->add_option("--stop-spacing", args->stop_spacing_m, "metres between stops (0: none)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  plan->add_flag("--no-objects", args->no_objects,
                 "plan on the walls and structures only (no starting objects)");
  plan->add_option("--out,-o", args->out, "PNG of the plan over the field");
  plan->add_option("--export", args->export_file,
                   "LemLib path file of the route (PATH.JERRYIO's LemLib v0.4 format, inches)");
  plan->callback([action, args] { *action = [args] { return Plan(*args); }; });
}

}  // namespace slamo::autonomy
