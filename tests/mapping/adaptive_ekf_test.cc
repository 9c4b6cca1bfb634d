// The EKF on logs it was not tuned to: odometry noisier than its motion model, a kidnapped
// robot, and a log that matches the model (its NIS must then sit near its expectation).
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"

namespace slamo::mapping {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct LoggedRun {
  std::vector<std::pair<OdometryStep, std::vector<RangeBearing>>> steps;  // odometry, then seen
  std::vector<Eigen::Vector3d> truth;                                     // after each step
  std::vector<Eigen::Vector2d> landmarks;
};

// Two laps of a 4 m square in 0.1 m steps, 90 degree turns in nine steps, among 16 landmarks
// with known ids seen within 4 m. The odometry's error is the filter's default motion model
// times `noise_factor` (drawn from a fixed seed); a kidnap at step `kidnap_step` moves the
// robot `kidnap_m` sideways without the odometry knowing. The measurements' true noise is
// `sensor_factor` times the covariance they carry.
LoggedRun MakeRun(double noise_factor, int seed, int kidnap_step = -1, double kidnap_m = 0.0,
                  double sensor_factor = 1.0) {
  LoggedRun run;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) run.landmarks.emplace_back(-1.0 + 2.0 * i, -1.0 + 2.0 * j);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const MotionNoise model;
  const double sigma_range = 0.02, sigma_bearing = 0.01;
  Eigen::Vector3d pose(0.0, 0.0, 0.0);
  int index = 0;
  const auto step = [&](double dx, double dtheta) {
    const OdometryStep commanded{dx, 0.0, dtheta};
    const Eigen::Vector3d sigma =
        MotionModelCovariance(model, commanded).diagonal().cwiseSqrt() * noise_factor;
    // The robot moves by the odometry reading's error; the odometry reads the command.
    OdometryStep actual{dx + sigma.x() * n01(rng), sigma.y() * n01(rng),
                        dtheta + sigma.z() * n01(rng)};
    if (index++ == kidnap_step) actual.dy_m += kidnap_m;
    pose = EkfSlam::Move(pose, actual, nullptr, nullptr);
    std::vector<RangeBearing> seen;
    for (size_t l = 0; l < run.landmarks.size(); ++l) {
      const Eigen::Vector2d h = EkfSlam::Observe(pose, run.landmarks[l]);
      if (h.x() > 4.0) continue;
      RangeBearing z;
      z.range_m = h.x() + sensor_factor * sigma_range * n01(rng);
      z.bearing_rad = std::remainder(h.y() + sensor_factor * sigma_bearing * n01(rng), 2.0 * kPi);
      z.covariance =
          Eigen::Vector2d(sigma_range * sigma_range, sigma_bearing * sigma_bearing).asDiagonal();
      z.id = static_cast<int>(l);
      seen.push_back(z);
    }
    run.steps.push_back({commanded, seen});
    run.truth.push_back(pose);
  };
  for (int lap = 0; lap < 2; ++lap) {
    for (int side = 0; side < 4; ++side) {
      for (int i = 0; i < 40; ++i) step(0.1, 0.0);
      for (int i = 0; i < 9; ++i) step(0.0, kPi / 18.0);
    }
  }
  return run;
}

struct Outcome {
  double ate_m = 0.0;            // every step's pose after its measurements, aligned
  double landmark_rmse_m = 0.0;  // in the trajectory's alignment
  double rejected_fraction = 0.0;
  std::vector<double> error_m;  // unaligned position error after each step
  FilterCounters counters;
  double final_scale = 1.0;
  double final_sensor_scale = 1.0;
  double mean_nees = 0.0;  // pose NEES after each step's measurements, over the steps
};

Outcome Replay(const LoggedRun& run, bool adaptive, bool first_estimates = false) {
  EkfOptions options;
  options.adaptive.enabled = adaptive;
  options.first_estimates = first_estimates;
  options.max_range_m = 4.5;
  EkfSlam ekf(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 1e-6, options);
  Outcome out;
  std::vector<Eigen::Vector2d> truth, estimate;
  int tried = 0;
  for (size_t k = 0; k < run.steps.size(); ++k) {
    ekf.Predict(run.steps[k].first);
    for (const RangeBearing& z : run.steps[k].second) {
      ++tried;
      ekf.Update(z);
    }
    truth.push_back(run.truth[k].head<2>());
    estimate.push_back(ekf.pose().head<2>());
    out.error_m.push_back((truth.back() - estimate.back()).norm());
    out.mean_nees += PoseNees(run.truth[k], ekf.pose(), ekf.pose_covariance()) /
                     static_cast<double>(run.steps.size());
  }
  const AteResult ate = PairedTrajectoryError(truth, estimate, /*align=*/true);
  out.ate_m = ate.rmse_m;
  std::vector<LandmarkPoint> true_landmarks, mapped;
  for (size_t l = 0; l < run.landmarks.size(); ++l)
    true_landmarks.push_back({static_cast<int>(l), run.landmarks[l].x(), run.landmarks[l].y()});
  for (int i = 0; i < ekf.landmark_count(); ++i)
    mapped.push_back({ekf.landmark_id(i), ekf.landmark(i).x(), ekf.landmark(i).y()});
  out.landmark_rmse_m = LandmarkRmse(true_landmarks, mapped, ate.alignment).rmse_m;
  out.counters = ekf.counters();
  out.rejected_fraction = static_cast<double>(out.counters.rejected) / tried;
  out.final_scale = ekf.process_noise_scale();
  out.final_sensor_scale = ekf.measurement_noise_scale();
  return out;
}

TEST(AdaptiveEkfTest, NisStaysNearItsExpectationWhenTheLogMatchesTheModel) {
  for (int seed : {1, 2, 3}) {
    const Outcome o = Replay(MakeRun(1.0, seed), /*adaptive=*/true);
    SCOPED_TRACE("seed " + std::to_string(seed));
    // Expected 2 (2 dof); the average over some 2000 updates is within a few per cent of it
    // when the model is right.
    EXPECT_GT(o.counters.MeanNis(), 1.6);
    EXPECT_LT(o.counters.MeanNis(), 2.5);
    EXPECT_LT(o.rejected_fraction, 0.02);
    EXPECT_EQ(o.counters.reacquired, 0);
    EXPECT_LT(o.ate_m, 0.05);
  }
}

TEST(AdaptiveEkfTest, FiveTimesTheAssumedMotionNoiseStillMaps) {
  for (int seed : {1, 2, 3}) {
    const LoggedRun run = MakeRun(5.0, seed);
    const Outcome fixed = Replay(run, /*adaptive=*/false);
    const Outcome adaptive = Replay(run, /*adaptive=*/true);
    SCOPED_TRACE("seed " + std::to_string(seed) + ": fixed ATE " + std::to_string(fixed.ate_m) +
                 " landmarks " + std::to_string(fixed.landmark_rmse_m) + " rejected " +
                 std::to_string(fixed.rejected_fraction) + "; adaptive ATE " +
                 std::to_string(adaptive.ate_m) + " landmarks " +
                 std::to_string(adaptive.landmark_rmse_m) + " rejected " +
                 std::to_string(adaptive.rejected_fraction));
    EXPECT_LT(adaptive.ate_m, 0.05);
    EXPECT_LT(adaptive.landmark_rmse_m, 0.05);
    EXPECT_LT(adaptive.rejected_fraction, 0.10);
    EXPECT_GE(adaptive.counters.adaptive_episodes, 1);  // it noticed
    EXPECT_GT(adaptive.final_scale, 1.0);
    EXPECT_LE(adaptive.ate_m, fixed.ate_m);
  }
}

TEST(AdaptiveEkfTest, FiveTimesTheToldSensorNoiseIsLearntAndNotTakenForMotion) {
  for (int seed : {1, 2, 3}) {
    const LoggedRun run = MakeRun(1.0, seed, -1, 0.0, /*sensor_factor=*/5.0);
    const Outcome fixed = Replay(run, /*adaptive=*/false);
    const Outcome adaptive = Replay(run, /*adaptive=*/true);
    // The reference: the same log with its measurements' true covariance.
    LoggedRun told_right = run;
    for (auto& [odometry, seen] : told_right.steps)
      for (RangeBearing& z : seen) z.covariance *= 25.0;
    const Outcome right = Replay(told_right, /*adaptive=*/false);
    SCOPED_TRACE(
        "seed " + std::to_string(seed) + ": told right ATE " + std::to_string(right.ate_m) +
        " landmarks " + std::to_string(right.landmark_rmse_m) + "; fixed ATE " +
        std::to_string(fixed.ate_m) + " rejected " + std::to_string(fixed.rejected_fraction) +
        "; adaptive ATE " + std::to_string(adaptive.ate_m) + " landmarks " +
        std::to_string(adaptive.landmark_rmse_m) + " sensor scale " +
        std::to_string(adaptive.final_sensor_scale));
    // The variance is 25x the told: the learnt scale lands near it.
    EXPECT_GE(adaptive.counters.sensor_episodes, 1);
    EXPECT_GT(adaptive.final_sensor_scale, 12.0);
    EXPECT_LT(adaptive.final_sensor_scale, 50.0);
    // The motion model is right: its noise is not raised for the sensor's fault.
    EXPECT_EQ(adaptive.counters.adaptive_episodes, 0);
    EXPECT_LT(adaptive.rejected_fraction, 0.02);
    EXPECT_GT(fixed.rejected_fraction, 0.3);  // the fixed filter gates most of them away
    // Better than the filter told wrong. Not as good as one told the truth: the landmarks
    // placed in the steps before the verdict keep part of their error (2-3x the told-right
    // filter's landmark RMSE on these seeds; the README's robustness notes).
    EXPECT_LT(adaptive.ate_m, fixed.ate_m);
    EXPECT_LT(adaptive.landmark_rmse_m, 0.05);
    EXPECT_LT(adaptive.landmark_rmse_m, 4.0 * right.landmark_rmse_m);
  }
}

TEST(AdaptiveEkfTest, AKidnappedRobotIsReacquiredWithinAFewSteps) {
  // Half a metre sideways at step 100, on a log that otherwise matches the model.
  const int kidnap = 100;
  const LoggedRun run = MakeRun(1.0, 4, kidnap, 0.5);
  const Outcome fixed = Replay(run, /*adaptive=*/false);
  const Outcome adaptive = Replay(run, /*adaptive=*/true);
  EXPECT_GE(adaptive.counters.reacquired, 1);
  // Within 10 cm of the truth from two steps (a handful of measurements) after the kidnap on,
  // as before it (unaligned, the map's frame drifts by a few centimetres).
  for (size_t k = kidnap + 2; k < adaptive.error_m.size(); ++k)
    ASSERT_LT(adaptive.error_m[k], 0.1) << "step " << k;
  // The filter as it was stays lost.
  EXPECT_EQ(fixed.counters.reacquired, 0);
  EXPECT_GT(fixed.error_m[kidnap + 10], 0.3);
}

// A match as SlamO feeds the filter (found on Push Back with the V5 robot, where the adaptive
// filter ran 0.5-1.4 m off while the fixed one held within a centimetre): a surveyed field,
// stops where the same markers are measured frame after frame (IteratedFrameCovariance) and
// one colour misdetected in front of the robot, its marker really behind it, at every frame.
// The repeated frames are not a snapshot of many landmarks and the misdetection is an outlier:
// the adaptive filter must stay with the truth, its noise unraised and its pose never widened.
TEST(AdaptiveEkfTest, RepeatedFramesAndAMisdetectedMarkerAreNotTakenForWrongNoise) {
  const std::vector<Eigen::Vector2d> markers{{1.85, 0.61},   {1.85, -0.61},  {0.91, -1.85},
                                             {-0.91, -1.85}, {-1.85, -0.61}, {-1.85, 0.61},
                                             {-0.91, 1.85},  {0.91, 1.85}};
  EkfOptions options;
  options.adaptive.enabled = true;
  options.add_landmarks = false;
  const Eigen::Vector3d start(-1.2, 0.0, 0.0);
  EkfSlam ekf(start, Eigen::Vector3d(1e-4, 1e-4, 3e-4).asDiagonal(), options);
  for (size_t i = 0; i < markers.size(); ++i)
    ekf.AddKnownLandmark(markers[i], Eigen::Matrix2d::Identity() * 1e-6, static_cast<int>(i),
                         "m" + std::to_string(i));
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  const Eigen::Matrix2d white = Eigen::Vector2d(0.01 * 0.01, 0.004 * 0.004).asDiagonal();
  const Eigen::Matrix2d bias = Eigen::Vector2d(0.01 * 0.01, 0.005 * 0.005).asDiagonal();
  Eigen::Vector3d pose = start;
  for (int stop = 0; stop < 12; ++stop) {
    // Drive 0.2 m (odometry exact here: only the measurements are in question).
    const OdometryStep u{0.2, 0.0, stop % 3 == 2 ? 0.3 : 0.0};
    pose = EkfSlam::Move(pose, u, nullptr, nullptr);
    ekf.Predict(u);
    // Ten frames at the stop: every marker in front within 4 m, with one bias per stop.
    std::vector<std::pair<int, Eigen::Vector2d>> stop_bias;
    for (int frame = 1; frame <= 10; ++frame) {
      std::vector<RangeBearing> seen;
      for (size_t l = 0; l < markers.size(); ++l) {
        const Eigen::Vector2d h = EkfSlam::Observe(pose, markers[l]);
        if (h.x() > 4.0 || std::abs(h.y()) > 0.76) continue;
        if (frame == 1)
          stop_bias.push_back(
              {static_cast<int>(l), Eigen::Vector2d(0.01 * n01(rng), 0.005 * n01(rng))});
        Eigen::Vector2d b = Eigen::Vector2d::Zero();
        for (const auto& [id, v] : stop_bias)
          if (id == static_cast<int>(l)) b = v;
        RangeBearing z;
        z.range_m = h.x() + b.x() + 0.01 * n01(rng);
        z.bearing_rad = h.y() + b.y() + 0.004 * n01(rng);
        z.covariance = IteratedFrameCovariance(white, bias, frame);
        z.id = static_cast<int>(l);
        seen.push_back(z);
      }
      // Marker 2's colour seen 1.3 m straight ahead, every frame.
      RangeBearing ghost;
      ghost.range_m = 1.3 + 0.01 * n01(rng);
      ghost.bearing_rad = 0.17;
      ghost.covariance = IteratedFrameCovariance(white, bias, frame);
      ghost.id = 2;
      seen.push_back(ghost);
      for (const RangeBearing& z : seen) ekf.Update(z);
    }
    const Eigen::Vector2d error = ekf.pose().head<2>() - pose.head<2>();
    ASSERT_LT(error.norm(), 0.03) << "stop " << stop;
  }
  EXPECT_EQ(ekf.process_noise_scale(), 1.0);
  EXPECT_EQ(ekf.measurement_noise_scale(), 1.0);
  EXPECT_EQ(ekf.counters().reacquired, 0);
  EXPECT_EQ(ekf.counters().adaptive_episodes, 0);
  EXPECT_EQ(ekf.counters().sensor_episodes, 0);
  EXPECT_GT(ekf.counters().rejected, 100);  // the ghost, refused at every frame
}

TEST(AdaptiveEkfTest, FirstEstimatesJacobiansMapBetterWhereTheModelIsRight) {
  // Ten logs that match the model: the textbook EKF, Jacobians at the latest estimate, against
  // the first-estimates EKF (FEJ). Relinearising at estimates that moved makes the textbook
  // filter believe it observes the map's heading; measured on seeds 1-10 its landmark RMSE is
  // 0.005-0.022 m against FEJ's 0.0016-0.0046 m, its ATE 0.008-0.018 m against 0.006-0.007 m,
  // and its worst seed's mean pose NEES 9.0 against 5.2.
  double standard_rmse = 0.0, fej_rmse = 0.0, standard_worst_nees = 0.0, fej_worst_nees = 0.0;
  for (int seed = 1; seed <= 10; ++seed) {
    const LoggedRun run = MakeRun(1.0, seed);
    const Outcome standard = Replay(run, /*adaptive=*/false, /*first_estimates=*/false);
    const Outcome fej = Replay(run, /*adaptive=*/false, /*first_estimates=*/true);
    SCOPED_TRACE("seed " + std::to_string(seed) + ": landmarks " +
                 std::to_string(standard.landmark_rmse_m) + " against FEJ " +
                 std::to_string(fej.landmark_rmse_m) + ", ATE " + std::to_string(standard.ate_m) +
                 " against " + std::to_string(fej.ate_m));
    EXPECT_LT(fej.landmark_rmse_m, standard.landmark_rmse_m);
    EXPECT_LT(fej.ate_m, standard.ate_m);
    EXPECT_LT(fej.landmark_rmse_m, 0.006);
    EXPECT_LT(fej.ate_m, 0.01);
    standard_rmse += standard.landmark_rmse_m / 10.0;
    fej_rmse += fej.landmark_rmse_m / 10.0;
    standard_worst_nees = std::max(standard_worst_nees, standard.mean_nees);
    fej_worst_nees = std::max(fej_worst_nees, fej.mean_nees);
  }
  EXPECT_LT(fej_rmse, 0.5 * standard_rmse);
  EXPECT_LT(fej_worst_nees, standard_worst_nees);
  EXPECT_LT(fej_worst_nees, 9.35);  // inside one step's 95 % band (3 dof)
}

TEST(AdaptiveEkfTest, AStepsOwnCovarianceReplacesTheMotionModel) {
  EkfSlam model(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
  EkfSlam own(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
  const Eigen::Matrix3d q = Eigen::Vector3d(0.04, 0.01, 0.0025).asDiagonal();
  model.Predict(OdometryStep{0.5, 0.0, 0.0});
  own.Predict(OdometryStep{0.5, 0.0, 0.0, q});
  EXPECT_TRUE(own.pose_covariance().isApprox(q));
  EXPECT_TRUE(model.pose_covariance().isApprox(
      MotionModelCovariance(MotionNoise{}, OdometryStep{0.5, 0.0, 0.0})));
}

}  // namespace
}  // namespace slamo::mapping
