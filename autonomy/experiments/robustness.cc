#include "autonomy/experiments/robustness.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <map>
#include <optional>
#include <random>

#include "autonomy/experiments/peer_bench.h"
#include "field_configs/loader.h"
#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"
#include "mapping/replay_log.h"
#include "mapping/slam_o.h"
#include "platform/camera_geometry.h"
#include "platform/clock.h"
#include "platform/drive_base.h"
#include "platform/drive_script.h"
#include "platform/sim/sim_drive.h"
#include "platform/sim/sim_drive_script.h"
#include "platform/sim/sim_gyro.h"
#include "vision/camera_model.h"
#include "vision/measurement.h"

namespace slamo::autonomy {
namespace {

namespace fs = std::filesystem;
using platform::kPi;

// simul-landmarks' ini for one run.
void WriteIni(const std::string& path, const RobustnessOptions& o, const RobustnessCase& c,
              uint64_t seed) {
  std::ofstream out(path);
  out << "[Params]\nrandom_seed = " << seed << "\nnSteps = " << o.steps
      << "\ncircularPath = 0\nsquarePathLength = 50\nloadLandmarksFromFile =\n"
      << "odometryNoiseXY_std = " << o.odometry_xy_sigma_m * c.motion_factor
      << "\nodometryNoisePhi_std_deg = " << o.odometry_heading_sigma_deg * c.motion_factor
      << "\nminSensorDistance = 0\nmaxSensorDistance = " << o.max_range_m
      << "\nfieldOfView_deg = " << o.field_of_view_deg
      << "\nstdRange = " << o.range_sigma_m * c.sensor_factor
      << "\nstdYaw_deg = " << o.bearing_sigma_deg * c.sensor_factor
      << "\nstdPitch_deg = 0\noutFile = gen.rawlog\noutDir = OUT\nshow_in_3d = false\n\n"
      << "[RANDOMSET_1]\nnLandmarks = " << o.landmarks
      << "\nmin_x = -4\nmax_x = 12\nmin_y = -3\nmax_y = 12\nmin_z = 0\nmax_z = 0\n";
  if (!out) throw std::runtime_error(path + ": cannot write");
}

// The generated run as a peer scenario: step 0 holds what is seen before the first move, step
// k the k-th odometry increment and what is seen after it, with the truth after it (line k
// of the path file); both filters are told the options' noise, whatever the truth was.
PeerScenario ScenarioFrom(const std::string& dir, const PeerBenchOptions& told) {
  const mapping::ReplayLog log = mapping::ReadRawlog(dir + "/OUT/gen.rawlog");
  const std::vector<mapping::SimulLandmarksPose> path =
      mapping::ReadSimulLandmarksPath(dir + "/OUT/gen.rawlog_ground_truth_robot_path.txt");
  const Eigen::Matrix3d q = PeerStepCovariance(told);
  const Eigen::Matrix2d r = Eigen::Vector2d(told.sigma_range_m * told.sigma_range_m,
                                            told.sigma_bearing_rad * told.sigma_bearing_rad)
                                .asDiagonal();
  PeerScenario scenario;
  scenario.steps.emplace_back();
  for (const mapping::LogEvent& e : log.events) {
    if (e.is_odometry()) {
      PeerStep step;
      step.odometry = e.odometry();
      step.odometry.covariance = q;
      scenario.steps.push_back(step);
    } else {
      mapping::RangeBearing z = e.measurement();
      z.covariance = r;
      scenario.steps.back().measurements.push_back(z);
    }
  }
  if (path.size() < 2) throw std::runtime_error(dir + ": simul-landmarks wrote no robot path");
  if (scenario.steps.size() > path.size()) scenario.steps.resize(path.size());
  for (size_t k = 0; k < scenario.steps.size(); ++k) {
    scenario.steps[k].truth = Eigen::Vector3d(path[k].x_m, path[k].y_m, path[k].yaw_rad);
  }
  return scenario;
}

RobustnessScore Score(const PeerScenario& scenario, const PeerTrack& track,
                      const std::vector<mapping::LandmarkPoint>& landmarks, int measurements) {
  std::vector<Eigen::Vector2d> truth, estimate;
  double nees = 0.0;
  int nees_steps = 0;
  for (size_t k = 0; k < scenario.steps.size() && k < track.poses.size(); ++k) {
    truth.push_back(scenario.steps[k].truth.head<2>());
    const mapping::TimedPose& p = track.poses[k];
    estimate.emplace_back(p.x_m, p.y_m);
    if (k == 0 || track.covariances[k].determinant() <= 0.0) continue;
    nees += mapping::PoseNees(scenario.steps[k].truth, Eigen::Vector3d(p.x_m, p.y_m, p.theta_rad),
                              track.covariances[k]);
    ++nees_steps;
  }
  const mapping::AteResult ate = mapping::PairedTrajectoryError(truth, estimate, true);
  RobustnessScore s;
  s.ate_m = ate.rmse_m;
  s.landmark_rmse_m = mapping::LandmarkRmse(landmarks, track.landmarks, ate.alignment).rmse_m;
  s.mean_nees = nees_steps ? nees / nees_steps : 0.0;
  s.rejected_fraction = measurements ? static_cast<double>(track.rejected) / measurements : 0.0;
  s.ms_per_step = 1000.0 * track.filter_s / static_cast<double>(scenario.steps.size());
  return s;
}

void Accumulate(const RobustnessScore& s, int runs, RobustnessScore* sum) {
  sum->landmark_rmse_m += s.landmark_rmse_m / runs;
  sum->ate_m += s.ate_m / runs;
  sum->mean_nees += s.mean_nees / runs;
  sum->rejected_fraction += s.rejected_fraction / runs;
  sum->ms_per_step += s.ms_per_step / runs;
}

}  // namespace

std::vector<RobustnessCase> DefaultRobustnessCases() {
  std::vector<RobustnessCase> cases;
  for (double m : {0.5, 1.0, 2.0, 5.0, 10.0}) cases.push_back({m, 1.0});
  for (double s : {0.5, 2.0, 5.0, 10.0}) cases.push_back({1.0, s});
  return cases;
}

std::vector<RobustnessRow> RunRobustness(const RobustnessOptions& options,
                                         const std::vector<RobustnessCase>& cases, int runs,
                                         uint64_t seed, const std::string& work_dir,
                                         const std::function<void(int, int)>& progress) {
  if (runs < 1) throw std::invalid_argument("robustness: runs must be at least 1");
  if (std::system("command -v simul-landmarks > /dev/null 2>&1") != 0) {
    throw std::runtime_error(
        "simul-landmarks not found: it is MRPT's, in Debian's mrpt-apps "
        "(apt-get install mrpt-apps; ./slamo installs it)");
  }
  PeerBenchOptions told;
  told.sigma_step_xy_m = options.odometry_xy_sigma_m;
  told.sigma_step_heading_rad = options.odometry_heading_sigma_deg * kPi / 180.0;
  told.sigma_range_m = options.range_sigma_m;
  told.sigma_bearing_rad = options.bearing_sigma_deg * kPi / 180.0;
  told.max_range_m = options.max_range_m;
  told.adaptive = true;  // as `slamo replay` runs it
  told.first_estimates = true;
  std::vector<RobustnessRow> rows;
  int done = 0;
  const int total = static_cast<int>(cases.size()) * runs;
  for (size_t c = 0; c < cases.size(); ++c) {
    RobustnessRow row;
    row.noise = cases[c];
    row.slamo.rejected_fraction = row.mrpt.rejected_fraction = 0.0;
    for (int r = 0; r < runs; ++r) {
      const std::string dir = work_dir + "/case" + std::to_string(c) + "_run" + std::to_string(r);
      fs::create_directories(dir);
      WriteIni(dir + "/gen.ini", options, cases[c], seed + static_cast<uint64_t>(r));
      const std::string command =
          "cd '" + dir + "' && simul-landmarks gen.ini > simul-landmarks.log 2>&1";
      if (std::system(command.c_str()) != 0) {
        throw std::runtime_error("simul-landmarks failed in " + dir +
                                 " (see simul-landmarks.log there)");
      }
      const PeerScenario scenario = ScenarioFrom(dir, told);
      const std::vector<mapping::LandmarkPoint> landmarks =
          mapping::ReadSimulLandmarksMap(dir + "/OUT/gen.rawlog_ground_truth.txt");
      int measurements = 0;
      for (const PeerStep& s : scenario.steps)
        measurements += static_cast<int>(s.measurements.size());
      Accumulate(Score(scenario, RunSlamoFilter(scenario, told), landmarks, measurements), runs,
                 &row.slamo);
      PeerTrack mrpt = RunMrptFilter(scenario, told);
      RobustnessScore m = Score(scenario, mrpt, landmarks, measurements);
      m.rejected_fraction = 0.0;  // MRPT's filter does not report refusals
      Accumulate(m, runs, &row.mrpt);
      if (progress) progress(++done, total);
    }
    row.mrpt.rejected_fraction = -1.0;
    rows.push_back(row);
  }
  return rows;
}

std::vector<SimRobotCase> DefaultSimRobotCases(const std::string& second_robot) {
  if (second_robot == field::kDefaultRobot) return {{second_robot, second_robot}};
  return {{second_robot, field::kDefaultRobot}, {second_robot, second_robot}};
}

std::pair<double, double> ToldSensorSigmas(const field::CameraConfig& camera,
                                           double pixel_sigma_px) {
  // The depth sigma's RMS over the camera's range, every depth equally likely.
  const int n = 200;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double d = camera.min_range_m + (camera.max_range_m - camera.min_range_m) * (i + 0.5) / n;
    const double sigma = platform::DepthSigmaM(camera, d);
    sum += sigma * sigma;
  }
  return {std::sqrt(sum / n), pixel_sigma_px / camera.fx};
}

SimRobotLog SimulateRobotLog(const field::SeasonConfig& season, const field::RobotConfig& data,
                             const field::RobotConfig& told, const SimRobotOptions& options,
                             uint64_t seed) {
  if (!(options.step_s > 0.0) || !std::isfinite(options.step_s))
    throw std::invalid_argument("robustness: the filter step must be a positive time");
  const std::vector<platform::DriveStep> script = platform::ParseDriveScript(options.script);
  platform::SimDriveBase drive(data.drive, platform::SimDriveOptionsFor(data.drive), seed,
                               options.start);
  std::optional<platform::SimGyro> gyro;
  if (data.imu) gyro.emplace(seed, platform::SimGyroOptionsFor(*data.imu));
  platform::SimClock clock;
  const vision::CameraModel camera(data.camera);
  const Eigen::Isometry3d camera_from_robot =
      platform::RobotFromCamera(data.camera.mount).inverse();
  std::mt19937_64 rng(seed ^ 0x5EC0DD0Bull);
  std::normal_distribution<double> normal;

  SimRobotLog log;
  log.gyro = gyro.has_value();
  const mapping::MotionNoise motion = mapping::MotionNoiseFor(told.odometry_noise);
  const auto [range_sigma, bearing_sigma] = ToldSensorSigmas(told.camera, options.pixel_sigma_px);
  log.told.sigma_range_m = range_sigma;
  log.told.sigma_bearing_rad = bearing_sigma;
  // The told camera's farthest reading from the robot centre: its deepest, at the edge of its
  // view, plus the mount's offset.
  const field::CameraConfig& tc = told.camera;
  const double half_fov = std::atan(std::max(tc.cx, tc.width_px - tc.cx) / tc.fx);
  log.told.max_range_m =
      tc.max_range_m / std::cos(half_fov) + std::hypot(tc.mount.x_m, tc.mount.y_m);
  const Eigen::Matrix2d r =
      Eigen::Vector2d(range_sigma * range_sigma, bearing_sigma * bearing_sigma).asDiagonal();

  // Poses and markers in the frame of the start pose.
  const platform::Pose2D start = options.start;
  const auto relative = [&](double x, double y) {
    const double c = std::cos(start.theta_rad), s = std::sin(start.theta_rad);
    const double dx = x - start.x_m, dy = y - start.y_m;
    return Eigen::Vector2d(c * dx + s * dy, -s * dx + c * dy);
  };
  const auto relative_pose = [&](const platform::Pose2D& p) {
    const Eigen::Vector2d xy = relative(p.x_m, p.y_m);
    return Eigen::Vector3d(xy.x(), xy.y(), platform::WrapAngleRad(p.theta_rad - start.theta_rad));
  };
  for (size_t i = 0; i < season.landmarks.size(); ++i) {
    const Eigen::Vector2d l =
        relative(season.landmarks[i].position_m.x, season.landmarks[i].position_m.y);
    log.landmarks.push_back({static_cast<int>(i), l.x(), l.y()});
  }

  // What the camera sees from the true pose.
  const auto measure = [&](const platform::Pose2D& pose) {
    std::vector<mapping::RangeBearing> seen;
    const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
    for (size_t i = 0; i < season.landmarks.size(); ++i) {
      const field::Landmark& marker = season.landmarks[i];
      const double dx = marker.position_m.x - pose.x_m, dy = marker.position_m.y - pose.y_m;
      const Eigen::Vector3d in_robot(c * dx + s * dy, -s * dx + c * dy, marker.height_m);
      const Eigen::Vector3d in_camera = camera_from_robot * in_robot;
      if (in_camera.z() < data.camera.min_range_m || in_camera.z() > data.camera.max_range_m)
        continue;
      const Eigen::Vector2d px = camera.Project(in_camera);
      if (px.x() < 0.0 || px.x() >= data.camera.width_px || px.y() < 0.0 ||
          px.y() >= data.camera.height_px)
        continue;
      const double u = px.x() + options.pixel_sigma_px * normal(rng);
      const double v = px.y() + options.pixel_sigma_px * normal(rng);
      const double depth = in_camera.z() + camera.DepthSigmaM(in_camera.z()) * normal(rng);
      const Eigen::Vector2d rb = vision::RangeBearing(camera, u, v, depth);
      mapping::RangeBearing z;
      z.range_m = rb.x();
      z.bearing_rad = rb.y();
      // slamo is told each measurement's own covariance, as a match's vision gives it: the told
      // camera's depth sigma at the depth read (MRPT's 2D filter takes one sigma, the RMS).
      if (options.per_measurement_sigma) {
        const double sigma_depth = platform::DepthSigmaM(told.camera, depth);
        z.covariance = Eigen::Vector2d(sigma_depth * sigma_depth, r(1, 1)).asDiagonal();
      } else {
        z.covariance = r;
      }
      z.id = static_cast<int>(i);
      seen.push_back(z);
    }
    return seen;
  };

  PeerStep first;
  first.truth = relative_pose(drive.true_pose());
  first.measurements = measure(drive.true_pose());
  if (first.measurements.empty())
    throw std::invalid_argument("robustness: no marker in view of the data robot at the start");
  log.scenario.steps.push_back(first);
  platform::Pose2D last_odometry = drive.odometry_pose(), last_truth = drive.true_pose();
  double last_heading = gyro ? gyro->Read(drive.true_pose().theta_rad, 0.0) : 0.0;
  double next_s = options.step_s;
  const auto advance = [&](double dt_s) {
    drive.Step(dt_s);
    const double t = drive.time_s();
    if (t + 1e-9 < next_s) return;
    while (next_s <= t + 1e-9) next_s += options.step_s;
    PeerStep step;
    step.odometry = mapping::OdometryIncrement(last_odometry, drive.odometry_pose());
    last_odometry = drive.odometry_pose();
    if (gyro) {
      // Gyro-aided odometry, as the match runs it: the turn from the inertial sensor.
      const double heading = gyro->Read(drive.true_pose().theta_rad, t);
      step.odometry.dtheta_rad = platform::WrapAngleRad(heading - last_heading);
      last_heading = heading;
    }
    step.odometry.covariance = mapping::MotionModelCovariance(motion, step.odometry);
    step.truth = relative_pose(drive.true_pose());
    step.measurements = measure(drive.true_pose());
    log.distance_m +=
        std::hypot(drive.true_pose().x_m - last_truth.x_m, drive.true_pose().y_m - last_truth.y_m);
    last_truth = drive.true_pose();
    log.scenario.steps.push_back(step);
  };
  platform::RunDriveScript(script, platform::DriveControllerOptionsFor(data.drive), &drive, &clock,
                           advance);
  for (const mapping::LandmarkPoint& l : log.landmarks)
    log.scenario.landmarks.emplace_back(l.x_m, l.y_m);
  return log;
}

void WriteSimRobotLog(const std::string& dir, const SimRobotLog& log, double step_s) {
  fs::create_directories(dir);
  mapping::ReplayLog replay;
  std::vector<mapping::TimedPose> truth;
  for (size_t k = 0; k < log.scenario.steps.size(); ++k) {
    const PeerStep& step = log.scenario.steps[k];
    const double t = static_cast<double>(k) * step_s;
    mapping::OdometryStep u = step.odometry;
    // Step 0 has no motion: a zero step (the format wants positive sigmas) carries its
    // measurements, so that replay's trajectory has a pose for it too.
    if (k == 0) u = mapping::OdometryStep(0.0, 0.0, 0.0, Eigen::Matrix3d::Identity() * 1e-18);
    replay.events.push_back({t, u});
    for (const mapping::RangeBearing& z : step.measurements) replay.events.push_back({t, z});
    truth.push_back({t, step.truth.x(), step.truth.y(), step.truth.z()});
  }
  mapping::WriteTextLog(dir + "/run.log", replay);
  mapping::WriteTumTrajectory(dir + "/truth.tum", truth, "true pose");
  std::ofstream landmarks(dir + "/landmarks.csv");
  landmarks << "id,x_m,y_m\n";
  char line[128];
  for (const mapping::LandmarkPoint& l : log.landmarks) {
    std::snprintf(line, sizeof(line), "%d,%.9f,%.9f\n", l.id, l.x_m, l.y_m);
    landmarks << line;
  }
  if (!landmarks) throw std::runtime_error(dir + "/landmarks.csv: write failed");
}

std::vector<SimRobotRow> RunSimRobotRows(const SimRobotOptions& options,
                                         const std::vector<SimRobotCase>& cases, int runs,
                                         uint64_t seed,
                                         const std::function<void(int, int)>& progress,
                                         const std::string& out_dir) {
  if (runs < 1) throw std::invalid_argument("robustness: runs must be at least 1");
  const field::SeasonConfig season = field::LoadSeasonConfig(options.season);
  std::map<std::string, field::RobotConfig> robots;
  for (const SimRobotCase& c : cases) {
    for (const std::string& name : {c.data_robot, c.told_robot})
      if (!robots.count(name)) robots.emplace(name, field::LoadRobotConfig(name));
  }
  std::vector<SimRobotRow> rows;
  int done = 0;
  const int total = static_cast<int>(cases.size()) * runs;
  for (const SimRobotCase& c : cases) {
    SimRobotRow row;
    row.robots = c;
    row.slamo.rejected_fraction = 0.0;
    for (int r = 0; r < runs; ++r) {
      const SimRobotLog log =
          SimulateRobotLog(season, robots.at(c.data_robot), robots.at(c.told_robot), options,
                           seed + static_cast<uint64_t>(r));
      if (!out_dir.empty()) {
        WriteSimRobotLog(out_dir + "/sim_" + fs::path(c.data_robot).stem().string() + "_told_" +
                             fs::path(c.told_robot).stem().string() + "_run" + std::to_string(r),
                         log, options.step_s);
      }
      PeerBenchOptions told = log.told;
      told.adaptive = true;  // as `slamo replay` runs it
      told.first_estimates = true;
      int measurements = 0;
      for (const PeerStep& s : log.scenario.steps)
        measurements += static_cast<int>(s.measurements.size());
      Accumulate(
          Score(log.scenario, RunSlamoFilter(log.scenario, told), log.landmarks, measurements),
          runs, &row.slamo);
      RobustnessScore m =
          Score(log.scenario, RunMrptFilter(log.scenario, told), log.landmarks, measurements);
      m.rejected_fraction = 0.0;
      Accumulate(m, runs, &row.mrpt);
      const double steps = static_cast<double>(log.scenario.steps.size());
      row.steps += steps / runs;
      row.measurements_per_step += measurements / steps / runs;
      row.distance_m += log.distance_m / runs;
      row.gyro = log.gyro;
      row.range_sigma_m = told.sigma_range_m;
      row.bearing_sigma_rad = told.sigma_bearing_rad;
      row.max_range_m = told.max_range_m;
      if (progress) progress(++done, total);
    }
    row.mrpt.rejected_fraction = -1.0;
    rows.push_back(row);
  }
  return rows;
}

}  // namespace slamo::autonomy
