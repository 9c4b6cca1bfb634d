// The thesis's SLAM experiments on the simulated field, end to end: the robot drives legs
// with wheel slip, and at each stop renders RGB-D frames, detects the landmark markers and
// updates the EKF frame by frame until the frame rule says stop.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "mapping/ekf_slam.h"
#include "mapping/frame_selection.h"
#include "mapping/object_tracker.h"
#include "platform/drive_base.h"

namespace slamo::autonomy {

struct WaypointsSetup {
  int landmarks = 2;  // 1, 2 or 3 markers on the far wall
  int stops = 4;      // thesis: every 0.3 m to 1.2 m
  double stop_spacing_m = 0.3;
  mapping::FrameSelectionOptions frames;
  mapping::EkfOptions ekf;
  // The filter's motion noise and range from the robot file (true), or `ekf`'s as given.
  bool motion_from_robot = true;
  Eigen::Matrix2d bias_covariance = Eigen::Matrix2d::Zero();  // per-stop measurement bias
  // Per-frame (white) measurement covariance; zero: vision's own estimate for each detection.
  Eigen::Matrix2d white_covariance = Eigen::Matrix2d::Zero();
  double known_landmark_sigma_m = 0.001;  // surveyed marker positions
  // When set (and objects are tracked): the OctoMap of the field with the confirmed objects,
  // updated at every stop, is written here at the end as objects.bt and objects.ot.
  std::string map_out_dir;
  bool iterate = true;  // false: one update per stop whatever the rule (single-frame mode)
  // true: the markers' surveyed positions are given to the filter (sigma 1 cm), as a team
  // that placed them would; false: SLAM, they are found as the thesis did.
  bool known_landmarks = false;
};

struct WaypointsRun {
  std::vector<double> stop_error_m;      // SLAM position error at the end of each stop
  std::vector<double> odometry_error_m;  // encoder dead reckoning at the same stops
  std::vector<double> stop_nees;         // pose NEES at each stop
  int frames = 0;
  double compute_s =
      0.0;  // detection + filter, measured on this machine
            // Measurement errors against the truth, per stop and landmark, for the bias model.
  std::vector<std::vector<Eigen::Vector2d>> errors_by_stop;
  // SLAM-O objects at the end (when objects were detected): each tracked object with the
  // nearest true object of its kind and colour, if one is within 0.5 m.
  struct ObjectResult {
    mapping::TrackedObject tracked;
    bool matched = false;
    Eigen::Vector2d truth_m = Eigen::Vector2d::Zero();
    double error_m = 0.0;
    double first_range_m = 0.0;  // from the robot when first seen
    bool truth_moved = false;    // the true object was pushed during the run
    bool confirmed = false;      // seen at least twice (the tracker's rule)
  };
  std::vector<ObjectResult> objects;
  double AccumulatedError() const;
  double OdometryAccumulatedError() const;
};

// The thesis 4.5 scene: the season's field without structures or objects, `landmarks`
// coloured markers with unique ids on the far wall, the robot 1.2 m + 1.8 m away facing them.
field::SeasonConfig WaypointsField(const field::SeasonConfig& season, int landmarks);

WaypointsRun RunWaypoints(const field::SeasonConfig& field, const field::RobotConfig& robot,
                          const WaypointsSetup& setup, uint64_t seed);

// Drives `legs` (drive-script statements, e.g. "forward 0.3", "turn 90") from `start`,
// stopping after each to observe; with `objects`, also detects and tracks game objects once
// per stop (on its last frame), as the thesis's covariance-selection pipeline does.
WaypointsRun RunRoute(const field::SeasonConfig& field, const field::RobotConfig& robot,
                      const platform::Pose2D& start, const std::vector<std::string>& legs,
                      const WaypointsSetup& setup, uint64_t seed, bool objects);

// Per-component white (within a stop) and bias (between stops) variances of range and bearing
// errors, estimated from runs.
void EstimateMeasurementNoise(const std::vector<WaypointsRun>& runs, Eigen::Vector2d* white,
                              Eigen::Vector2d* bias);

}  // namespace slamo::autonomy
