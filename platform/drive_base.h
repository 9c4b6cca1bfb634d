// The drive base the rest of the system drives: wheel speed targets or raw PWM out, encoder
// ticks back. Commands are fire-and-forget and readings are timestamped plain structs, so the
// simulator and a serial link to the motor-controller board are interchangeable behind it.
// Also the dead reckoning every implementation shares.
#pragma once

#include <cmath>
#include <cstdint>

namespace slamo::platform {

inline constexpr double kPi = 3.14159265358979323846;

// A planar pose: metres, heading counter-clockwise from +x in radians.
struct Pose2D {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
};

// Cumulative encoder counts per side (positive forward) and when they were read.
struct EncoderTicks {
  double t_s = 0.0;
  int64_t left = 0;
  int64_t right = 0;
};

class DriveBase {
 public:
  virtual ~DriveBase() = default;
  // Wheel surface speed targets for the board's PID speed loop (m/s, positive forward).
  virtual void SetSpeedTargets(double left_mps, double right_mps) = 0;
  // Raw servo PWM per side, bypassing the speed loop (the robot's PwmConvention applies).
  virtual void SetPwm(int left, int right) = 0;
  // PWM to stop on both sides and the speed loop reset.
  virtual void Stop() = 0;
  virtual EncoderTicks ReadEncoders() = 0;
};

// Angle in (-pi, pi].
inline double WrapAngleRad(double angle_rad) {
  const double wrapped = std::remainder(angle_rad, 2.0 * kPi);
  return wrapped <= -kPi ? wrapped + 2.0 * kPi : wrapped;
}

// One dead-reckoning step of a differential drive from encoder tick increments (midpoint
// heading). metres_per_tick converts ticks to wheel surface travel.
inline Pose2D IntegrateOdometry(const Pose2D& pose, int64_t d_left_ticks, int64_t d_right_ticks,
                                double metres_per_tick, double track_width_m) {
  const double left_m = static_cast<double>(d_left_ticks) * metres_per_tick;
  const double right_m = static_cast<double>(d_right_ticks) * metres_per_tick;
  const double forward_m = 0.5 * (left_m + right_m);
  const double dtheta_rad = (right_m - left_m) / track_width_m;
  const double mid_rad = pose.theta_rad + 0.5 * dtheta_rad;
  return {pose.x_m + forward_m * std::cos(mid_rad), pose.y_m + forward_m * std::sin(mid_rad),
          WrapAngleRad(pose.theta_rad + dtheta_rad)};
}

// Encoder odometry: feed it every reading of a DriveBase; it integrates the increments.
class EncoderOdometry {
 public:
  EncoderOdometry(double metres_per_tick, double track_width_m, const EncoderTicks& first,
                  const Pose2D& start = {})
      : metres_per_tick_(metres_per_tick),
        track_width_m_(track_width_m),
        last_(first),
        pose_(start) {}

  const Pose2D& Update(const EncoderTicks& ticks) {
    pose_ = IntegrateOdometry(pose_, ticks.left - last_.left, ticks.right - last_.right,
                              metres_per_tick_, track_width_m_);
    last_ = ticks;
    return pose_;
  }
  const Pose2D& pose() const { return pose_; }
  const EncoderTicks& last() const { return last_; }

 private:
  double metres_per_tick_;
  double track_width_m_;
  EncoderTicks last_;
  Pose2D pose_;
};

}  // namespace slamo::platform
