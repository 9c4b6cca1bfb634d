// Peer comparison: MRPT's CRangeBearingKFSLAM2D and slamo's EkfSlam on the same simulated
// run. A robot drives laps of a square among point landmarks; odometry noise is drawn from
// exactly the per-step covariance both filters are given, measurements carry known landmark
// ids (both filters associate by id), and each filter is scored on ATE, pose NEES and time.
// The generator is pure and seeded; only the runners read a clock, around each filter step.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"

namespace slamo::autonomy {

struct PeerBenchOptions {
  int laps = 2;
  double side_m = 2.0;             // the square driven, from (0, 0) heading +x, turning left
  double step_m = 0.1;             // forward per odometry step; a corner is one 90 deg step
  double dt_s = 0.1;               // time per step (trajectory timestamps)
  int landmarks = 8;               // spread evenly around the square
  double landmark_margin_m = 0.5;  // landmarks lie this far outside the square
  double max_range_m = 3.0;        // measured range limit (omnidirectional sensor)
  double sigma_range_m = 0.02;     // range noise
  double sigma_bearing_rad = 0.017453292519943295;  // bearing noise (1 deg)
  double sigma_step_xy_m = 0.005;                   // odometry noise per step, forward and sideways
  double sigma_step_heading_rad = 0.01;             // odometry heading noise per step
  bool adaptive = false;         // slamo's filter checks itself (mapping::AdaptiveOptions)
  bool first_estimates = false;  // slamo's filter: first-estimates Jacobians (mapping::EkfOptions)
};

// The motion noise slamo's filter is given: a fixed covariance per step, the one the
// generator draws from (MRPT gets the same matrix in each CActionRobotMovement2D).
mapping::MotionNoise PeerMotionNoise(const PeerBenchOptions& options);
// The per-step odometry covariance diag(sxy^2, sxy^2, stheta^2) in the robot frame.
Eigen::Matrix3d PeerStepCovariance(const PeerBenchOptions& options);

// One step: the odometry since the previous step, then the measurements at the new pose.
// Step 0 has a zero odometry step and the first measurements at the start pose.
struct PeerStep {
  mapping::OdometryStep odometry;
  std::vector<mapping::RangeBearing> measurements;  // id = landmark index; float-exact values
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();  // x_m, y_m, theta_rad after the step
};

struct PeerScenario {
  std::vector<Eigen::Vector2d> landmarks;  // id = index
  std::vector<PeerStep> steps;
};

// Simulates one run. Throws std::invalid_argument if no landmark is in range at the start
// (MRPT would then drop the first odometry steps; see RunMrptFilter).
PeerScenario SimulatePeerScenario(const PeerBenchOptions& options, uint64_t seed);

// A filter's estimate after each step, and its time over all steps.
struct PeerTrack {
  std::vector<mapping::TimedPose> poses;
  std::vector<Eigen::Matrix3d> covariances;
  double filter_s = 0.0;  // wall clock inside the filter's step calls only
  int rejected = 0;       // measurements the filter refused (slamo's outcome kRejected)
  std::vector<mapping::LandmarkPoint> landmarks;  // the map at the end, with the landmarks' ids
};

// slamo's EkfSlam: Predict, then Update with each measurement, per step.
PeerTrack RunSlamoFilter(const PeerScenario& scenario, const PeerBenchOptions& options);
// MRPT's CRangeBearingKFSLAM2D: one processActionObservation per step, the step's odometry
// covariance its own where it has one (else PeerStepCovariance), as slamo's filter uses it.
PeerTrack RunMrptFilter(const PeerScenario& scenario, const PeerBenchOptions& options);

// The truth as a trajectory, timestamped like the tracks.
std::vector<mapping::TimedPose> PeerTruth(const PeerScenario& scenario,
                                          const PeerBenchOptions& options);

// One filter's results over all runs.
struct PeerRow {
  std::string filter;
  double ate_aligned_m = 0.0;    // mean over runs of the ATE after rigid alignment
  double ate_unaligned_m = 0.0;  // mean over runs of the RMSE without alignment
  double mean_nees = 0.0;        // pose NEES averaged over runs, then over steps 1..N
  int steps_in_band = 0;         // steps whose run-averaged NEES lies in the 95 % band
  int steps = 0;                 // steps scored for NEES (step 0 has a zero covariance)
  double ms_per_step = 0.0;
  int rejected = 0;  // measurements refused, over all runs
};

struct PeerBenchResult {
  std::pair<double, double> nees_band;  // mapping::NeesBand(3, runs)
  std::vector<PeerRow> rows;            // slamo, then MRPT
};

// Runs both filters on `runs` scenarios, seeds seed, seed + 1, ...
PeerBenchResult RunPeerBench(const PeerBenchOptions& options, int runs, uint64_t seed);

}  // namespace slamo::autonomy
