// Pure motor maths shared by the simulator and the firmware model: the servo PWM convention of
// the VEX Motor Controller 29 and its inverse, the PID step the board runs, and a first-order
// motor response. No state beyond what the caller passes in.
#pragma once

#include "field_configs/robot_config.h"

namespace slamo::platform {

// Steady-state speed fraction in [-1, 1] (positive forward) that `pwm` produces: 0 within
// the deadband around stop, then ((|offset| - deadband) / (span - deadband))^curve_exponent,
// saturating at +-1 at and beyond full_forward / full_reverse.
double PwmToSpeedFraction(const field::PwmConvention& pwm, int pwm_value);

// Inverse of PwmToSpeedFraction before rounding: the signed PWM offset from stop (positive
// towards full_forward, in PWM units) that yields `fraction`; 0 for 0, saturating at +-1.
double SpeedFractionToPwmOffset(const field::PwmConvention& pwm, double fraction);

// A signed PWM offset (positive towards full_forward) -> the PWM value, rounded to the
// nearest integer and saturated at full_forward / full_reverse.
int PwmFromOffset(const field::PwmConvention& pwm, double offset);

// SpeedFractionToPwmOffset then PwmFromOffset.
int SpeedFractionToPwm(const field::PwmConvention& pwm, double fraction);

struct PidState {
  double integral = 0.0;
  double prev_error = 0.0;
};

// One PID step: returns kp*e + ki*integral + kd*de/dt with the integral clamped so that
// |ki * integral| <= gains.integral_limit (anti-windup; a limit of 0 means no clamp).
// With dt_s <= 0 only the proportional term acts and the state is left unchanged.
double PidStep(const field::PidGains& gains, double error, double dt_s, PidState* state);

struct MotorResponseOptions {
  double time_constant_s = 0.08;  // first-order lag of wheel speed behind its steady value (s)
};

// Wheel speed after dt_s of first-order lag from speed_mps toward steady_mps (exact
// discretisation, so any dt_s is stable).
double MotorResponseStep(double speed_mps, double steady_mps, double dt_s,
                         const MotorResponseOptions& options);

}  // namespace slamo::platform
