#include "platform/motor.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace slamo::platform {
namespace {

// +1 if moving from stop towards `end` increases the PWM value, else -1.
int Direction(int stop, int end) { return end > stop ? 1 : -1; }

}  // namespace

double PwmToSpeedFraction(const field::PwmConvention& pwm, int pwm_value) {
  const int forward_offset = (pwm_value - pwm.stop) * Direction(pwm.stop, pwm.full_forward);
  if (forward_offset == 0) return 0.0;
  const bool forward = forward_offset > 0;
  const int span = std::abs((forward ? pwm.full_forward : pwm.full_reverse) - pwm.stop);
  const int magnitude = std::abs(pwm_value - pwm.stop);
  if (magnitude <= pwm.deadband || span <= pwm.deadband) return 0.0;
  const double x = std::min(1.0, static_cast<double>(magnitude - pwm.deadband) /
                                     static_cast<double>(span - pwm.deadband));
  const double fraction = std::pow(x, pwm.curve_exponent);
  return forward ? fraction : -fraction;
}

double SpeedFractionToPwmOffset(const field::PwmConvention& pwm, double fraction) {
  if (fraction == 0.0 || std::isnan(fraction)) return 0.0;
  const bool forward = fraction > 0.0;
  const double span = std::abs((forward ? pwm.full_forward : pwm.full_reverse) - pwm.stop);
  const double x = std::pow(std::min(1.0, std::abs(fraction)), 1.0 / pwm.curve_exponent);
  const double magnitude = pwm.deadband + x * (span - pwm.deadband);
  return forward ? magnitude : -magnitude;
}

int PwmFromOffset(const field::PwmConvention& pwm, double offset) {
  if (std::isnan(offset)) return pwm.stop;
  const bool forward = offset >= 0.0;
  const int end = forward ? pwm.full_forward : pwm.full_reverse;
  const double span = std::abs(end - pwm.stop);
  const double magnitude = std::min(span, std::abs(offset));
  return pwm.stop + Direction(pwm.stop, end) * static_cast<int>(std::lround(magnitude));
}

int SpeedFractionToPwm(const field::PwmConvention& pwm, double fraction) {
  return PwmFromOffset(pwm, SpeedFractionToPwmOffset(pwm, fraction));
}

double PidStep(const field::PidGains& gains, double error, double dt_s, PidState* state) {
  if (dt_s <= 0.0) return gains.kp * error;
  // Integrate, then clamp the integral term (not just the output) against wind-up.
  state->integral += error * dt_s;
  if (gains.integral_limit > 0.0 && gains.ki > 0.0) {
    const double max_integral = gains.integral_limit / gains.ki;
    state->integral = std::clamp(state->integral, -max_integral, max_integral);
  }
  const double derivative = (error - state->prev_error) / dt_s;
  state->prev_error = error;
  return gains.kp * error + gains.ki * state->integral + gains.kd * derivative;
}

double MotorResponseStep(double speed_mps, double steady_mps, double dt_s,
                         const MotorResponseOptions& options) {
  if (dt_s <= 0.0) return speed_mps;
  if (options.time_constant_s <= 0.0) return steady_mps;
  const double blend = 1.0 - std::exp(-dt_s / options.time_constant_s);
  return speed_mps + (steady_mps - speed_mps) * blend;
}

}  // namespace slamo::platform
