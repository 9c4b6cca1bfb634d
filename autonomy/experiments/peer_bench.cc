#include "autonomy/experiments/peer_bench.h"

#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/slam/CRangeBearingKFSLAM2D.h>

#include "platform/drive_base.h"

namespace slamo::autonomy {
namespace {

using platform::kPi;

double Wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// MRPT keeps ranges, bearings and sensor sigmas as float: both filters get the float values.
double AsFloat(double v) { return static_cast<double>(static_cast<float>(v)); }

Eigen::Vector3d Compose(const Eigen::Vector3d& pose, const Eigen::Vector3d& u) {
  const double c = std::cos(pose.z()), s = std::sin(pose.z());
  return {pose.x() + c * u.x() - s * u.y(), pose.y() + s * u.x() + c * u.y(),
          Wrap(pose.z() + u.z())};
}

Eigen::Matrix2d MeasurementCovariance(const PeerBenchOptions& options) {
  const double r = AsFloat(options.sigma_range_m), b = AsFloat(options.sigma_bearing_rad);
  return Eigen::Vector2d(r * r, b * b).asDiagonal();
}

// Landmarks evenly spaced around the square enlarged by the margin, from its lower-left corner.
std::vector<Eigen::Vector2d> PlaceLandmarks(const PeerBenchOptions& options) {
  const double lo = -options.landmark_margin_m;
  const double side = options.side_m + 2.0 * options.landmark_margin_m;
  std::vector<Eigen::Vector2d> out;
  for (int i = 0; i < options.landmarks; ++i) {
    double along = 4.0 * side * i / options.landmarks;
    const int edge = static_cast<int>(along / side);
    along -= edge * side;
    const Eigen::Vector2d corners[4] = {
        {lo, lo}, {lo + side, lo}, {lo + side, lo + side}, {lo, lo + side}};
    const Eigen::Vector2d dir = (corners[(edge + 1) % 4] - corners[edge]) / side;
    out.push_back(corners[edge] + along * dir);
  }
  return out;
}

std::vector<mapping::RangeBearing> Measure(const Eigen::Vector3d& truth,
                                           const std::vector<Eigen::Vector2d>& landmarks,
                                           const PeerBenchOptions& options, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  std::vector<mapping::RangeBearing> out;
  for (size_t id = 0; id < landmarks.size(); ++id) {
    const Eigen::Vector2d z = mapping::EkfSlam::Observe(truth, landmarks[id]);
    // Draw both noises for every landmark so a landmark's range does not shift the stream.
    const double range = AsFloat(z.x() + options.sigma_range_m * normal(*rng));
    const double bearing = AsFloat(Wrap(z.y() + options.sigma_bearing_rad * normal(*rng)));
    if (z.x() > options.max_range_m || range > options.max_range_m || range <= 0.0) continue;
    mapping::RangeBearing m;
    m.range_m = range;
    m.bearing_rad = bearing;
    m.covariance = MeasurementCovariance(options);
    m.id = static_cast<int>(id);
    out.push_back(m);
  }
  return out;
}

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

mapping::TimedPose Timed(int step, const PeerBenchOptions& options, const Eigen::Vector3d& p) {
  return {step * options.dt_s, p.x(), p.y(), p.z()};
}

}  // namespace

mapping::MotionNoise PeerMotionNoise(const PeerBenchOptions& options) {
  mapping::MotionNoise noise;
  noise.sigma_per_m = noise.lateral_sigma_per_m = 0.0;
  noise.forward_sigma_per_rad = noise.lateral_sigma_per_rad = 0.0;
  noise.heading_sigma_per_rad = noise.heading_sigma_per_m = 0.0;
  noise.floor_m = options.sigma_step_xy_m;
  noise.floor_rad = options.sigma_step_heading_rad;
  return noise;
}

Eigen::Matrix3d PeerStepCovariance(const PeerBenchOptions& options) {
  const double xy = options.sigma_step_xy_m, th = options.sigma_step_heading_rad;
  return Eigen::Vector3d(xy * xy, xy * xy, th * th).asDiagonal();
}

PeerScenario SimulatePeerScenario(const PeerBenchOptions& options, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  PeerScenario scenario;
  scenario.landmarks = PlaceLandmarks(options);

  // The commanded increments: forward steps along each side, one 90 deg step at each corner.
  std::vector<Eigen::Vector3d> commands;
  const int per_side = static_cast<int>(std::lround(options.side_m / options.step_m));
  for (int lap = 0; lap < options.laps; ++lap) {
    for (int side = 0; side < 4; ++side) {
      for (int i = 0; i < per_side; ++i) commands.emplace_back(options.step_m, 0.0, 0.0);
      commands.emplace_back(0.0, 0.0, kPi / 2.0);
    }
  }

  PeerStep first;
  first.measurements = Measure(first.truth, scenario.landmarks, options, &rng);
  if (first.measurements.empty()) {
    throw std::invalid_argument("peer bench: no landmark within range of the start pose");
  }
  scenario.steps.push_back(first);
  for (const Eigen::Vector3d& u : commands) {
    // The robot moves as commanded; odometry reads the command plus noise of the covariance
    // both filters are given.
    PeerStep step;
    step.truth = Compose(scenario.steps.back().truth, u);
    step.odometry.dx_m = u.x() + options.sigma_step_xy_m * normal(rng);
    step.odometry.dy_m = u.y() + options.sigma_step_xy_m * normal(rng);
    step.odometry.dtheta_rad = u.z() + options.sigma_step_heading_rad * normal(rng);
    step.measurements = Measure(step.truth, scenario.landmarks, options, &rng);
    scenario.steps.push_back(step);
  }
  return scenario;
}

std::vector<mapping::TimedPose> PeerTruth(const PeerScenario& scenario,
                                          const PeerBenchOptions& options) {
  std::vector<mapping::TimedPose> out;
  for (size_t k = 0; k < scenario.steps.size(); ++k) {
    out.push_back(Timed(static_cast<int>(k), options, scenario.steps[k].truth));
  }
  return out;
}

PeerTrack RunSlamoFilter(const PeerScenario& scenario, const PeerBenchOptions& options) {
  mapping::EkfOptions ekf;
  ekf.motion = PeerMotionNoise(options);
  ekf.max_range_m = options.max_range_m;
  ekf.adaptive.enabled = options.adaptive;
  ekf.first_estimates = options.first_estimates;
  // Known start, as MRPT's filter (it starts at (0, 0, 0) with zero covariance).
  mapping::EkfSlam filter(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero(), ekf);
  PeerTrack track;
  for (size_t k = 0; k < scenario.steps.size(); ++k) {
    const PeerStep& step = scenario.steps[k];
    const Clock::time_point start = Clock::now();
    if (k > 0) filter.Predict(step.odometry);
    for (const mapping::RangeBearing& z : step.measurements) {
      if (filter.Update(z) == mapping::UpdateOutcome::kRejected) ++track.rejected;
    }
    track.filter_s += Seconds(start);
    track.poses.push_back(Timed(static_cast<int>(k), options, filter.pose()));
    track.covariances.push_back(filter.pose_covariance());
  }
  for (int i = 0; i < filter.landmark_count(); ++i)
    track.landmarks.push_back(
        {filter.landmark_id(i), filter.landmark(i).x(), filter.landmark(i).y()});
  return track;
}

PeerTrack RunMrptFilter(const PeerScenario& scenario, const PeerBenchOptions& options) {
  mrpt::slam::CRangeBearingKFSLAM2D filter;
  filter.options.std_sensor_range = static_cast<float>(options.sigma_range_m);
  filter.options.std_sensor_yaw = static_cast<float>(options.sigma_bearing_rad);
  filter.options.create_simplemap = false;
  // Ids are given (landmarkID >= 0): the filter then associates by id and data_assoc_method is
  // used only for measurements without one.
  filter.KF_options.method = mrpt::bayes::kfEKFNaive;

  const Eigen::Matrix3d model_cov = PeerStepCovariance(options);
  PeerTrack track;
  for (size_t k = 0; k < scenario.steps.size(); ++k) {
    const PeerStep& step = scenario.steps[k];
    mrpt::math::CMatrixDouble33 q;
    const Eigen::Matrix3d step_cov = step.odometry.covariance.value_or(model_cov);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) q(r, c) = step_cov(r, c);
    // Step 0 is a zero move: MRPT skips prediction until its map holds a landmark anyway.
    auto actions = mrpt::obs::CActionCollection::Create();
    {
      const mrpt::poses::CPose2D mean(step.odometry.dx_m, step.odometry.dy_m,
                                      step.odometry.dtheta_rad);
      mrpt::obs::CActionRobotMovement2D move;
      move.estimationMethod = mrpt::obs::CActionRobotMovement2D::emOdometry;
      move.rawOdometryIncrementReading = mean;
      // The exact per-step covariance (computeFromOdometry's Gaussian model would rotate it by
      // half the turn and add its own terms).
      move.poseChange = mrpt::poses::CPosePDFGaussian::Create(mean, q);
      actions->insert(move);
    }
    auto frame = mrpt::obs::CSensoryFrame::Create();
    {
      // Always one observation, even empty: the filter asserts there is one.
      auto obs = mrpt::obs::CObservationBearingRange::Create();
      obs->minSensorDistance = 0.0f;
      // Both feed the filter's guess of which landmarks to predict; the defaults (0 = no
      // limit is taken as 0 m, 180 deg field of view) make it predict too few and redo the work.
      obs->maxSensorDistance = static_cast<float>(options.max_range_m);
      obs->fieldOfView_yaw = static_cast<float>(2.0 * kPi);
      obs->validCovariances = false;  // the filter reads its options' sigmas anyway
      obs->sensor_std_range = filter.options.std_sensor_range;
      obs->sensor_std_yaw = filter.options.std_sensor_yaw;
      for (const mapping::RangeBearing& z : step.measurements) {
        mrpt::obs::CObservationBearingRange::TMeasurement m;
        m.range = static_cast<float>(z.range_m);
        m.yaw = static_cast<float>(z.bearing_rad);
        m.pitch = 0.0f;
        m.landmarkID = z.id;
        m.covariance.setZero();
        obs->sensedData.push_back(m);
      }
      frame->insert(obs);
    }
    const Clock::time_point start = Clock::now();
    filter.processActionObservation(actions, frame);
    track.filter_s += Seconds(start);

    mrpt::poses::CPosePDFGaussian pose;
    filter.getCurrentRobotPose(pose);
    track.poses.push_back(Timed(static_cast<int>(k), options,
                                Eigen::Vector3d(pose.mean.x(), pose.mean.y(), pose.mean.phi())));
    Eigen::Matrix3d cov;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) cov(r, c) = pose.cov(r, c);
    track.covariances.push_back(cov);
  }
  // The map, with the landmarks' ids.
  mrpt::poses::CPosePDFGaussian pose;
  std::vector<mrpt::math::TPoint2D> positions;
  std::map<unsigned int, mrpt::maps::CLandmark::TLandmarkID> ids;
  mrpt::math::CVectorDouble state;
  mrpt::math::CMatrixDouble covariance;
  filter.getCurrentState(pose, positions, ids, state, covariance);
  for (size_t i = 0; i < positions.size(); ++i) {
    const auto id = ids.find(static_cast<unsigned int>(i));
    track.landmarks.push_back(
        {id == ids.end() ? -1 : static_cast<int>(id->second), positions[i].x, positions[i].y});
  }
  return track;
}

PeerBenchResult RunPeerBench(const PeerBenchOptions& options, int runs, uint64_t seed) {
  if (runs < 1) throw std::invalid_argument("peer bench: runs must be at least 1");
  PeerBenchResult result;
  result.nees_band = mapping::NeesBand(3, runs);
  struct Sums {
    double ate = 0, rmse = 0, seconds = 0;
    int steps = 0, rejected = 0;
    std::vector<double> nees;  // per step, summed over runs
  };
  Sums sums[2];
  for (int r = 0; r < runs; ++r) {
    const PeerScenario scenario = SimulatePeerScenario(options, seed + r);
    const std::vector<mapping::TimedPose> truth = PeerTruth(scenario, options);
    const PeerTrack tracks[2] = {RunSlamoFilter(scenario, options),
                                 RunMrptFilter(scenario, options)};
    for (int f = 0; f < 2; ++f) {
      const PeerTrack& track = tracks[f];
      Sums& s = sums[f];
      s.ate += mapping::AbsoluteTrajectoryError(truth, track.poses).rmse_m / runs;
      s.rmse += mapping::AbsoluteTrajectoryError(truth, track.poses, 0.02, false).rmse_m / runs;
      s.seconds += track.filter_s;
      s.steps += static_cast<int>(track.poses.size());
      s.rejected += track.rejected;
      s.nees.resize(track.poses.size(), 0.0);
      for (size_t k = 1; k < track.poses.size(); ++k) {
        const mapping::TimedPose& p = track.poses[k];
        s.nees[k] +=
            mapping::PoseNees(scenario.steps[k].truth, Eigen::Vector3d(p.x_m, p.y_m, p.theta_rad),
                              track.covariances[k]) /
            runs;
      }
    }
  }
  const char* names[2] = {"slamo EkfSlam", "MRPT CRangeBearingKFSLAM2D"};
  for (int f = 0; f < 2; ++f) {
    const Sums& s = sums[f];
    PeerRow row;
    row.filter = names[f];
    row.ate_aligned_m = s.ate;
    row.ate_unaligned_m = s.rmse;
    row.ms_per_step = 1000.0 * s.seconds / s.steps;
    row.rejected = s.rejected;
    for (size_t k = 1; k < s.nees.size(); ++k) {
      row.mean_nees += s.nees[k];
      row.steps_in_band +=
          s.nees[k] >= result.nees_band.first && s.nees[k] <= result.nees_band.second;
      ++row.steps;
    }
    if (row.steps > 0) row.mean_nees /= row.steps;
    result.rows.push_back(row);
  }
  return result;
}

}  // namespace slamo::autonomy
