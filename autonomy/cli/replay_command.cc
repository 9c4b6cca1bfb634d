// `slamo replay`: EKF SLAM over a recorded run (a text log or an MRPT rawlog, see
// mapping/replay_log.h), writing the trajectory and the map, and scoring both against ground
// truth when it is given.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "autonomy/cli/commands.h"
#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"
#include "mapping/replay_log.h"

namespace slamo::autonomy {
namespace {

struct ReplayArgs {
  std::string log;
  std::string truth;
  std::string landmarks_truth;
  std::string out;
  double max_dt_s = 0.02;
  double start_sigma_m = 1e-3;
  double start_sigma_rad = 1e-3;
};

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

int Run(const ReplayArgs& args) {
  const mapping::ReplayLog log = mapping::ReadReplayLog(args.log);

  // Start where the log says (a `start` line), else at the origin; the small covariance
  // anchors the map frame to the start pose.
  const Eigen::Vector3d start = log.start_pose.value_or(Eigen::Vector3d::Zero());
  const Eigen::Matrix3d start_covariance =
      Eigen::Vector3d(args.start_sigma_m * args.start_sigma_m,
                      args.start_sigma_m * args.start_sigma_m,
                      args.start_sigma_rad * args.start_sigma_rad)
          .asDiagonal();
  mapping::EkfSlam ekf(start, start_covariance);

  // Predict on odometry, update on measurements; one pose per odometry step.
  std::vector<mapping::TimedPose> trajectory;
  int outcomes[4] = {0, 0, 0, 0};
  int measurements = 0;
  for (const mapping::LogEvent& e : log.events) {
    if (e.is_odometry()) {
      ekf.Predict(e.odometry());
      const Eigen::Vector3d pose = ekf.pose();
      trajectory.push_back({e.t_s, pose.x(), pose.y(), pose.z()});
    } else {
      ++measurements;
      ++outcomes[static_cast<int>(ekf.Update(e.measurement()))];
    }
  }
  const Eigen::Vector3d pose = ekf.pose();
  const Eigen::Matrix3d pose_covariance = ekf.pose_covariance();
  std::printf(
      "%s: %zu odometry steps, %d measurements (%d updated, %d added, %d ambiguous, %d "
      "rejected)\n",
      args.log.c_str(), trajectory.size(), measurements, outcomes[0], outcomes[1], outcomes[2],
      outcomes[3]);
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
    const std::vector<mapping::TimedPose> truth = mapping::ReadTumTrajectory(args.truth);
    const mapping::AteResult ate =
        mapping::AbsoluteTrajectoryError(truth, trajectory, args.max_dt_s, /*align=*/true);
    const mapping::AteResult raw =
        mapping::AbsoluteTrajectoryError(truth, trajectory, args.max_dt_s, /*align=*/false);
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
    const mapping::LandmarkError error =
        mapping::LandmarkRmse(mapping::ReadLandmarkCsv(args.landmarks_truth), estimate, alignment);
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
  replay->add_option("--truth", args->truth, "true trajectory, TUM format: prints the ATE");
  replay->add_option("--landmarks-truth", args->landmarks_truth,
                     "true landmarks, CSV id,x_m,y_m: prints the landmark RMSE");
  replay->add_option("--out", args->out, "directory for trajectory.tum and landmarks.csv");
  replay->add_option("--max-dt", args->max_dt_s, "ATE: largest time difference of a pose pair, s")
      ->capture_default_str();
  replay->add_option("--start-sigma-m", args->start_sigma_m, "start position sigma, m")
      ->capture_default_str();
  replay->add_option("--start-sigma-rad", args->start_sigma_rad, "start heading sigma, rad")
      ->capture_default_str();
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
