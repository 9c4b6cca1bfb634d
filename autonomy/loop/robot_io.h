// What a match runs on, below SLAM-O and the executive: the drive base and its encoders, the
// camera, the intake, a yaw gyro when there is one, and the passing of time. MatchWorld sees
// the robot only through this, so the same match loop runs on the simulated field (SimIo: a
// dry run) and on the robot (HardwareIo, autonomy/hardware_io.h: the board over its serial
// link and a camera). Only the simulator knows the truth (true pose, points); on hardware
// those are unknown and reported as such.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "platform/clock.h"
#include "platform/drive_base.h"
#include "platform/drive_script.h"
#include "platform/rgbd.h"
#include "strategy/strategy.h"

namespace slamo::autonomy {

// An object where it really is, when that is known (the simulator): for the report and the
// replay, never for steering.
struct TrueObject {
  int id = 0;  // 1-based, stable for the run
  std::string kind;
  std::string colour;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  // centre of the object's bounding box
  double radius_m = 0.0;                               // half the object type's size
  bool held = false;                                   // in the robot's intake: not on the field
  int in_goal = -1;  // index into SeasonConfig::goals when released into a goal structure
};

// What the intake holds after a pick (or the preload).
struct IntakeItem {
  std::string kind;
  std::string colour;
  bool assumed = false;  // no intake sensor: the pick's target, taken on trust
};

// Where a released object went.
struct ReleaseOutcome {
  std::optional<int> goal_index;  // none: on the floor
  bool assumed = false;           // no sensor: the intended goal, taken on trust
};

class RobotIo {
 public:
  virtual ~RobotIo() = default;

  // Called once, first, by MatchWorld: the field as placed for this match, the robot as
  // driven in it, and the starting pose. The match clock reads 0 from here on.
  virtual void Start(const field::SeasonConfig& field, const field::RobotConfig& robot,
                     const platform::Pose2D& start) = 0;
  // Match time: 0 at Start().
  virtual const platform::Clock& clock() const = 0;
  virtual platform::DriveBase& drive() = 0;
  // Lets dt_s of match time pass (the simulator steps; on hardware the board's link is
  // serviced while the clock runs on).
  virtual void Advance(double dt_s) = 0;
  // Encoder dead reckoning since Start(), in the field frame.
  virtual platform::Pose2D OdometryPose() const = 0;
  // Whether either motor is driven (PWM not at stop) now.
  virtual bool MotorsDriven() const = 0;
  // A yaw gyro's heading (rad, unwrapped offsets allowed), when the robot has one.
  virtual std::optional<double> GyroHeadingRad() = 0;
  // The camera's frame now; nothing when the camera has none.
  virtual std::optional<platform::RgbdFrame> Capture() = 0;
  // A frame only if the camera has one ready, never waiting for it: frames taken while
  // driving, where the drive controller must get its period back (the simulator renders one
  // at once).
  virtual std::optional<platform::RgbdFrame> CaptureReady() { return Capture(); }
  // The intake, in front of `target`; nothing when it took nothing.
  virtual std::optional<IntakeItem> Pick(const strategy::ObjectBelief& target) = 0;
  // The release, aimed at goal `intended_goal` (-1: dropped on the floor); nothing when
  // nothing left the intake.
  virtual std::optional<ReleaseOutcome> Release(int intended_goal) = 0;
  // What was loaded by hand before the match.
  virtual std::optional<IntakeItem> Preload() const = 0;
  // True distance per encoder distance, as calibrated before the match.
  virtual double OdometryScale() = 0;

  // The truth, where it is known (the simulator).
  virtual std::optional<platform::Pose2D> TruePose() const = 0;
  virtual std::optional<int> Points() const = 0;
  // Every object of the field (held ones too), in a fixed order; nothing on hardware.
  virtual std::optional<std::vector<TrueObject>> TrueObjects() const { return std::nullopt; }
  // For reports: "simulated field", "board /dev/ttyACM0, camera recording rec/", ...
  virtual std::string Describe() const = 0;
  // Counters for the report (link losses, frames missed, ...); none on the simulator.
  virtual std::map<std::string, double> Status() const { return {}; }
};

// The drive controller's link to io's drive base (RunDriveScript): the robot's wheel geometry,
// the match clock, io.Advance as the passing of time, io's truth when it has one.
platform::DriveBodyLink DriveLinkFor(RobotIo& io, const field::RobotConfig& robot);

}  // namespace slamo::autonomy
