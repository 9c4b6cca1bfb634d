// Drive scripts: "forward 0.3; turn 90; back 0.2; wait 1" parsed into steps and driven on any
// DriveBase (the simulator's: platform/sim/sim_drive_script.h) by a closed-loop controller that
// knows the encoders, and a yaw gyro when the link has one (turn, then drive holding heading,
// with speed ramps), the way the real robot will be driven. After each step the result holds
// the true pose and the encoder-odometry pose.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "field_configs/robot_config.h"
#include "platform/clock.h"
#include "platform/drive_base.h"

namespace slamo::platform {

// A script that does not parse; the message names the statement and the bad token.
class DriveScriptError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

enum class DriveStepKind {
  kDrive,  // straight: amount in metres, negative = backwards ("back")
  kTurn,   // in place: amount in degrees, counter-clockwise positive
  kWait,   // stopped: amount in seconds
};

struct DriveStep {
  DriveStepKind kind = DriveStepKind::kWait;
  double amount = 0.0;  // m, deg or s by kind
  std::string text;     // the statement as written, for reports
};

// Statements are separated by ';' or newlines; each is one of "forward M", "back M",
// "turn DEG", "wait S" (M > 0 metres, S >= 0 seconds). Throws DriveScriptError.
std::vector<DriveStep> ParseDriveScript(const std::string& script);

struct DriveControllerOptions {
  double cruise_speed_mps = 0.067;  // wheel speed when driving and turning (m/s)
  double accel_mps2 = 0.5;          // ramp up and down (m/s^2)
  // Lowest commanded speed before the target (m/s): the ramp down otherwise ends in a crawl
  // the motors' deadband stretches to seconds. 0: ramp all the way down.
  double min_speed_mps = 0.0;
  double control_dt_s = 0.02;        // controller period (s)
  double heading_gain_per_s = 2.0;   // yaw-rate command per radian of heading error (1/s)
  double align_tolerance_deg = 1.0;  // a drive turns first if the heading is off by more (deg)
  double stop_lead_s = 0.05;         // stop this long before the target at the commanded speed (s)
  // A turn is cut stop_lead_s before its target at the measured turning speed when that is the
  // faster (the wheels trail the ramp down): less overshoot, fewer correcting turns. Off: at
  // the commanded speed.
  bool lead_on_measured_speed = false;
  double settle_s = 0.1;  // encoders still this long ends a step (s)...
  // ...or, when above 0, moving at most this many ticks per wheel over the last settle_s (by
  // the readings' clock, back and forth counted). A first-order motor lag with time constant
  // tau coasts speed x tau once cut, and over a window T >= tau it covers speed x tau x
  // (e^(T/tau) - 1), at least 1.7 times that; so with settle_s at the time constant (rounded up
  // to control periods) and 1 tick measured (under 2 travelled), what is left to coast is
  // about a tick, which the odometry counts into the next step. Waiting for the coast's last
  // tick takes 4-6 time constants more.
  int settle_ticks = 0;
  double max_settle_s = 2.0;       // give up waiting for the wheels to stop after this (s)
  double timeout_factor = 3.0;     // a step times out after this times its nominal duration...
  double timeout_margin_s = 10.0;  // ...plus this (s)
  // The match's end on the clock (s): motion is commanded to stop when the clock reaches it,
  // whatever the step; later steps do not start. Infinite: no deadline.
  double hard_deadline_s = std::numeric_limits<double>::infinity();
};

// Cruise speed and acceleration from the robot's drive config, other fields defaulted.
DriveControllerOptions DriveControllerOptionsFor(const field::DriveConfig& drive);

enum class DriveStepStatus {
  kDone,
  kTimedOut,  // the step's own timeout
  kDeadline,  // stopped (or not started) at options.hard_deadline_s
};

struct DriveStepResult {
  DriveStep step;
  DriveStepStatus status = DriveStepStatus::kDone;
  double end_time_s = 0.0;
  Pose2D true_pose;         // ground truth from the simulator (the odometry when unknown)
  bool truth_known = true;  // false on hardware
  Pose2D odometry_pose;     // what the encoders say (the controller's dead reckoning)
};

// A correction of a straight drive under way (DriveBodyLink::correct).
struct DriveCorrection {
  double heading_change_rad = 0.0;
  double remaining_m = 0.0;
};

// What the controller drives: any DriveBase (the simulator's, the serial link to the board),
// its wheel geometry, the clock, and how time passes. `advance(dt_s)` must let dt_s pass on
// `clock` (step the simulator and advance a SimClock; or service the link until a real clock
// has moved on). `truth`, when known (the simulator), fills DriveStepResult::true_pose.
struct DriveBodyLink {
  DriveBase* base = nullptr;
  double metres_per_tick = 0.0;
  double track_width_m = 0.0;
  Pose2D odometry_start;  // the dead reckoning's start (only headings matter to the controller)
  const Clock* clock = nullptr;
  std::function<void(double)> advance;
  std::function<Pose2D()> truth;
  // A yaw gyro's heading (rad, counter-clockwise positive as the odometry's; only its changes
  // matter), when the robot has one: turns and the
  // heading held on a drive are then closed on it, as V5 teams turn on the inertial sensor,
  // not on the encoders, whose turn is wrong whenever a wheel slips. A reading of nothing (or
  // no function) leaves that period to the encoders.
  std::function<std::optional<double>()> gyro;
  // Polled every period of a straight drive: a correction from outside the controller (SLAM-O's
  // estimate, which sees where the body went when the wheels slipped). The drive then holds its
  // current heading turned by heading_change_rad and has remaining_m (>= 0, encoder metres)
  // still to go in its own direction. Nothing: carry on.
  std::function<std::optional<DriveCorrection>()> correct;
};

// Drives `steps` on `body`. Throws std::invalid_argument for a link without a base, clock or
// advance function, or without a wheel geometry.
std::vector<DriveStepResult> RunDriveScript(const std::vector<DriveStep>& steps,
                                            const DriveControllerOptions& options,
                                            const DriveBodyLink& body);

}  // namespace slamo::platform
