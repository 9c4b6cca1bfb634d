// `slamo eval vision`: every detection and separation method scored against the simulator's
// ground truth over many rendered views.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "autonomy/cli/commands.h"
#include "autonomy/cli/options.h"
#include "autonomy/experiments/vision_eval.h"
#include "field_configs/loader.h"

namespace slamo::autonomy {
namespace {

struct EvalArgs {
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  int frames = 50;
  uint64_t seed = 1;
  std::string pictures;
  std::string picture_method = "kmeans+defects";
  bool arena = false;
  bool no_depth = false;
  double max_range_m = 3.0;
  double pose_sigma_m = 0.05;
  std::vector<int> pile;  // MIN,MAX
  bool no_size_split = false;
  bool no_sphere_split = false;
  bool no_sphere_pieces = false;
  bool no_bulge_test = false;
  bool no_curvature_test = false;
  bool either_curvature = false;
  bool keep_small_pieces = false;
  bool same_depth_cut = false;
  bool no_attach_test = false;
  bool no_float_test = false;
  bool no_depth_cut = false;
  bool no_supports = false;
  bool no_sliver_drop = false;
  bool no_semi_discs = false;
  bool no_semi_spheres = false;
  bool no_flat_sides = false;
  bool semi_spheres_threshold = false;
};

int RunVision(const EvalArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  VisionEvalOptions options;
  options.frames = args.frames;
  options.seed = args.seed;
  options.picture_dir = args.pictures;
  options.picture_method = args.picture_method;
  options.arena = args.arena;
  options.depth = !args.no_depth;
  options.max_range_m = args.max_range_m;
  options.pose_sigma_m = args.pose_sigma_m;
  options.detect.split_by_size = !args.no_size_split;
  options.detect.split_spheres = !args.no_sphere_split;
  options.detect.split_sphere_pieces = !args.no_sphere_pieces;
  if (args.no_bulge_test) options.detect.min_bulge_ratio = 0.0;
  if (args.no_curvature_test) options.detect.flat_curvature_ratio = 0.0;
  options.detect.convex_curvature = !args.either_curvature;
  if (args.keep_small_pieces) options.detect.min_sized_area_ratio = 0.0;
  if (args.no_attach_test) options.detect.attach_margin_ratio = 0.0;
  options.detect.drop_floating = !args.no_float_test;
  if (args.no_depth_cut) options.detect.depth_cut_min_m = 0.0;
  if (args.same_depth_cut) options.detect.depth_cut_min_flat_m = 0.0;
  options.detect.size_split.rest_on_supports = !args.no_supports;
  if (args.no_sliver_drop) options.detect.size_split.sliver_fraction = 0.0;
  if (args.no_semi_discs) options.detect.min_disc_fill = 0.0;
  if (args.no_semi_spheres) options.detect.semi_sphere_pieces = false;
  if (args.no_flat_sides) options.detect.flat_side_pieces = false;
  if (args.semi_spheres_threshold) options.detect.semi_sphere_threshold = true;
  if (!args.pile.empty()) {
    if (args.pile[0] > args.pile[1])
      throw std::invalid_argument("--pile MIN,MAX: MIN must not exceed MAX");
    options.pile_min = args.pile[0];
    options.pile_max = args.pile[1];
  }
  if (!args.pictures.empty()) std::filesystem::create_directories(args.pictures);
  const auto progress = [](int done, int total) {
    if (done % 10 == 0 || done == total) std::fprintf(stderr, "\rframe %d/%d", done, total);
    if (done == total) std::fprintf(stderr, "\n");
  };
  const std::vector<VisionMethodScore> scores = EvaluateVision(season, robot, options, progress);
  std::printf(
      "vision on %s, %s%s: %d rendered views, seed %llu (objects within %.1f m with >= %d "
      "visible pixels are expected; field gate pose sigma %.2f m)\n",
      season.season.c_str(), args.arena ? "arena" : "clean field",
      args.no_depth ? ", no depth" : "", args.frames, static_cast<unsigned long long>(args.seed),
      options.max_range_m, options.min_visible_px, options.pose_sigma_m);
  std::fputs(FormatVisionTable(scores).c_str(), stdout);
  std::fputs(FormatPileTable(scores).c_str(), stdout);
  for (const VisionMethodScore& s : scores) {
    if (s.name == args.picture_method) std::fputs(FormatTypeTable(s).c_str(), stdout);
  }
  return 0;
}

}  // namespace

void RegisterEvalCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* eval = app.add_subcommand("eval",
                                      "Score components against the simulator's ground truth.   "
                                      "e.g. slamo eval vision --frames 50");
  eval->require_subcommand(1);
  CLI::App* vision = eval->add_subcommand(
      "vision",
      "Detection and separation methods on rendered views: precision, recall, errors.   "
      "e.g. slamo eval vision --season over_under --arena --frames 100 --seed 1");
  AddSeasonRobotOptions(vision, &args->season, &args->robot);
  vision->add_option("--frames", args->frames, "rendered views")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  vision->add_option("--seed", args->seed, "random seed")->capture_default_str();
  vision->add_flag("--arena", args->arena,
                   "render the arena: crowd, posters and lights beyond the perimeter, opponent "
                   "robots on the field");
  vision->add_flag("--no-depth", args->no_depth,
                   "detect without the depth image (ranges and types from the ground plane)");
  vision->add_option("--max-range", args->max_range_m, "objects within this range are expected (m)")
      ->capture_default_str();
  vision
      ->add_option("--pose-sigma", args->pose_sigma_m,
                   "error of the pose the field gate is given, 1 sigma in x and y (m)")
      ->capture_default_str();
  vision
      ->add_option("--pile", args->pile,
                   "MIN,MAX: every view gets a heap of MIN..MAX touching objects of one colour "
                   "(the season's smallest type); counts of it are scored within 10 %")
      ->expected(2)
      ->delimiter(',')
      ->check(CLI::Range(1, 200));
  vision->add_flag("--no-size-split", args->no_size_split,
                   "separate without the objects' known size (the detector before it, for "
                   "comparison)");
  vision->add_flag("--no-sphere-split", args->no_sphere_split,
                   "separate touching balls without their centres (the detector before it, for "
                   "comparison)");
  vision->add_flag("--no-sphere-pieces", args->no_sphere_pieces,
                   "do not split a piece of the cut that no circle fits by the balls' centres "
                   "(the detector before it, for comparison)");
  vision->add_flag("--no-bulge-test", args->no_bulge_test,
                   "keep round detections whose surface does not curve away (the detector "
                   "before the test, for comparison)");
  vision->add_flag("--no-curvature-test", args->no_curvature_test,
                   "keep round detections flat along some direction (the detector before the "
                   "test, for comparison)");
  vision->add_flag("--either-curvature", args->either_curvature,
                   "in the curvature test, keep round detections that curve strongly towards "
                   "the camera (a saddle, a hollow) as well as away (the detector before, for "
                   "comparison)");
  vision->add_flag("--keep-small-pieces", args->keep_small_pieces,
                   "keep pieces split off by size however small (strips of a rim; the detector "
                   "before, for comparison)");
  vision->add_flag("--no-attach-test", args->no_attach_test,
                   "keep pieces whose top runs on into a taller body at their depth (a "
                   "bumper under its chassis; the detector before the test, for comparison)");
  vision->add_flag("--no-float-test", args->no_float_test,
                   "keep blobs held off the floor over nothing (the detector before the test, "
                   "for comparison)");
  vision->add_flag("--no-depth-cut", args->no_depth_cut,
                   "do not cut colour masks where the depth jumps (an object and a thing of its "
                   "colour far behind it stay one blob; the detector before, for comparison)");
  vision->add_flag("--same-depth-cut", args->same_depth_cut,
                   "cut colours with no round kind at the depth step of the others (0.25 m), not "
                   "0.1 m (the detector before, for comparison)");
  vision->add_flag("--no-supports", args->no_supports,
                   "split by size only what rests on the floor, not on the supports the season "
                   "places objects on (the detector before, for comparison)");
  vision->add_flag("--no-sliver-drop", args->no_sliver_drop,
                   "a thin group (a sliver of an object hidden or cut by the image's edge) "
                   "refuses the split by size of its whole pile (the detector before, for "
                   "comparison)");
  vision->add_flag("--no-semi-discs", args->no_semi_discs,
                   "separate a semi-transparent ball's blob like any other (at its concave "
                   "defects, or by watershed) even when its outline is a circle it fills (the "
                   "detector before, for comparison)");
  vision->add_flag("--no-semi-spheres", args->no_semi_spheres,
                   "reject a semi-transparent ball's blob or piece that no circle fits, however "
                   "well its depth fits one ball of its size (the detector before, for "
                   "comparison)");
  vision->add_flag("--no-flat-sides", args->no_flat_sides,
                   "reject a piece too small by its area for a ring (a flat kind) even when its "
                   "width and height are a ring's seen from the side, its top hidden (the "
                   "detector before, for comparison)");
  vision->add_flag("--semi-spheres-threshold", args->semi_spheres_threshold,
                   "find semi-transparent balls by their depth with the HSV threshold too, not "
                   "only with K-Means (slower on views full of them)");
  vision->add_option("--pictures", args->pictures,
                     "write annotated views of the 12 worst frames (detections, misses, false "
                     "and off-field detections) here");
  vision
      ->add_option("--picture-method", args->picture_method,
                   "method the pictures and the per-type table show")
      ->capture_default_str();
  vision->callback([action, args] { *action = [args] { return RunVision(*args); }; });
}

}  // namespace slamo::autonomy
