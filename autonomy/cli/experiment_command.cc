// `slamo experiment`: the thesis's SLAM experiments on the simulated field, averaged over
// seeds and printed as tables.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "autonomy/cli/commands.h"
#include "autonomy/cli/options.h"
#include "autonomy/experiments/peer_bench.h"
#include "autonomy/experiments/robustness.h"
#include "autonomy/experiments/slam_experiments.h"
#include "field_configs/loader.h"
#include "mapping/ekf_slam.h"

namespace slamo::autonomy {
namespace {

// The robustness tables' "rejected" column: the fraction the filter refused, or "-" when the
// filter does not say (MRPT's).
std::string RejectedText(const RobustnessScore& s) {
  if (s.rejected_fraction < 0.0) return "-";
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f %%", 100.0 * s.rejected_fraction);
  return text;
}

struct ExperimentArgs {
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  int runs = 5;
  uint64_t seed = 1;
  std::string landmarks = "1,2,3";
  std::string map = "slam,known";
  std::string out;  // case study: where to write the first run's object map
  std::string rules = "fixed:1,fixed:5,fixed:10,fixed:20,fixed:30,covariance,covariance:0.004,gmm";
};

std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

// Measures the per-stop measurement bias the iterated filter must model: 10 frames a stop,
// two landmarks, the same seeds as the experiment.
Eigen::Matrix2d MeasureBias(const field::SeasonConfig& field, const field::RobotConfig& robot,
                            const ExperimentArgs& args, Eigen::Vector2d* white) {
  WaypointsSetup setup;
  setup.landmarks = 2;
  mapping::ParseFrameRule("fixed:10", &setup.frames);
  std::vector<WaypointsRun> runs;
  for (int r = 0; r < args.runs; ++r)
    runs.push_back(RunWaypoints(field, robot, setup, args.seed + 1000 + r));
  Eigen::Vector2d bias;
  EstimateMeasurementNoise(runs, white, &bias);
  return bias.asDiagonal();
}

int RunWaypointsTable(const ExperimentArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  std::vector<mapping::FrameSelectionOptions> rules;
  for (const std::string& text : Split(args.rules)) {
    mapping::FrameSelectionOptions options;
    try {
      mapping::ParseFrameRule(text, &options);
    } catch (const std::invalid_argument& e) {
      std::cerr << "error: --frames: " << e.what() << "\n";
      return 2;
    }
    if (options.rule == mapping::FrameRule::kCovariance && options.covariance_threshold <= 0.0) {
      options.covariance_threshold =
          mapping::DerivedCovarianceThreshold(mapping::MotionNoise{}, 0.3);
    }
    rules.push_back(options);
  }
  std::vector<int> landmark_counts;
  for (const std::string& n : Split(args.landmarks)) {
    const int count = std::atoi(n.c_str());
    if (count < 1 || count > 3) {
      std::cerr << "error: --landmarks: expected counts 1, 2 or 3, got '" << n << "'\n";
      return 2;
    }
    landmark_counts.push_back(count);
  }

  Eigen::Vector2d white;
  const Eigen::Matrix2d bias = MeasureBias(WaypointsField(season, 2), robot, args, &white);
  std::printf(
      "measured per-frame noise (10 frames a stop, %d runs): range sd white %.4f m, per-stop bias "
      "%.4f m;"
      " bearing sd white %.5f rad, per-stop bias %.5f rad\n",
      args.runs, std::sqrt(white.x()), std::sqrt(bias(0, 0)), std::sqrt(white.y()),
      std::sqrt(bias(1, 1)));
  std::printf("derived covariance threshold (one 0.3 m leg of motion noise): %.4f m^2\n\n",
              mapping::DerivedCovarianceThreshold(mapping::MotionNoise{}, 0.3));
  const auto band = mapping::NeesBand(3, args.runs);
  std::printf(
      "thesis 4.5: 4 stops every 0.3 m to 1.2 m, %d runs from seed %llu; NEES band (95 %%, %d "
      "runs) "
      "[%.2f, %.2f]\n",
      args.runs, static_cast<unsigned long long>(args.seed), args.runs, band.first, band.second);
  std::vector<bool> map_modes;
  for (const std::string& m : Split(args.map)) {
    if (m != "slam" && m != "known") {
      std::cerr << "error: --map: expected slam and/or known, got '" << m << "'\n";
      return 2;
    }
    map_modes.push_back(m == "known");
  }
  std::printf("%-6s %-10s %-19s %10s %10s %8s %9s %11s %9s\n", "map", "landmarks", "frames",
              "acc_err_m", "odom_err_m", "frames", "observe_s", "compute_ms", "nees");
  int done = 0;
  const int total =
      static_cast<int>(map_modes.size() * landmark_counts.size() * rules.size()) * args.runs;
  for (const bool known : map_modes) {
    for (int landmarks : landmark_counts) {
      const field::SeasonConfig field = WaypointsField(season, landmarks);
      for (const mapping::FrameSelectionOptions& rule : rules) {
        WaypointsSetup setup;
        setup.landmarks = landmarks;
        setup.frames = rule;
        setup.bias_covariance = bias;
        setup.white_covariance = white.asDiagonal();  // the measured per-frame noise
        setup.known_landmarks = known;
        double error = 0, odom = 0, frames = 0, compute = 0, nees = 0;
        int nees_n = 0;
        for (int r = 0; r < args.runs; ++r) {
          const WaypointsRun run = RunWaypoints(field, robot, setup, args.seed + r);
          error += run.AccumulatedError() / args.runs;
          odom += run.OdometryAccumulatedError() / args.runs;
          frames += static_cast<double>(run.frames) / args.runs;
          compute += run.compute_s / args.runs;
          for (double n : run.stop_nees) nees += n, ++nees_n;
          std::fprintf(stderr, "\rrun %d/%d", ++done, total);
        }
        std::fprintf(stderr, "\r");
        std::printf("%-6s %-10d %-19s %10.4f %10.4f %8.1f %9.2f %11.2f %9.2f\n",
                    known ? "known" : "slam", landmarks, mapping::Describe(rule).c_str(), error,
                    odom, frames, frames / robot.camera.frame_rate_hz,
                    1000.0 * compute / std::max(1.0, frames), nees_n ? nees / nees_n : 0.0);
      }
    }
  }
  std::printf(
      "\nacc_err_m: sum over the 4 stops of the position error (thesis Table 4-1); odom_err_m: the "
      "same"
      " for encoder dead reckoning; frames: in total; observe_s: frames at %.0f fps; compute_ms: "
      "detection"
      " and filter per frame on this machine; nees: mean pose NEES at the stops.\n",
      robot.camera.frame_rate_hz);
  return 0;
}

int RunNeesTable(const ExperimentArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  Eigen::Vector2d white;
  const Eigen::Matrix2d bias = MeasureBias(WaypointsField(season, 2), robot, args, &white);
  const auto band = mapping::NeesBand(3, args.runs);
  std::printf(
      "pose NEES at each stop, averaged over %d runs (seed %llu); 95 %% band [%.2f, %.2f]\n",
      args.runs, static_cast<unsigned long long>(args.seed), band.first, band.second);
  std::printf("%-6s %-34s %8s %8s %8s %8s %8s\n", "map", "mode", "stop 1", "stop 2", "stop 3",
              "stop 4", "inside");
  for (const bool known : {false, true}) {
    for (int mode = 0; mode < 3; ++mode) {
      WaypointsSetup setup;
      setup.landmarks = 2;
      setup.known_landmarks = known;
      mapping::ParseFrameRule("fixed:10", &setup.frames);
      setup.iterate = mode != 0;
      // The measured per-frame noise; the per-stop bias modelled only in the last mode (and in
      // the single-frame mode, where one frame carries both).
      setup.white_covariance = white.asDiagonal();
      if (mode == 0) setup.white_covariance += bias;
      if (mode == 2) setup.bias_covariance = bias;
      std::vector<double> average(setup.stops, 0.0);
      for (int r = 0; r < args.runs; ++r) {
        const WaypointsRun run =
            RunWaypoints(WaypointsField(season, 2), robot, setup, args.seed + r);
        for (size_t s = 0; s < run.stop_nees.size(); ++s)
          average[s] += run.stop_nees[s] / args.runs;
      }
      int inside = 0;
      for (double a : average) inside += a >= band.first && a <= band.second;
      const char* name = mode == 0   ? "single frame"
                         : mode == 1 ? "10 frames, frames independent"
                                     : "10 frames, per-stop bias modelled";
      std::printf("%-6s %-34s %8.2f %8.2f %8.2f %8.2f %6d/%d\n", known ? "known" : "slam", name,
                  average[0], average[1], average[2], average[3], inside, setup.stops);
    }
  }
  return 0;
}

int RunCaseStudy(const ExperimentArgs& args, int study) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  // Thesis ch. 6 on the field: (1) a 1.5 m diagonal, stopping every 0.3 m; (2) 1.2 m forward,
  // a 90 degree left turn, 0.6 m. 20 frames a stop, the season's surveyed markers.
  // Starts with room to drive: clear of the hanging-bar posts and the goals.
  const platform::Pose2D start =
      study == 1 ? platform::Pose2D{-1.45, -0.45, 0.61} : platform::Pose2D{-1.524, -0.3048, 0.0};
  std::vector<std::string> legs;
  if (study == 1) {
    legs.assign(5, "forward 0.3");
  } else {
    legs.assign(4, "forward 0.3");
    legs.push_back("turn 90");
    legs.push_back("forward 0.3");
    legs.push_back("forward 0.3");
  }
  if (!args.out.empty()) std::filesystem::create_directories(args.out);
  WaypointsSetup setup;
  mapping::ParseFrameRule(args.rules.find(',') == std::string::npos ? args.rules : "fixed:20",
                          &setup.frames);
  setup.known_landmarks = args.map != "slam";
  std::printf("case study %d on %s: %s, frames %s, %s markers, %d runs from seed %llu\n", study,
              season.season.c_str(),
              study == 1 ? "1.5 m diagonal, stops every 0.3 m" : "1.2 m, turn left 90, 0.6 m",
              mapping::Describe(setup.frames).c_str(),
              setup.known_landmarks ? "surveyed" : "unknown (SLAM)", args.runs,
              static_cast<unsigned long long>(args.seed));
  std::vector<double> pose_error(legs.size(), 0.0), odometry_error(legs.size(), 0.0);
  double within3_sq = 0.0, all_sq = 0.0;
  int within3 = 0, matched = 0, tracked = 0, moved = 0, unconfirmed = 0;
  for (int r = 0; r < args.runs; ++r) {
    setup.map_out_dir = r == 0 ? args.out : "";
    const WaypointsRun run = RunRoute(season, robot, start, legs, setup, args.seed + r, true);
    for (size_t s = 0; s < legs.size(); ++s) {
      pose_error[s] += run.stop_error_m[s] / args.runs;
      odometry_error[s] += run.odometry_error_m[s] / args.runs;
    }
    for (const WaypointsRun::ObjectResult& o : run.objects) {
      if (!o.confirmed) {
        ++unconfirmed;  // seen once: not yet part of the map
        continue;
      }
      ++tracked;
      if (!o.matched) continue;
      ++matched;
      if (o.truth_moved) {
        ++moved;  // pushed by the robot after it was seen: not a mapping error
        continue;
      }
      all_sq += o.error_m * o.error_m;
      if (o.first_range_m <= 3.0) within3_sq += o.error_m * o.error_m, ++within3;
    }
    std::fprintf(stderr, "\rrun %d/%d", r + 1, args.runs);
  }
  std::fprintf(stderr, "\r");
  std::printf("%-6s %-12s %12s %12s\n", "stop", "leg", "slam_err_m", "odom_err_m");
  for (size_t s = 0; s < legs.size(); ++s) {
    std::printf("%-6zu %-12s %12.4f %12.4f\n", s + 1, legs[s].c_str(), pose_error[s],
                odometry_error[s]);
  }
  const int unmoved = matched - moved;
  std::printf(
      "objects: %d confirmed (seen at two stops or more; %d seen once are not mapped yet), ",
      tracked, unconfirmed);
  std::printf(
      "%d matched to a true object within 0.5 m (%d of those pushed by the robot afterwards, "
      "not scored); RMSE %.3f m over %d, %.3f m over the %d first seen within 3 m\n",
      matched, moved, unmoved ? std::sqrt(all_sq / unmoved) : 0.0, unmoved,
      within3 ? std::sqrt(within3_sq / within3) : 0.0, within3);
  return 0;
}

int RunPeerTable(const ExperimentArgs& args) {
  const PeerBenchOptions options;
  const PeerBenchResult result = RunPeerBench(options, args.runs, args.seed);
  std::printf(
      "peer comparison: %d laps of a %.1f m square in %.2f m steps, %d landmarks, range <= %.1f m"
      " (sd %.3f m, %.2f deg), odometry sd %.3f m, %.3f rad a step, ids known; %d runs from seed "
      "%llu\n",
      options.laps, options.side_m, options.step_m, options.landmarks, options.max_range_m,
      options.sigma_range_m, options.sigma_bearing_rad * 180.0 / 3.14159265358979323846,
      options.sigma_step_xy_m, options.sigma_step_heading_rad, args.runs,
      static_cast<unsigned long long>(args.seed));
  std::printf("%-28s %14s %16s %14s %9s %11s\n", "filter", "ATE_aligned_m", "ATE_unaligned_m",
              "mean_NEES", "in_band", "ms_per_step");
  for (const PeerRow& row : result.rows) {
    std::printf("%-28s %14.4f %16.4f %14.2f %5d/%-3d %11.4f\n", row.filter.c_str(),
                row.ate_aligned_m, row.ate_unaligned_m, row.mean_nees, row.steps_in_band, row.steps,
                row.ms_per_step);
  }
  std::printf(
      "\nATE: mean over runs of the trajectory RMSE, after rigid alignment and without; "
      "mean_NEES: pose NEES averaged over the runs at each step, then over steps 1-%d; in_band: "
      "steps whose run average lies in the 95 %% band [%.2f, %.2f]; ms_per_step: inside the "
      "filter's step call only, on this machine.\n",
      result.rows.empty() ? 0 : result.rows.front().steps, result.nees_band.first,
      result.nees_band.second);
  for (const PeerRow& row : result.rows) {
    if (row.rejected > 0) {
      std::printf("note: %s refused %d measurements\n", row.filter.c_str(), row.rejected);
    }
  }
  return 0;
}

// `slamo experiment robustness`: what the rows are made of.
struct RobustnessArgs {
  int runs = 3;
  std::string out = "robustness";
  std::string second_robot = "v5_drivetrain";  // drives the simulator rows
  std::string season = field::kDefaultSeason;  // its markers are the simulator rows' landmarks
};

int RunRobustnessTable(const RobustnessArgs& args, uint64_t seed) {
  const int runs = args.runs;
  const RobustnessOptions options;
  SimRobotOptions sim_options;
  sim_options.season = args.season;
  const std::vector<SimRobotCase> sim_cases = DefaultSimRobotCases(args.second_robot);
  std::vector<RobustnessRow> rows;
  std::vector<SimRobotRow> sim_rows;
  size_t markers = 0;
  const int mrpt_total = static_cast<int>(DefaultRobustnessCases().size()) * runs;
  const int total = mrpt_total + static_cast<int>(sim_cases.size()) * runs;
  const auto progress = [total](int done) {
    std::fprintf(stderr, "\rrobustness: %d/%d runs", done, total);
    if (done == total) std::fprintf(stderr, "\n");
  };
  try {
    // The robot and season files first: a typo fails before the long part.
    field::LoadRobotConfig(args.second_robot);
    markers = field::LoadSeasonConfig(args.season).landmarks.size();
    rows = RunRobustness(options, DefaultRobustnessCases(), runs, seed, args.out,
                         [&](int done, int) { progress(done); });
    sim_rows = RunSimRobotRows(
        sim_options, sim_cases, runs, seed, [&](int done, int) { progress(mrpt_total + done); },
        args.out);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  std::printf(
      "robustness: MRPT simul-landmarks logs (%d steps, %d landmarks, range <= %.0f m, field of "
      "view %.0f deg), %d runs from seed %llu; both filters told odometry sd %.3f m and %.2f deg "
      "a step, range sd %.3f m, bearing sd %.2f deg; the true noise is the row's multiple\n",
      options.steps, options.landmarks, options.max_range_m, options.field_of_view_deg, runs,
      static_cast<unsigned long long>(seed), options.odometry_xy_sigma_m,
      options.odometry_heading_sigma_deg, options.range_sigma_m, options.bearing_sigma_deg);
  std::printf("%-8s %-7s %-6s %16s %10s %10s %9s %12s\n", "motion", "sensor", "filter",
              "landmark_RMSE_m", "ATE_m", "mean_NEES", "rejected", "ms_per_step");
  for (const RobustnessRow& row : rows) {
    for (int f = 0; f < 2; ++f) {
      const RobustnessScore& s = f == 0 ? row.slamo : row.mrpt;
      const std::string rejected = RejectedText(s);
      std::printf("%-8s %-7s %-6s %16.4f %10.4f %10.2f %9s %12.4f\n",
                  (std::to_string(row.noise.motion_factor).substr(0, 4) + "x").c_str(),
                  (std::to_string(row.noise.sensor_factor).substr(0, 4) + "x").c_str(),
                  f == 0 ? "slamo" : "mrpt", s.landmark_rmse_m, s.ate_m, s.mean_nees,
                  rejected.c_str(), s.ms_per_step);
    }
  }
  const std::pair<double, double> band = mapping::NeesBand(3, 1);
  std::printf(
      "\nlandmark_RMSE and ATE after the trajectory's rigid alignment; mean_NEES: pose NEES (3 "
      "dof) averaged over the steps (one step's 95 %% band [%.2f, %.2f], expectation 3); "
      "rejected: measurements the filter refused (MRPT's does not say); ms_per_step: inside the "
      "filter's step calls, on this machine. slamo runs as `slamo replay` does (adaptive, "
      "first-estimates Jacobians).\n",
      band.first, band.second);

  std::printf(
      "\nrobustness on our simulator: the data robot drives two laps of a 2.4 m square on %s "
      "from (%.2f, %.2f) (its drive's physics and slip; its inertial sensor for the heading when "
      "it has one), one filter step per %.2f s; each of the season's %zu markers its camera sees "
      "is measured (1 px on the centre, its depth sigma on the depth; ids known, no occlusion); "
      "%d runs from seed %llu; both filters told the `told` robot file's odometry model and "
      "camera: MRPT one range sigma (the RMS of the camera's depth sigma over its range), slamo "
      "each measurement's (the depth sigma at the depth read), as a match's vision gives it\n",
      args.season.c_str(), sim_options.start.x_m, sim_options.start.y_m, sim_options.step_s,
      markers, runs, static_cast<unsigned long long>(seed));
  std::printf("%-14s %-14s %-6s %16s %10s %10s %9s %12s\n", "data", "told", "filter",
              "landmark_RMSE_m", "ATE_m", "mean_NEES", "rejected", "ms_per_step");
  for (const SimRobotRow& row : sim_rows) {
    for (int f = 0; f < 2; ++f) {
      const RobustnessScore& s = f == 0 ? row.slamo : row.mrpt;
      const std::string rejected = RejectedText(s);
      std::printf("%-14s %-14s %-6s %16.4f %10.4f %10.2f %9s %12.4f\n",
                  row.robots.data_robot.c_str(), row.robots.told_robot.c_str(),
                  f == 0 ? "slamo" : "mrpt", s.landmark_rmse_m, s.ate_m, s.mean_nees,
                  rejected.c_str(), s.ms_per_step);
    }
  }
  std::printf("\n");
  for (const SimRobotRow& row : sim_rows) {
    std::printf(
        "%s told %s: %.0f steps, %.1f m, %.2f markers seen a step, heading from %s; told range "
        "sd %.4f m (MRPT), bearing sd %.3f deg, max range %.2f m\n",
        row.robots.data_robot.c_str(), row.robots.told_robot.c_str(), row.steps, row.distance_m,
        row.measurements_per_step, row.gyro ? "the inertial sensor" : "the encoders",
        row.range_sigma_m, row.bearing_sigma_rad * 180.0 / M_PI, row.max_range_m);
  }
  if (!sim_rows.empty()) {
    std::printf(
        "each run's log is in %s/sim_<data>_told_<told>_run<r> (run.log, truth.tum, "
        "landmarks.csv): `slamo replay --log run.log --truth truth.tum --landmarks-truth "
        "landmarks.csv --start-sigma-m 0 --start-sigma-rad 0 --max-range <max range>` replays "
        "slamo's row\n",
        args.out.c_str());
  }
  return 0;
}

}  // namespace

void RegisterExperimentCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<ExperimentArgs>();
  CLI::App* experiment = app.add_subcommand("experiment",
                                            "The thesis's SLAM experiments on the simulator, as "
                                            "tables.   e.g. slamo experiment waypoints");
  experiment->require_subcommand(1);
  CLI::App* waypoints = experiment->add_subcommand(
      "waypoints",
      "Thesis 4.5: stops every 0.3 m to 1.2 m, 1-3 landmarks, each frame rule.   "
      "e.g. slamo experiment waypoints --runs 10");
  AddSeasonRobotOptions(waypoints, &args->season, &args->robot);
  waypoints->add_option("--runs", args->runs, "seeds averaged per row")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  waypoints->add_option("--seed", args->seed, "first seed")->capture_default_str();
  waypoints->add_option("--landmarks", args->landmarks, "landmark counts, comma separated")
      ->capture_default_str();
  waypoints->add_option("--map", args->map, "slam (markers found) and/or known (surveyed markers)")
      ->capture_default_str();
  waypoints
      ->add_option("--frames", args->rules,
                   "frame rules: fixed:N, covariance[:T], gmm; comma separated")
      ->capture_default_str();
  waypoints->callback([action, args] { *action = [args] { return RunWaypointsTable(*args); }; });

  CLI::App* nees = experiment->add_subcommand(
      "nees",
      "Pose NEES per stop over many runs, single-frame and iterated, against the 95 % band.   "
      "e.g. slamo experiment nees --runs 50");
  AddSeasonRobotOptions(nees, &args->season, &args->robot);
  nees->add_option("--runs", args->runs, "Monte Carlo runs")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  nees->add_option("--seed", args->seed, "first seed")->capture_default_str();
  nees->callback([action, args] { *action = [args] { return RunNeesTable(*args); }; });

  auto study = std::make_shared<int>(1);
  CLI::App* case_study = experiment->add_subcommand(
      "case-study",
      "Thesis ch. 6 on the field: pose error per stop and object errors.   "
      "e.g. slamo experiment case-study 1 --runs 5");
  case_study->add_option("study", *study, "1: 1.5 m diagonal; 2: 1.2 m, turn left 90, 0.6 m")
      ->required()
      ->check(CLI::Range(1, 2));
  AddSeasonRobotOptions(case_study, &args->season, &args->robot);
  case_study->add_option("--runs", args->runs, "seeds averaged")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  case_study->add_option("--seed", args->seed, "first seed")->capture_default_str();
  case_study->add_option("--map", args->map, "known (surveyed markers) or slam")
      ->capture_default_str();
  case_study->add_option("--frames", args->rules,
                         "one frame rule (default fixed:20 as the thesis)");
  case_study->add_option("--out", args->out,
                         "write the first run's OctoMap (objects.bt, objects.ot) here");
  case_study->callback(
      [action, args, study] { *action = [args, study] { return RunCaseStudy(*args, *study); }; });

  CLI::App* robustness = experiment->add_subcommand(
      "robustness",
      "slamo's EKF and MRPT's CRangeBearingKFSLAM2D on MRPT simul-landmarks logs whose true "
      "noise is 0.5x-10x what both are told, and on our simulator with a second robot.   "
      "e.g. slamo experiment robustness --runs 3");
  auto robustness_args = std::make_shared<RobustnessArgs>();
  robustness->add_option("--runs", robustness_args->runs, "runs (seeds) per row")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  robustness->add_option("--seed", args->seed, "first seed")->capture_default_str();
  robustness
      ->add_option("--out", robustness_args->out,
                   "folder for the generated logs (MRPT's, and the simulator's for slamo replay)")
      ->capture_default_str();
  robustness
      ->add_option("--robot", robustness_args->second_robot,
                   "the simulator rows' second robot (name or .yaml): told the thesis robot's "
                   "noise, then its own")
      ->capture_default_str();
  robustness
      ->add_option("--season", robustness_args->season,
                   "the simulator rows' field (name or .yaml): its markers are the landmarks")
      ->capture_default_str();
  robustness->callback([action, args, robustness_args] {
    *action = [args, robustness_args] { return RunRobustnessTable(*robustness_args, args->seed); };
  });

  CLI::App* peer = experiment->add_subcommand(
      "peer",
      "MRPT's CRangeBearingKFSLAM2D and slamo's EKF on the same simulated laps: ATE, NEES, time.   "
      "e.g. slamo experiment peer --runs 20");
  auto peer_runs = std::make_shared<int>(20);
  peer->add_option("--runs", *peer_runs, "Monte Carlo runs (seeds)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  peer->add_option("--seed", args->seed, "first seed")->capture_default_str();
  peer->callback([action, args, peer_runs] {
    *action = [args, peer_runs] {
      ExperimentArgs peer_args = *args;
      peer_args.runs = *peer_runs;
      return RunPeerTable(peer_args);
    };
  });
}

}  // namespace slamo::autonomy
