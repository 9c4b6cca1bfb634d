#include "platform/sim/sim_drive.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace slamo::platform {
namespace {

// Floating-point slack when sub-steps land on a firmware tick.
constexpr double kTimeEpsilonS = 1e-9;

}  // namespace

SimDriveOptions SimDriveOptionsFor(const field::DriveConfig& drive) {
  SimDriveOptions options;
  if (!drive.slip) return options;
  const field::SlipConfig& s = *drive.slip;
  options.motor.time_constant_s = s.motor_time_constant_s;
  options.straight_slip.mean = s.straight_mean;
  options.straight_slip.stddev = s.straight_stddev;
  options.differential_slip.stddev = s.side_stddev;
  options.turn_slip.mean = s.turn_mean;
  options.turn_slip.stddev = s.turn_stddev;
  options.pivot_offset_m.mean = s.pivot_offset_m;
  options.pivot_offset_m.stddev = s.pivot_stddev_m;
  return options;
}

SimDriveBase::SimDriveBase(const field::DriveConfig& drive, const SimDriveOptions& options,
                           uint64_t seed, const Pose2D& start)
    : drive_(drive),
      options_(options),
      rng_(seed),
      metres_per_tick_(kPi * drive.wheel_diameter_m / drive.encoder_ticks_per_rev),
      pid_period_s_(1.0 / drive.pid.rate_hz),
      time_to_firmware_tick_s_(1.0 / drive.pid.rate_hz),
      true_pose_(start),
      odometry_pose_(start) {
  if (!(drive.wheel_diameter_m > 0.0 && drive.encoder_ticks_per_rev > 0.0 &&
        drive.track_width_m > 0.0 && drive.pid.rate_hz > 0.0 && options.physics_dt_s > 0.0)) {
    std::fprintf(stderr,
                 "SimDriveBase: drive config not validated (wheel, encoder, track, "
                 "pid rate and physics_dt_s must be positive)\n");
    std::abort();
  }
  left_.motor_gain = options.left_motor_gain;
  right_.motor_gain = options.right_motor_gain;
  left_.pwm = right_.pwm = drive.pwm.stop;
  straight_slip_.options = options.straight_slip;
  differential_slip_.options = options.differential_slip;
  turn_slip_.options = options.turn_slip;
  pivot_offset_.options = options.pivot_offset_m;
  // Slip starts from its stationary distribution so the first seconds are typical too.
  for (SlipProcess* slip : {&straight_slip_, &differential_slip_, &turn_slip_, &pivot_offset_}) {
    slip->deviation = slip->options.stddev * normal_(rng_);
  }
}

void SimDriveBase::SetSpeedTargets(double left_mps, double right_mps) {
  speed_mode_ = true;
  left_.target_mps = left_mps;
  right_.target_mps = right_mps;
}

void SimDriveBase::SetPwm(int left, int right) {
  speed_mode_ = false;
  left_.pwm = left;
  right_.pwm = right;
}

void SimDriveBase::Stop() {
  speed_mode_ = false;
  for (Side* side : {&left_, &right_}) {
    side->target_mps = 0.0;
    side->pwm = drive_.pwm.stop;
    side->pid = PidState{};
  }
}

EncoderTicks SimDriveBase::ReadEncoders() { return {time_s_, left_.ticks, right_.ticks}; }

void SimDriveBase::Step(double dt_s) {
  if (!(dt_s >= 0.0)) {
    std::fprintf(stderr, "SimDriveBase::Step: dt_s must be >= 0, got %g\n", dt_s);
    std::abort();
  }
  double remaining_s = dt_s;
  while (remaining_s > kTimeEpsilonS) {
    const double h_s =
        std::min({remaining_s, options_.physics_dt_s, std::max(time_to_firmware_tick_s_, 0.0)});
    Integrate(h_s);
    remaining_s -= h_s;
    time_s_ += h_s;
    time_to_firmware_tick_s_ -= h_s;
    if (time_to_firmware_tick_s_ <= kTimeEpsilonS) {
      RunFirmwareTick();
      time_to_firmware_tick_s_ += pid_period_s_;
    }
  }
}

void SimDriveBase::RunFirmwareTick() {
  for (Side* side : {&left_, &right_}) {
    if (speed_mode_) FirmwareSide(side);
    side->ticks_at_last_tick = side->ticks;
  }
}

// The board's speed loop for one side: speed measured from encoder ticks since the last
// tick, PID (plus the nominal PWM for the target as feedforward) -> PWM. A zero target
// stops the motor and resets the loop.
void SimDriveBase::FirmwareSide(Side* side) {
  if (side->target_mps == 0.0) {
    side->pwm = drive_.pwm.stop;
    side->pid = PidState{};
    return;
  }
  const double measured_mps = static_cast<double>(side->ticks - side->ticks_at_last_tick) *
                              metres_per_tick_ / pid_period_s_;
  double offset = PidStep(drive_.pid, side->target_mps - measured_mps, pid_period_s_, &side->pid);
  if (options_.speed_feedforward) {
    offset += SpeedFractionToPwmOffset(drive_.pwm, side->target_mps / drive_.max_speed_mps);
  }
  side->pwm = PwmFromOffset(drive_.pwm, offset);
}

void SimDriveBase::AdvanceSide(double dt_s, Side* side) {
  // Motor: first-order lag toward the steady speed of the applied PWM.
  const double steady_mps =
      drive_.max_speed_mps * side->motor_gain * PwmToSpeedFraction(drive_.pwm, side->pwm);
  const double before_mps = side->wheel_speed_mps;
  side->wheel_speed_mps = MotorResponseStep(before_mps, steady_mps, dt_s, options_.motor);
  // Encoder: counts wheel rotation, whatever the ground does.
  const double radius_m = 0.5 * drive_.wheel_diameter_m;
  side->wheel_angle_rad += 0.5 * (before_mps + side->wheel_speed_mps) * dt_s / radius_m;
  side->ticks = static_cast<int64_t>(
      std::floor(side->wheel_angle_rad / (2.0 * kPi) * drive_.encoder_ticks_per_rev));
}

void SimDriveBase::AdvanceSlip(double dt_s, SlipProcess* slip) {
  if (slip->options.stddev <= 0.0 || slip->options.correlation_time_s <= 0.0) {
    slip->deviation = 0.0;
    return;
  }
  const double keep = std::exp(-dt_s / slip->options.correlation_time_s);
  slip->deviation =
      keep * slip->deviation + slip->options.stddev * std::sqrt(1.0 - keep * keep) * normal_(rng_);
}

void SimDriveBase::Integrate(double dt_s) {
  // Wheels and encoders.
  const int64_t left_ticks_before = left_.ticks;
  const int64_t right_ticks_before = right_.ticks;
  const double left_before_mps = left_.wheel_speed_mps;
  const double right_before_mps = right_.wheel_speed_mps;
  AdvanceSide(dt_s, &left_);
  AdvanceSide(dt_s, &right_);
  for (SlipProcess* slip : {&straight_slip_, &differential_slip_, &turn_slip_, &pivot_offset_}) {
    AdvanceSlip(dt_s, slip);
  }

  // Body motion the wheels ask for (mean wheel speeds over the sub-step).
  const double left_mps = 0.5 * (left_before_mps + left_.wheel_speed_mps);
  const double right_mps = 0.5 * (right_before_mps + right_.wheel_speed_mps);
  const double wheel_forward_mps = 0.5 * (left_mps + right_mps);
  const double wheel_yaw_rate_rps = (right_mps - left_mps) / drive_.track_width_m;

  // Slip: what the ground actually does.
  const double forward_mps =
      wheel_forward_mps * (1.0 - std::clamp(straight_slip_.value(), -0.5, 0.95));
  const double yaw_rate_rps =
      wheel_yaw_rate_rps * (1.0 - std::clamp(turn_slip_.value(), -0.5, 0.95)) +
      differential_slip_.value() * wheel_forward_mps / drive_.track_width_m;
  // Turning about a pivot ahead of the centre moves the centre sideways (body frame).
  const double lateral_mps = -yaw_rate_rps * pivot_offset_.value();

  // True pose (midpoint heading), unless the new pose is blocked.
  const double dtheta_rad = yaw_rate_rps * dt_s;
  const double mid_rad = true_pose_.theta_rad + 0.5 * dtheta_rad;
  const double c = std::cos(mid_rad);
  const double s = std::sin(mid_rad);
  const Pose2D next{true_pose_.x_m + (forward_mps * c - lateral_mps * s) * dt_s,
                    true_pose_.y_m + (forward_mps * s + lateral_mps * c) * dt_s,
                    WrapAngleRad(true_pose_.theta_rad + dtheta_rad)};
  if (!is_free_ || is_free_(next)) true_pose_ = next;

  // Encoder dead reckoning.
  odometry_pose_ =
      IntegrateOdometry(odometry_pose_, left_.ticks - left_ticks_before,
                        right_.ticks - right_ticks_before, metres_per_tick_, drive_.track_width_m);
}

}  // namespace slamo::platform
