// Accuracy of a SLAM run against ground truth: trajectories in the TUM RGB-D format, the
// absolute trajectory error (ATE) exactly as the TUM RGB-D benchmark's evaluate_ate.py computes
// it (associate by timestamp, rigid Horn/Umeyama alignment without scale, RMSE of the
// translational differences), and the landmark position error after the same alignment.
// Pure functions apart from the file readers and writers; bad files throw std::runtime_error
// naming the file and the line.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace slamo::mapping {

// A planar pose at a time.
struct TimedPose {
  double t_s = 0.0;
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
};

// A point landmark with its id (-1 when it has none).
struct LandmarkPoint {
  int id = -1;
  double x_m = 0.0;
  double y_m = 0.0;
};

// A planar rigid transform p' = R(theta) p + t.
struct Rigid2d {
  double theta_rad = 0.0;
  Eigen::Vector2d translation_m = Eigen::Vector2d::Zero();

  Eigen::Vector2d Apply(const Eigen::Vector2d& p) const;
  TimedPose Apply(const TimedPose& pose) const;
};

// TUM RGB-D trajectory: one line `timestamp tx ty tz qx qy qz qw` per pose, z = 0 and the
// quaternion a rotation about z by theta, after a header comment that names `what` the poses
// are when it is given. Throws std::runtime_error if the file cannot be written.
void WriteTumTrajectory(const std::string& path, const std::vector<TimedPose>& poses,
                        const std::string& what = "");
// Reads a TUM trajectory (`#` comments and blank lines allowed); the heading is the yaw of the
// quaternion. Errors name the file and the line.
std::vector<TimedPose> ReadTumTrajectory(const std::string& path);

// Pairs (truth index, estimate index) whose timestamps differ by less than max_dt_s, each
// timestamp used at most once, closest pairs first (the benchmark's associate.py with offset
// 0); sorted by truth time.
std::vector<std::pair<int, int>> AssociateByTime(const std::vector<TimedPose>& truth,
                                                 const std::vector<TimedPose>& estimate,
                                                 double max_dt_s);

// The rigid transform (no scale) that best maps `from` onto `to` in the least-squares sense
// (Horn / Umeyama). Needs at least one pair; with one pair it is a translation.
Rigid2d AlignRigid(const std::vector<Eigen::Vector2d>& from,
                   const std::vector<Eigen::Vector2d>& to);

struct AteResult {
  double rmse_m = 0.0;  // the ATE
  double mean_m = 0.0;
  double median_m = 0.0;
  double max_m = 0.0;
  int pairs = 0;      // associated poses
  Rigid2d alignment;  // estimate -> truth frame (identity without alignment)
};

// The error of estimated positions paired with true ones (truth[k] with estimate[k]: taken at
// the same instants), after the rigid alignment of the estimates onto the truth when `align`.
// Throws std::invalid_argument when there are no pairs or the two differ in length.
AteResult PairedTrajectoryError(const std::vector<Eigen::Vector2d>& truth,
                                const std::vector<Eigen::Vector2d>& estimate, bool align);

// Absolute trajectory error of `estimate` against `truth`: poses associated by time
// (AssociateByTime), then PairedTrajectoryError. Throws std::invalid_argument when no
// timestamps associate.
AteResult AbsoluteTrajectoryError(const std::vector<TimedPose>& truth,
                                  const std::vector<TimedPose>& estimate, double max_dt_s = 0.02,
                                  bool align = true);

struct LandmarkError {
  double rmse_m = 0.0;
  int pairs = 0;    // matched landmarks
  int missing = 0;  // truth landmarks without an estimate
};

// RMSE of estimated landmark positions, mapped into the truth frame by `alignment` (e.g.
// AteResult::alignment, so the map is judged in the frame that best fits the trajectory).
// Landmarks match by id; an estimate without an id (-1) matches the nearest truth landmark not
// otherwise matched. Throws std::invalid_argument when nothing matches.
LandmarkError LandmarkRmse(const std::vector<LandmarkPoint>& truth,
                           const std::vector<LandmarkPoint>& estimate,
                           const Rigid2d& alignment = {});

// Landmark CSV: an optional header line, then `id,x_m,y_m[,more columns]` per landmark (the replay
// command's landmarks.csv has the covariance in the extra columns). Errors name file and line.
std::vector<LandmarkPoint> ReadLandmarkCsv(const std::string& path);

// The truth MRPT's `simul-landmarks` writes beside its rawlog `X`:
// - `X_ground_truth_robot_path.txt`: `%` comment lines, then `x y z yaw pitch roll` per step:
//   row k (from 0) is the pose where the rawlog's k-th observation was taken, after k odometry
//   steps; the last odometry step leads to a pose without a row (no timestamps, so a replay
//   pairs the rows with its trajectory step by step);
// - `X_ground_truth.txt`: `x y z a b c id` per landmark, the id the one the rawlog's
//   observations carry.
// Errors name the file and the line.
struct SimulLandmarksPose {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};
std::vector<SimulLandmarksPose> ReadSimulLandmarksPath(const std::string& path);
std::vector<LandmarkPoint> ReadSimulLandmarksMap(const std::string& path);

// Which of the formats above a truth file is in, by its first line that is not blank: `%`
// opens simul-landmarks' robot path; a line of numbers without commas is simul-landmarks'
// landmark map; anything else is TUM (trajectories) or CSV (landmarks). Throws
// std::runtime_error naming the file when it cannot be opened.
enum class TruthFormat { kTumOrCsv, kSimulLandmarksPath, kSimulLandmarksMap };
TruthFormat DetectTruthFormat(const std::string& path);

}  // namespace slamo::mapping
