// The simulated drive base: skid-steer physics behind the DriveBase interface. It models the
// firmware's per-side PID speed loop at pid.rate_hz, the motors (PWM curve, first-order lag),
// wheel slip (systematic plus correlated random, separately for straight driving and turning),
// encoder quantisation of wheel rotation, the true pose and the encoder dead reckoning. It has
// no clock: its owner calls Step(dt_s) and keeps any SimClock in lockstep.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <utility>

#include "field_configs/robot_config.h"
#include "platform/drive_base.h"
#include "platform/motor.h"

namespace slamo::platform {

// A slowly varying random quantity: mean plus an Ornstein-Uhlenbeck deviation with the given
// stationary standard deviation and correlation time.
struct SlipProcessOptions {
  double mean = 0.0;
  double stddev = 0.0;
  double correlation_time_s = 3.0;  // s
};

// Defaults are calibrated for the thesis robot driven at 0.067 m/s by RunDriveScript: about
// 0.05 m odometry position error per 0.3 m straight, 2 deg heading-error spread (std dev)
// per 90 deg turn and 0.1 m of centre travel during a turn in place (thesis appendix B).
struct SimDriveOptions {
  MotorResponseOptions motor;
  double left_motor_gain = 1.0;    // actual / nominal steady speed at a PWM, left motors
  double right_motor_gain = 0.95;  // right motors (motors differ; the PID makes up for it)
  bool speed_feedforward = true;   // firmware adds the nominal PWM for the target to its PID
  double physics_dt_s = 0.005;     // largest integration sub-step (s)
  // Straight driving: fraction of the mean wheel travel the ground does not follow (the
  // encoders over-read distance).
  SlipProcessOptions straight_slip{0.165, 0.06, 3.0};
  // Straight driving: rotation the encoders do not see, as a fraction of forward travel over
  // the track width (one side slips more than the other).
  SlipProcessOptions differential_slip{0.0, 0.04, 3.0};
  // Turning: fraction of the encoder-derived rotation the body does not follow.
  SlipProcessOptions turn_slip{0.01, 0.03, 3.0};
  // Turning: grippy front and omni rear wheels make the robot pivot about a point this far
  // ahead of its centre (m), so the centre sweeps sideways during a turn in place.
  SlipProcessOptions pivot_offset_m{0.07, 0.01, 3.0};
};

// The defaults above with the robot file's slip model (drive.slip) when it has one.
SimDriveOptions SimDriveOptionsFor(const field::DriveConfig& drive);

class SimDriveBase : public DriveBase {
 public:
  SimDriveBase(const field::DriveConfig& drive, const SimDriveOptions& options, uint64_t seed,
               const Pose2D& start = {});

  // DriveBase
  void SetSpeedTargets(double left_mps, double right_mps) override;
  void SetPwm(int left, int right) override;
  void Stop() override;
  EncoderTicks ReadEncoders() override;

  // Advances the physics by dt_s (>= 0), running the firmware's PID ticks that fall inside.
  void Step(double dt_s);

  // Collision hook: a pose the robot would move to is accepted only if is_free(pose); if
  // not, the robot stays put and its wheels slip (the encoders still count). Empty = free.
  void SetFreeSpaceCheck(std::function<bool(const Pose2D&)> is_free) {
    is_free_ = std::move(is_free);
  }

  const Pose2D& true_pose() const { return true_pose_; }
  const Pose2D& odometry_pose() const { return odometry_pose_; }
  double time_s() const { return time_s_; }
  double left_wheel_speed_mps() const { return left_.wheel_speed_mps; }
  double right_wheel_speed_mps() const { return right_.wheel_speed_mps; }
  int left_pwm() const { return left_.pwm; }
  int right_pwm() const { return right_.pwm; }
  double metres_per_tick() const { return metres_per_tick_; }
  const field::DriveConfig& drive() const { return drive_; }

 private:
  struct Side {
    double motor_gain = 1.0;
    double target_mps = 0.0;
    int pwm = 90;
    double wheel_speed_mps = 0.0;
    double wheel_angle_rad = 0.0;  // cumulative rotation, positive forward
    int64_t ticks = 0;
    int64_t ticks_at_last_tick = 0;  // at the previous firmware tick
    PidState pid;
  };
  struct SlipProcess {
    SlipProcessOptions options;
    double deviation = 0.0;
    double value() const { return options.mean + deviation; }
  };

  void RunFirmwareTick();
  void FirmwareSide(Side* side);
  void Integrate(double dt_s);
  void AdvanceSide(double dt_s, Side* side);
  void AdvanceSlip(double dt_s, SlipProcess* slip);

  field::DriveConfig drive_;
  SimDriveOptions options_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::function<bool(const Pose2D&)> is_free_;

  double metres_per_tick_;
  double pid_period_s_;
  bool speed_mode_ = false;  // speed targets through the PID, else raw PWM
  double time_s_ = 0.0;
  double time_to_firmware_tick_s_;
  Side left_;
  Side right_;
  SlipProcess straight_slip_;
  SlipProcess differential_slip_;
  SlipProcess turn_slip_;
  SlipProcess pivot_offset_;
  Pose2D true_pose_;
  Pose2D odometry_pose_;
};

}  // namespace slamo::platform
