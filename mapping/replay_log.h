// Recorded runs for offline SLAM: a time-ordered list of odometry steps and range-bearing
// measurements, read from a plain-text log or an MRPT rawlog, and written back (for tests and
// for converting between the two).
//
// The text format, one event per line (see also mapping/README.md):
//
//   # comment; blank lines are ignored
//   start <x_m> <y_m> <theta_rad>          optional, before any event: the start pose
//   odom <t_s> <v_mps> <w_radps>           velocity form: the step since the previous odom
//                                          line is dx = v * dt, dy = 0, dtheta = w * dt (the
//                                          first odom line is a zero step)
//   odom <t_s> <dx_m> <dy_m> <dtheta_rad>  increment in the robot frame at the previous pose
//   odom <t_s> <dx_m> <dy_m> <dtheta_rad> <sigma_dx_m> <sigma_dy_m> <sigma_dtheta_rad>
//                                          the same with the step's own sigmas, used by the
//                                          filter instead of its motion model
//   obs <t_s> <id> <range_m> <bearing_rad> [<sigma_range_m> <sigma_bearing_rad>]
//                                          from the robot centre; id >= 0 for a known
//                                          landmark, -1 for one to associate
//
// Times are seconds and may not decrease; every number must be finite. A bad line throws
// ReplayLogError naming the file and the line.
//
// An MRPT rawlog (either layout: action/sensory-frame pairs or plain observations) gives odometry
// from CActionRobotMovement2D (the mean of poseChange, with its covariance, as MRPT's own EKF
// uses it) and CObservationOdometry (the change
// between consecutive readings), and measurements from CObservationBearingRange, moved from the
// sensor (sensorLocationOnRobot) to the robot centre with their covariance. Other observations
// are skipped; anything else, or a record that does not deserialise, throws ReplayLogError
// naming the record number (1-based).
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "mapping/ekf_slam.h"

namespace slamo::mapping {

// A log that cannot be read: the message names the file and the line or record.
class ReplayLogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One event of a run: an odometry step or a measurement, at t_s.
struct LogEvent {
  double t_s = 0.0;
  std::variant<OdometryStep, RangeBearing> data;

  bool is_odometry() const { return std::holds_alternative<OdometryStep>(data); }
  const OdometryStep& odometry() const { return std::get<OdometryStep>(data); }
  const RangeBearing& measurement() const { return std::get<RangeBearing>(data); }
};

struct ReplayLog {
  std::optional<Eigen::Vector3d> start_pose;  // x_m, y_m, theta_rad from a `start` line
  std::vector<LogEvent> events;               // in time order
  // The longest range the log's sensor says it measures (an MRPT bearing-range observation's
  // maxSensorDistance), when it says.
  std::optional<double> sensor_max_range_m;
};

struct ReplayLogOptions {
  double sigma_range_m = 0.05;      // for obs lines without sigmas
  double sigma_bearing_rad = 0.03;  // for obs lines without sigmas
  // A rawlog is first read whole in a child process (platform/rawlog_guard.h); one that takes
  // longer than this is reported as hanging MRPT's deserialiser (a ReplayLogError).
  double rawlog_check_timeout_s = 120.0;
};

// The text format above.
ReplayLog ReadTextLog(const std::string& path, const ReplayLogOptions& options = {});
// Writes odometry in the increment form and measurements with their sigmas (the square roots
// of the covariance diagonal; a correlation is not kept). Throws std::runtime_error.
void WriteTextLog(const std::string& path, const ReplayLog& log);

// An MRPT rawlog (gzip-compressed or not). The options' sigmas stand in for a bearing-range
// sensor that gives none.
ReplayLog ReadRawlog(const std::string& path, const ReplayLogOptions& options = {});
// Writes a rawlog in the action / sensory-frame layout: each odometry step as a
// CActionRobotMovement2D, each measurement as a CObservationBearingRange with a sensor at the
// robot centre (ranges and bearings are stored as float). The start pose is not kept.
void WriteRawlog(const std::string& path, const ReplayLog& log);

// A rawlog when the name ends in .rawlog or .rawlog.gz or the file starts with the gzip magic
// bytes; otherwise the text format.
ReplayLog ReadReplayLog(const std::string& path, const ReplayLogOptions& options = {});

}  // namespace slamo::mapping
