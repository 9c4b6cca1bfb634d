// `slamo replay`: EKF SLAM over a recorded run (a text log or an MRPT rawlog, see
// mapping/replay_log.h), writing the trajectory and the map, and scoring both against ground
// truth when it is given.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "autonomy/cli/commands.h"
#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"
#include "mapping/replay_log.h"
#include "platform/drive_base.h"

namespace slamo::autonomy {
namespace {

// The filter of another robot: what `--filter-config FILE` (YAML, the same names with
// underscores) and the options below set. Unset values keep the log's own (sensor sigmas,
// odometry covariance) or the filter's defaults.
struct FilterArgs {
  std::optional<double> motion_per_m;       // position sigma per metre travelled
  std::optional<double> motion_per_rad;     // heading sigma per radian turned
  std::optional<double> range_sigma_m;      // every measurement's range sigma
  std::optional<double> bearing_sigma_deg;  // every measurement's bearing sigma
  std::optional<double> max_range_m;
  std::optional<double> fov_deg;                   // measurements beyond +-fov/2 are dropped
  std::optional<double> gate_probability;          // of the association gate, 2 dof
  std::optional<bool> known_ids;                   // false: associate every measurement by position
  std::optional<std::string> odometry_covariance;  // log | model
  std::optional<bool> adaptive;
  std::optional<bool> first_estimates;  // Jacobians at the first estimates (FEJ-EKF)
};

struct ReplayArgs {
  std::string log;
  std::string truth;
  std::string landmarks_truth;
  std::string out;
  std::string filter_config;
  double max_dt_s = 0.02;
  double start_sigma_m = 1e-3;
  double start_sigma_rad = 1e-3;
  FilterArgs filter;
};

// A bad filter value: the message names the option (or the file and key).
struct FilterError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

void CheckRange(const std::string& name, const std::optional<double>& v, double lo, double hi,
                bool lo_open = true) {
  if (!v) return;
  if (!std::isfinite(*v) || (lo_open ? *v <= lo : *v < lo) || *v > hi) {
    std::ostringstream out;
    out << name << ": expected a number in " << (lo_open ? "(" : "[") << lo << ", " << hi
        << "], got " << *v;
    throw FilterError(out.str());
  }
}

// Reads --filter-config into `filter`, keeping what the command line set.
void ReadFilterConfig(const std::string& path, FilterArgs* filter) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw FilterError(path + ": " + e.what());
  }
  if (!root.IsMap()) throw FilterError(path + ": expected a map of filter options");
  for (const auto& item : root) {
    const std::string key = item.first.as<std::string>();
    const YAML::Node& v = item.second;
    const std::string where = path + ":" + std::to_string(v.Mark().line + 1) + ": " + key;
    try {
      const auto number = [&](std::optional<double>* out) {
        if (!*out) *out = v.as<double>();
      };
      if (key == "motion_per_m")
        number(&filter->motion_per_m);
      else if (key == "motion_per_rad")
        number(&filter->motion_per_rad);
      else if (key == "range_sigma_m")
        number(&filter->range_sigma_m);
      else if (key == "bearing_sigma_deg")
        number(&filter->bearing_sigma_deg);
      else if (key == "max_range_m")
        number(&filter->max_range_m);
      else if (key == "fov_deg")
        number(&filter->fov_deg);
      else if (key == "gate_probability")
        number(&filter->gate_probability);
      else if (key == "known_ids") {
        if (!filter->known_ids) filter->known_ids = v.as<bool>();
      } else if (key == "odometry_covariance") {
        if (!filter->odometry_covariance) filter->odometry_covariance = v.as<std::string>();
      } else if (key == "adaptive") {
        if (!filter->adaptive) filter->adaptive = v.as<bool>();
      } else if (key == "first_estimates") {
        if (!filter->first_estimates) filter->first_estimates = v.as<bool>();
      } else {
        throw FilterError(where +
                          ": unknown key; expected motion_per_m, motion_per_rad, "
                          "range_sigma_m, bearing_sigma_deg, max_range_m, fov_deg, "
                          "gate_probability, known_ids, odometry_covariance, adaptive or "
                          "first_estimates");
      }
    } catch (const YAML::Exception&) {
      const bool boolean = key == "known_ids" || key == "adaptive" || key == "first_estimates";
      throw FilterError(where + ": expected " +
                        (boolean                        ? "true or false"
                         : key == "odometry_covariance" ? "log or model"
                                                        : "a number"));
    }
  }
}

// Every value in its range; the option names in the messages are the command line's.
void CheckFilter(const FilterArgs& f) {
  CheckRange("--motion-per-m", f.motion_per_m, 0.0, 10.0);
  CheckRange("--motion-per-rad", f.motion_per_rad, 0.0, 10.0);
  CheckRange("--range-sigma", f.range_sigma_m, 0.0, 100.0);
  CheckRange("--bearing-sigma-deg", f.bearing_sigma_deg, 0.0, 180.0);
  CheckRange("--max-range", f.max_range_m, 0.0, 1e6);
  CheckRange("--fov-deg", f.fov_deg, 0.0, 360.0);
  CheckRange("--gate-prob", f.gate_probability, 0.5, 0.999999);
  if (f.gate_probability && *f.gate_probability >= 1.0)
    throw FilterError("--gate-prob: expected a probability below 1");
  if (f.odometry_covariance && *f.odometry_covariance != "log" &&
      *f.odometry_covariance != "model") {
    throw FilterError("--odometry-covariance: expected log or model, got " +
                      *f.odometry_covariance);
  }
}

// The filter's options from the arguments (defaults where unset).
mapping::EkfOptions FilterOptions(const FilterArgs& f) {
  mapping::EkfOptions options;
  options.adaptive.enabled = f.adaptive.value_or(true);
  options.first_estimates = f.first_estimates.value_or(true);
  if (f.motion_per_m) {
    options.motion.sigma_per_m = *f.motion_per_m;
    options.motion.lateral_sigma_per_m = *f.motion_per_m;
  }
  if (f.motion_per_rad) {
    options.motion.heading_sigma_per_rad = *f.motion_per_rad;
    options.motion.forward_sigma_per_rad = 0.0;
    options.motion.lateral_sigma_per_rad = 0.0;
  }
  if (f.max_range_m) options.max_range_m = *f.max_range_m;
  if (f.gate_probability) {
    // Chi-square with 2 dof: P(d2 < g) = 1 - exp(-g / 2).
    options.association.gate_chi2 = -2.0 * std::log(1.0 - *f.gate_probability);
    options.association.new_chi2 =
        std::max(options.association.new_chi2, options.association.gate_chi2 * 25.0 / 9.21);
  }
  return options;
}

// The log as the arguments ask for it: measurement sigmas set, ids dropped, the field of view
// applied, the odometry's own covariance kept or dropped.
void ApplyFilterArgs(const FilterArgs& f, mapping::ReplayLog* log) {
  const double half_fov = f.fov_deg ? *f.fov_deg / 2.0 * platform::kPi / 180.0 : 10.0;
  std::vector<mapping::LogEvent> kept;
  for (mapping::LogEvent& e : log->events) {
    if (e.is_odometry()) {
      if (f.odometry_covariance.value_or("log") == "model")
        std::get<mapping::OdometryStep>(e.data).covariance.reset();
    } else {
      auto& z = std::get<mapping::RangeBearing>(e.data);
      if (std::abs(z.bearing_rad) > half_fov) continue;
      if (f.range_sigma_m) z.covariance(0, 0) = *f.range_sigma_m * *f.range_sigma_m;
      if (f.bearing_sigma_deg) {
        const double sb = *f.bearing_sigma_deg * platform::kPi / 180.0;
        z.covariance(1, 1) = sb * sb;
      }
      if (f.range_sigma_m || f.bearing_sigma_deg) z.covariance(0, 1) = z.covariance(1, 0) = 0.0;
      if (!f.known_ids.value_or(true)) z.id = -1;
    }
    kept.push_back(std::move(e));
  }
  log->events = std::move(kept);
}

void WriteLandmarks(const std::string& path, const mapping::EkfSlam& ekf) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out << "id,x_m,y_m,sxx,sxy,syy\n";
  char line[256];
  for (int i = 0; i < ekf.landmark_count(); ++i) {
    const Eigen::Vector2d p = ekf.landmark(i);
    const Eigen::Matrix2d c = ekf.landmark_covariance(i);
    std::snprintf(line, sizeof(line), "%d,%.6f,%.6f,%.9g,%.9g,%.9g\n", ekf.landmark_id(i), p.x(),
                  p.y(), c(0, 0), c(0, 1), c(1, 1));
    out << line;
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

int Run(const ReplayArgs& cli) {
  ReplayArgs args = cli;
  try {
    if (!args.filter_config.empty()) ReadFilterConfig(args.filter_config, &args.filter);
    CheckFilter(args.filter);
  } catch (const FilterError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  mapping::ReplayLog log = mapping::ReadReplayLog(args.log);
  ApplyFilterArgs(args.filter, &log);

  // Start where the log says (a `start` line), else at the origin; the small covariance
  // anchors the map frame to the start pose.
  const Eigen::Vector3d start = log.start_pose.value_or(Eigen::Vector3d::Zero());
  const Eigen::Matrix3d start_covariance =
      Eigen::Vector3d(args.start_sigma_m * args.start_sigma_m,
                      args.start_sigma_m * args.start_sigma_m,
                      args.start_sigma_rad * args.start_sigma_rad)
          .asDiagonal();
  // The sensor's own range when the log gives it and the command line does not.
  mapping::EkfOptions options = FilterOptions(args.filter);
  if (!args.filter.max_range_m && log.sensor_max_range_m)
    options.max_range_m = *log.sensor_max_range_m;
  mapping::EkfSlam ekf(start, start_covariance, options);

  // Predict on odometry, update on measurements; one pose per odometry step.
  std::vector<mapping::TimedPose> trajectory;
  // Each step's pose after the measurements that follow it (the filter's best estimate of it),
  // at the step's time.
  int measurements = 0, known = 0, known_rejected = 0;
  std::optional<double> step_t;
  const auto close_step = [&] {
    if (!step_t) return;
    const Eigen::Vector3d pose = ekf.pose();
    trajectory.push_back({*step_t, pose.x(), pose.y(), pose.z()});
  };
  for (const mapping::LogEvent& e : log.events) {
    if (e.is_odometry()) {
      close_step();
      ekf.Predict(e.odometry());
      step_t = e.t_s;
    } else {
      ++measurements;
      const mapping::UpdateOutcome o = ekf.Update(e.measurement());
      if (e.measurement().id >= 0) {
        ++known;
        known_rejected += o == mapping::UpdateOutcome::kRejected;
      }
    }
  }
  close_step();
  const Eigen::Vector3d pose = ekf.pose();
  const Eigen::Matrix3d pose_covariance = ekf.pose_covariance();
  const mapping::FilterCounters& c = ekf.counters();
  std::printf(
      "%s: %zu odometry steps, %d measurements (%d updated, %d added, %d ambiguous, %d "
      "rejected; known ids: %d, %d rejected, %.1f %%)\n",
      args.log.c_str(), trajectory.size(), measurements, c.updated, c.added, c.ambiguous,
      c.rejected, known, known_rejected, known ? 100.0 * known_rejected / known : 0.0);
  std::printf(
      "filter: %s; re-acquired %d, adaptive-noise episodes %d (process) and %d (sensor), "
      "noise scale now %.3g (process) and %.3g (sensor), mean NIS %.2f (2 expected)\n",
      ekf.options().adaptive.enabled ? "adaptive" : "fixed noise", c.reacquired,
      c.adaptive_episodes, c.sensor_episodes, ekf.process_noise_scale(),
      ekf.measurement_noise_scale(), c.MeanNis());
  std::printf(
      "final pose (%.3f m, %.3f m, %.1f deg), sigma (%.3f m, %.3f m, %.2f deg); %d "
      "landmarks\n",
      pose.x(), pose.y(), pose.z() * 180.0 / M_PI, std::sqrt(pose_covariance(0, 0)),
      std::sqrt(pose_covariance(1, 1)), std::sqrt(pose_covariance(2, 2)) * 180.0 / M_PI,
      ekf.landmark_count());

  if (!args.out.empty()) {
    std::filesystem::create_directories(args.out);
    const std::string trajectory_path = args.out + "/trajectory.tum";
    const std::string landmarks_path = args.out + "/landmarks.csv";
    mapping::WriteTumTrajectory(trajectory_path, trajectory);
    WriteLandmarks(landmarks_path, ekf);
    std::printf("wrote %s and %s\n", trajectory_path.c_str(), landmarks_path.c_str());
  }

  // Against the truth: ATE after rigid alignment (and without), then the map in the frame the
  // trajectory alignment gives (no alignment when only the landmark truth is known).
  mapping::Rigid2d alignment;
  if (!args.truth.empty()) {
    mapping::AteResult ate, raw;
    if (mapping::DetectTruthFormat(args.truth) == mapping::TruthFormat::kSimulLandmarksPath) {
      // simul-landmarks' path has no times. Its row k is the pose where the k-th observation
      // was taken, after k odometry steps: the replay's pose k - 1 (the last step, after the
      // last observation, has no row).
      const std::vector<mapping::SimulLandmarksPose> path =
          mapping::ReadSimulLandmarksPath(args.truth);
      if (path.size() != trajectory.size()) {
        std::cerr << "error: " << args.truth << ": " << path.size()
                  << " poses, but simul-landmarks writes one per odometry step of the log: "
                  << trajectory.size() << "\n";
        return 2;
      }
      std::vector<Eigen::Vector2d> truth, estimate;
      for (size_t k = 1; k < path.size(); ++k) {
        truth.emplace_back(path[k].x_m, path[k].y_m);
        estimate.emplace_back(trajectory[k - 1].x_m, trajectory[k - 1].y_m);
      }
      ate = mapping::PairedTrajectoryError(truth, estimate, /*align=*/true);
      raw = mapping::PairedTrajectoryError(truth, estimate, /*align=*/false);
    } else {
      const std::vector<mapping::TimedPose> truth = mapping::ReadTumTrajectory(args.truth);
      ate = mapping::AbsoluteTrajectoryError(truth, trajectory, args.max_dt_s, /*align=*/true);
      raw = mapping::AbsoluteTrajectoryError(truth, trajectory, args.max_dt_s, /*align=*/false);
    }
    alignment = ate.alignment;
    std::printf(
        "ATE %.4f m RMSE (mean %.4f, median %.4f, max %.4f) over %d poses, aligned by "
        "%.2f deg, (%.3f, %.3f) m; unaligned RMSE %.4f m\n",
        ate.rmse_m, ate.mean_m, ate.median_m, ate.max_m, ate.pairs,
        alignment.theta_rad * 180.0 / M_PI, alignment.translation_m.x(),
        alignment.translation_m.y(), raw.rmse_m);
  }
  if (!args.landmarks_truth.empty()) {
    std::vector<mapping::LandmarkPoint> estimate;
    for (int i = 0; i < ekf.landmark_count(); ++i) {
      estimate.push_back({ekf.landmark_id(i), ekf.landmark(i).x(), ekf.landmark(i).y()});
    }
    const std::vector<mapping::LandmarkPoint> truth =
        mapping::DetectTruthFormat(args.landmarks_truth) == mapping::TruthFormat::kSimulLandmarksMap
            ? mapping::ReadSimulLandmarksMap(args.landmarks_truth)
            : mapping::ReadLandmarkCsv(args.landmarks_truth);
    const mapping::LandmarkError error = mapping::LandmarkRmse(truth, estimate, alignment);
    std::printf("landmark RMSE %.4f m over %d landmarks (%d in the truth not mapped)%s\n",
                error.rmse_m, error.pairs, error.missing,
                args.truth.empty() ? ", unaligned" : ", after the trajectory alignment");
  }
  return 0;
}

}  // namespace

void RegisterReplayCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<ReplayArgs>();
  CLI::App* replay = app.add_subcommand(
      "replay",
      "EKF SLAM over a recorded run (text log or MRPT rawlog); trajectory, map and errors.   "
      "e.g. slamo replay --log run.log --truth truth.tum --out DIR");
  replay->add_option("--log", args->log, "recorded run: text log (mapping/README.md) or .rawlog")
      ->required();
  replay->add_option(
      "--truth", args->truth,
      "true trajectory, TUM format, or simul-landmarks' X_ground_truth_robot_path.txt "
      "(paired step by step): prints the ATE");
  replay->add_option("--landmarks-truth", args->landmarks_truth,
                     "true landmarks, CSV id,x_m,y_m, or simul-landmarks' X_ground_truth.txt: "
                     "prints the landmark RMSE");
  replay->add_option("--out", args->out, "directory for trajectory.tum and landmarks.csv");
  replay->add_option("--max-dt", args->max_dt_s, "ATE: largest time difference of a pose pair, s")
      ->capture_default_str();
  replay->add_option("--start-sigma-m", args->start_sigma_m, "start position sigma, m")
      ->capture_default_str();
  replay->add_option("--start-sigma-rad", args->start_sigma_rad, "start heading sigma, rad")
      ->capture_default_str();
  // The filter of another robot (bad values exit 2 naming the option).
  FilterArgs* f = &args->filter;
  replay->add_option("--filter-config", args->filter_config,
                     "YAML file of the options below (motion_per_m: 0.1, known_ids: false, ...); "
                     "the command line wins");
  replay->add_option("--motion-per-m", f->motion_per_m,
                     "odometry model: position sigma per metre travelled (default: the log's "
                     "own odometry covariance where it has one, else the thesis robot's 0.175)");
  replay->add_option("--motion-per-rad", f->motion_per_rad,
                     "odometry model: heading sigma per radian turned (thesis robot: 0.025)");
  replay->add_option("--range-sigma", f->range_sigma_m,
                     "every measurement's range sigma, m (default: the log's)");
  replay->add_option("--bearing-sigma-deg", f->bearing_sigma_deg,
                     "every measurement's bearing sigma, degrees (default: the log's)");
  replay->add_option("--max-range", f->max_range_m,
                     "measurements beyond this are ignored, m (default: the log's sensor range "
                     "where it gives one, else 4.5)");
  replay->add_option("--fov-deg", f->fov_deg,
                     "field of view: measurements beyond +-fov/2 are dropped (default: all)");
  replay->add_option("--gate-prob", f->gate_probability,
                     "association gate probability, 2 dof (default 0.99: chi2 9.21)");
  replay
      ->add_option("--known-ids", f->known_ids,
                   "true: measured ids name the landmark; false: associate by position")
      ->default_str("true");
  replay
      ->add_option("--odometry-covariance", f->odometry_covariance,
                   "log: each step's own covariance where the log has one (an MRPT action's "
                   "pose PDF, MRPT's own EKF does the same); model: the motion model's")
      ->default_str("log");
  replay
      ->add_option("--adaptive", f->adaptive,
                   "true: the filter raises its process noise when innovations stay larger "
                   "than predicted and widens a lost pose; false: fixed noise")
      ->default_str("true");
  replay
      ->add_option("--first-estimates", f->first_estimates,
                   "true: measurement Jacobians at the step's predicted pose and each "
                   "landmark's first estimate (FEJ-EKF, consistent); false: at the latest "
                   "estimate (the textbook EKF)")
      ->default_str("true");
  replay->footer(
      "Examples:\n"
      "  slamo replay --log run.rawlog --truth t.tum --landmarks-truth l.csv\n"
      "  slamo replay --log OUT/gen.rawlog --truth OUT/gen.rawlog_ground_truth_robot_path.txt \\\n"
      "               --landmarks-truth OUT/gen.rawlog_ground_truth.txt   (MRPT's "
      "simul-landmarks)\n"
      "  slamo replay --log run.rawlog --motion-per-m 0.3 --range-sigma 0.05 --known-ids false\n"
      "  slamo replay --log run.log --filter-config robot.yaml --out DIR\n"
      "  robot.yaml:  motion_per_m: 0.3\n"
      "               bearing_sigma_deg: 1.0\n"
      "               gate_probability: 0.999\n");
  replay->callback([args, action] {
    *action = [args] {
      try {
        return Run(*args);
      } catch (const std::exception& e) {  // bad input files: a message and status 2
        std::cerr << "error: " << e.what() << "\n";
        return 2;
      }
    };
  });
}

}  // namespace slamo::autonomy
