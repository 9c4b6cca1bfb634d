// The robustness experiment's rows from our own simulator: a log driven and seen with the data
// robot's own drive and camera, told another file's noise, and slamo's map and path on it.
#include "autonomy/experiments/robustness.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "field_configs/loader.h"
#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"
#include "mapping/replay_log.h"
#include "platform/camera_geometry.h"

namespace slamo::autonomy {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// What a log's measurements look like against its truth.
struct Seen {
  int measurements = 0;
  double max_camera_angle_rad = 0.0;  // horizontal angle of a seen marker off the camera's axis
  double max_range_m = 0.0;
  double range_error_rms_m = 0.0;
  double bearing_error_rms_rad = 0.0;
  double max_step_m = 0.0;  // the longest true move in one step
};

Seen Inspect(const SimRobotLog& log, const field::CameraMount& mount) {
  Seen out;
  double range_sq = 0.0, bearing_sq = 0.0;
  for (size_t k = 0; k < log.scenario.steps.size(); ++k) {
    const PeerStep& step = log.scenario.steps[k];
    if (k > 0) {
      out.max_step_m =
          std::max(out.max_step_m,
                   (step.truth.head<2>() - log.scenario.steps[k - 1].truth.head<2>()).norm());
    }
    for (const mapping::RangeBearing& z : step.measurements) {
      const Eigen::Vector2d landmark = log.scenario.landmarks.at(z.id);
      const Eigen::Vector2d truth = mapping::EkfSlam::Observe(step.truth, landmark);
      // The marker seen from the camera on its mount.
      const Eigen::Vector2d d = landmark - step.truth.head<2>();
      const double c = std::cos(step.truth.z()), s = std::sin(step.truth.z());
      const Eigen::Vector2d in_robot(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
      const double angle = std::atan2(in_robot.y() - mount.y_m, in_robot.x() - mount.x_m);
      out.max_camera_angle_rad = std::max(out.max_camera_angle_rad, std::abs(angle));
      out.max_range_m = std::max(out.max_range_m, z.range_m);
      range_sq += std::pow(z.range_m - truth.x(), 2);
      bearing_sq += std::pow(std::remainder(z.bearing_rad - truth.y(), 2.0 * M_PI), 2);
      ++out.measurements;
    }
  }
  out.range_error_rms_m = std::sqrt(range_sq / out.measurements);
  out.bearing_error_rms_rad = std::sqrt(bearing_sq / out.measurements);
  return out;
}

TEST(RobustnessSimTest, TheSecondRobotsLogIsDrivenAndSeenWithItsOwnDriveAndCamera) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig v5 = field::LoadRobotConfig("v5_drivetrain");
  const field::RobotConfig thesis = field::LoadRobotConfig("thesis_robot");
  const SimRobotOptions options;
  const SimRobotLog v5_log = SimulateRobotLog(season, v5, v5, options, 1);
  const SimRobotLog thesis_log = SimulateRobotLog(season, thesis, thesis, options, 1);
  ASSERT_EQ(v5_log.landmarks.size(), season.landmarks.size());
  ASSERT_FALSE(v5_log.scenario.steps.front().measurements.empty());

  // The drive: the V5 robot cruises at 0.5 m/s against the thesis robot's 0.067, so the same
  // two laps take it a fraction of the steps, and it moves further in one step than the thesis
  // robot's top speed allows. Its wheels slip less (3 % against 16.5 % of the encoders'
  // distance), so it truly covers more of the scripted 19.2 m. Its heading comes from its
  // inertial sensor; the thesis robot has none.
  EXPECT_LT(v5_log.scenario.steps.size() * 4, thesis_log.scenario.steps.size());
  const Seen v5_seen = Inspect(v5_log, v5.camera.mount);
  const Seen thesis_seen = Inspect(thesis_log, thesis.camera.mount);
  EXPECT_GT(v5_seen.max_step_m, thesis.drive.max_speed_mps * options.step_s);
  EXPECT_LE(v5_seen.max_step_m, v5.drive.max_speed_mps * options.step_s);
  EXPECT_GT(v5_log.distance_m, 17.5);
  EXPECT_LT(v5_log.distance_m, 19.2);
  EXPECT_LT(thesis_log.distance_m, v5_log.distance_m - 1.0);
  EXPECT_TRUE(v5_log.gyro);
  EXPECT_FALSE(thesis_log.gyro);

  // The camera: the D435's 87 deg view sees markers further off its axis than the Kinect's
  // 70 deg one could, never beyond its own half-angle; its depth noise (0.005 d^2) is an order
  // of magnitude above the Kinect's, its bearing noise (1 px) about the same.
  const double v5_half = std::atan(v5.camera.cx / v5.camera.fx);
  const double thesis_half = std::atan(thesis.camera.cx / thesis.camera.fx);
  EXPECT_GT(v5_seen.max_camera_angle_rad, thesis_half);
  EXPECT_LT(v5_seen.max_camera_angle_rad, v5_half + 2.0 * kDeg);  // the mount's pitch
  EXPECT_LT(thesis_seen.max_camera_angle_rad, thesis_half + 2.0 * kDeg);
  EXPECT_GT(v5_seen.range_error_rms_m, 5.0 * thesis_seen.range_error_rms_m);
  EXPECT_LT(v5_seen.range_error_rms_m, 0.08);  // the table's sigma at 4 m
  EXPECT_LT(v5_seen.bearing_error_rms_rad, 0.5 * kDeg);
  EXPECT_LT(thesis_seen.bearing_error_rms_rad, 0.5 * kDeg);

  // Seeded: the same seed gives the same log.
  const SimRobotLog again = SimulateRobotLog(season, v5, v5, options, 1);
  ASSERT_EQ(again.scenario.steps.size(), v5_log.scenario.steps.size());
  EXPECT_EQ(again.scenario.steps[40].odometry.dx_m, v5_log.scenario.steps[40].odometry.dx_m);
}

TEST(RobustnessSimTest, BothFiltersAreToldTheToldRobotsNoise) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig v5 = field::LoadRobotConfig("v5_drivetrain");
  const field::RobotConfig thesis = field::LoadRobotConfig("thesis_robot");
  SimRobotOptions one_sigma;
  one_sigma.per_measurement_sigma = false;
  const SimRobotLog log = SimulateRobotLog(season, v5, thesis, one_sigma, 2);
  const mapping::MotionNoise motion = mapping::MotionNoiseFor(thesis.odometry_noise);
  const auto [range_sigma, bearing_sigma] = ToldSensorSigmas(thesis.camera, 1.0);
  // The Kinect's depth sigma, 1.0-3.6 mm over 0.5-4.5 m; one pixel over 365.456 px.
  EXPECT_GT(range_sigma, 0.0015);
  EXPECT_LT(range_sigma, 0.003);
  EXPECT_NEAR(bearing_sigma, 1.0 / 365.456, 1e-9);
  EXPECT_EQ(log.told.sigma_range_m, range_sigma);
  EXPECT_EQ(log.told.sigma_bearing_rad, bearing_sigma);
  for (size_t k = 1; k < log.scenario.steps.size(); ++k) {
    const PeerStep& step = log.scenario.steps[k];
    ASSERT_TRUE(step.odometry.covariance.has_value());
    EXPECT_TRUE(
        step.odometry.covariance->isApprox(mapping::MotionModelCovariance(motion, step.odometry)));
    for (const mapping::RangeBearing& z : step.measurements) {
      EXPECT_EQ(z.covariance(0, 0), range_sigma * range_sigma);
      EXPECT_EQ(z.covariance(1, 1), bearing_sigma * bearing_sigma);
    }
  }
}

TEST(RobustnessSimTest, EachMeasurementCarriesTheToldCamerasDepthSigmaAtItsDepth) {
  // As a match's vision gives them: the V5 file's D435 depth sigma (0.005 d^2) grows with the
  // depth read, so far markers carry a wider range variance than near ones, and the RMS sigma
  // MRPT's filter is told lies between them. The bearing's is one pixel over the focal length.
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig v5 = field::LoadRobotConfig("v5_drivetrain");
  const SimRobotLog log = SimulateRobotLog(season, v5, v5, SimRobotOptions{}, 2);
  const auto [range_sigma, bearing_sigma] = ToldSensorSigmas(v5.camera, 1.0);
  double nearest = 1e9, farthest = 0.0, near_variance = 0.0, far_variance = 0.0;
  int n = 0;
  for (const PeerStep& step : log.scenario.steps) {
    for (const mapping::RangeBearing& z : step.measurements) {
      ++n;
      EXPECT_EQ(z.covariance(1, 1), bearing_sigma * bearing_sigma);
      EXPECT_EQ(z.covariance(0, 1), 0.0);
      if (z.range_m < nearest) nearest = z.range_m, near_variance = z.covariance(0, 0);
      if (z.range_m > farthest) farthest = z.range_m, far_variance = z.covariance(0, 0);
    }
  }
  ASSERT_GT(n, 100);
  ASSERT_GT(farthest, nearest + 1.0);
  EXPECT_LT(near_variance, range_sigma * range_sigma);
  EXPECT_GT(far_variance, range_sigma * range_sigma);
  // At the farthest marker the sigma is the table's at about its depth: within its 0.3-4 m.
  EXPECT_GT(std::sqrt(far_variance), platform::DepthSigmaM(v5.camera, 0.5 * farthest));
  EXPECT_LE(std::sqrt(far_variance), platform::DepthSigmaM(v5.camera, v5.camera.max_range_m));
}

TEST(RobustnessSimTest, TheWrittenLogReplaysTheSameSteps) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig v5 = field::LoadRobotConfig("v5_drivetrain");
  const SimRobotOptions options;
  const SimRobotLog log = SimulateRobotLog(season, v5, v5, options, 3);
  const std::string dir =
      (std::filesystem::temp_directory_path() / "slamo_robustness_sim_log").string();
  std::filesystem::remove_all(dir);
  WriteSimRobotLog(dir, log, options.step_s);
  const mapping::ReplayLog replay = mapping::ReadTextLog(dir + "/run.log");
  const std::vector<mapping::TimedPose> truth = mapping::ReadTumTrajectory(dir + "/truth.tum");
  const std::vector<mapping::LandmarkPoint> landmarks =
      mapping::ReadLandmarkCsv(dir + "/landmarks.csv");
  ASSERT_EQ(truth.size(), log.scenario.steps.size());
  ASSERT_EQ(landmarks.size(), log.landmarks.size());
  EXPECT_NEAR(landmarks[2].x_m, log.landmarks[2].x_m, 1e-9);
  // One odometry event per step (a zero one first), then that step's measurements.
  size_t step = 0, measurement = 0;
  bool first = true;
  for (const mapping::LogEvent& e : replay.events) {
    if (e.is_odometry()) {
      step = first ? 0 : step + 1;
      first = false;
      measurement = 0;
      ASSERT_LT(step, log.scenario.steps.size());
      EXPECT_NEAR(e.t_s, step * options.step_s, 1e-9);
      if (step > 0) {
        const mapping::OdometryStep& u = log.scenario.steps[step].odometry;
        EXPECT_NEAR(e.odometry().dx_m, u.dx_m, 1e-9);
        EXPECT_NEAR(e.odometry().dtheta_rad, u.dtheta_rad, 1e-9);
        EXPECT_TRUE(e.odometry().covariance->isApprox(*u.covariance, 1e-9));
      }
    } else {
      const mapping::RangeBearing& z = log.scenario.steps[step].measurements.at(measurement++);
      EXPECT_EQ(e.measurement().id, z.id);
      EXPECT_NEAR(e.measurement().range_m, z.range_m, 1e-9);
      EXPECT_NEAR(e.measurement().bearing_rad, z.bearing_rad, 1e-9);
    }
    EXPECT_NEAR(truth[step].x_m, log.scenario.steps[step].truth.x(), 1e-6);
  }
  EXPECT_EQ(step + 1, log.scenario.steps.size());
  std::filesystem::remove_all(dir);
}

TEST(RobustnessSimTest, SlamoMapsTheSecondRobotWhetherToldItsNoiseOrTheThesisRobots) {
  // Seeds 1-3, as `slamo experiment robustness --runs 3` prints them. Measured: told its own
  // file (each measurement's depth sigma at its depth), landmark RMSE 0.0076 m, ATE 0.0096 m,
  // mean NEES 2.3, where MRPT's filter, told one sigma, is at 0.0160 m and 0.0146 m; told the
  // thesis robot's (whose Kinect's depth sigma is a sixteenth of the D435's), 0.0111 m, 0.0152 m
  // and 2.6, where MRPT's filter is 4x worse and overconfident (0.041 m, 0.051 m, NEES 111).
  const std::vector<SimRobotRow> rows = RunSimRobotRows(
      SimRobotOptions{}, {{"v5_drivetrain", "v5_drivetrain"}, {"v5_drivetrain", "thesis_robot"}}, 3,
      1, nullptr);
  ASSERT_EQ(rows.size(), 2u);
  for (const SimRobotRow& row : rows) {
    SCOPED_TRACE(row.robots.data_robot + " told " + row.robots.told_robot + ": landmarks " +
                 std::to_string(row.slamo.landmark_rmse_m) + " (MRPT " +
                 std::to_string(row.mrpt.landmark_rmse_m) + "), ATE " +
                 std::to_string(row.slamo.ate_m) + " (MRPT " + std::to_string(row.mrpt.ate_m) +
                 "), NEES " + std::to_string(row.slamo.mean_nees));
    EXPECT_LT(row.slamo.ate_m, 0.03);
    EXPECT_LT(row.slamo.landmark_rmse_m, 0.03);
    EXPECT_LT(row.slamo.mean_nees, 18.7);  // twice the top of one step's 95 % band
    EXPECT_LT(row.slamo.rejected_fraction, 0.02);
  }
  const SimRobotRow& told_own = rows[0];
  EXPECT_LE(told_own.slamo.landmark_rmse_m, told_own.mrpt.landmark_rmse_m);
  EXPECT_LE(told_own.slamo.ate_m, told_own.mrpt.ate_m);
  const SimRobotRow& told_thesis = rows[1];
  EXPECT_LT(told_thesis.slamo.landmark_rmse_m, 0.5 * told_thesis.mrpt.landmark_rmse_m);
  EXPECT_LT(told_thesis.slamo.ate_m, 0.5 * told_thesis.mrpt.ate_m);
  EXPECT_GT(told_thesis.mrpt.mean_nees, 18.7);
}

}  // namespace
}  // namespace slamo::autonomy
