#include "platform/motor.h"

#include <gtest/gtest.h>

#include <cmath>

#include "field_configs/loader.h"

namespace slamo::platform {
namespace {

field::PwmConvention ThesisPwm() { return field::LoadRobotConfig("thesis_robot").drive.pwm; }

TEST(PwmTest, EndpointsAndStop) {
  const field::PwmConvention pwm = ThesisPwm();
  EXPECT_DOUBLE_EQ(PwmToSpeedFraction(pwm, 0), 1.0);
  EXPECT_DOUBLE_EQ(PwmToSpeedFraction(pwm, 90), 0.0);
  EXPECT_DOUBLE_EQ(PwmToSpeedFraction(pwm, 180), -1.0);
  // Saturation beyond the endpoints.
  EXPECT_DOUBLE_EQ(PwmToSpeedFraction(pwm, -20), 1.0);
  EXPECT_DOUBLE_EQ(PwmToSpeedFraction(pwm, 255), -1.0);
  EXPECT_EQ(SpeedFractionToPwm(pwm, 1.0), 0);
  EXPECT_EQ(SpeedFractionToPwm(pwm, 0.0), 90);
  EXPECT_EQ(SpeedFractionToPwm(pwm, -1.0), 180);
  EXPECT_EQ(SpeedFractionToPwm(pwm, 3.0), 0);
  EXPECT_EQ(SpeedFractionToPwm(pwm, -3.0), 180);
}

TEST(PwmTest, DeadbandDoesNotTurnTheMotor) {
  const field::PwmConvention pwm = ThesisPwm();
  ASSERT_EQ(pwm.deadband, 8);
  for (int value = 90 - 8; value <= 90 + 8; ++value) {
    EXPECT_EQ(PwmToSpeedFraction(pwm, value), 0.0) << "pwm " << value;
  }
  EXPECT_GT(PwmToSpeedFraction(pwm, 90 - 9), 0.0);
  EXPECT_LT(PwmToSpeedFraction(pwm, 90 + 9), 0.0);
}

TEST(PwmTest, MonotonicAndNonlinear) {
  const field::PwmConvention pwm = ThesisPwm();
  for (int value = 0; value < 180; ++value) {
    EXPECT_GE(PwmToSpeedFraction(pwm, value), PwmToSpeedFraction(pwm, value + 1)) << value;
  }
  // curve_exponent 1.6: half way through the live range gives 0.5^1.6 of full speed.
  const int half = 90 - (8 + 41);  // offset 49 = deadband + half of (90 - 8)
  EXPECT_NEAR(PwmToSpeedFraction(pwm, half), std::pow(0.5, 1.6), 1e-12);
  EXPECT_NEAR(PwmToSpeedFraction(pwm, 180 - half), -std::pow(0.5, 1.6), 1e-12);
}

TEST(PwmTest, InverseRoundTrip) {
  const field::PwmConvention pwm = ThesisPwm();
  // Every PWM that turns the motor maps back to itself.
  for (int value = 0; value <= 180; ++value) {
    if (std::abs(value - 90) <= pwm.deadband) continue;
    EXPECT_EQ(SpeedFractionToPwm(pwm, PwmToSpeedFraction(pwm, value)), value);
  }
  // Fractions come back exactly through the continuous offset.
  for (double fraction = -1.0; fraction <= 1.0; fraction += 0.05) {
    const double offset = SpeedFractionToPwmOffset(pwm, fraction);
    const double back =
        std::pow((std::abs(offset) - pwm.deadband) / (90.0 - pwm.deadband), pwm.curve_exponent);
    if (std::abs(fraction) > 1e-9) {
      EXPECT_NEAR(std::copysign(back, offset), fraction, 1e-9);
    }
  }
}

TEST(PwmTest, ReversedConvention) {
  field::PwmConvention pwm;
  pwm.full_forward = 180;
  pwm.stop = 90;
  pwm.full_reverse = 0;
  pwm.deadband = 3;
  pwm.curve_exponent = 1.0;
  EXPECT_DOUBLE_EQ(PwmToSpeedFraction(pwm, 180), 1.0);
  EXPECT_DOUBLE_EQ(PwmToSpeedFraction(pwm, 0), -1.0);
  EXPECT_EQ(SpeedFractionToPwm(pwm, 1.0), 180);
  EXPECT_EQ(PwmFromOffset(pwm, -10.0), 80);
}

TEST(PidTest, ProportionalIntegralDerivative) {
  field::PidGains gains;
  gains.kp = 2.0;
  gains.ki = 10.0;
  gains.kd = 0.5;
  PidState state;
  // integral 0.1*1 = 0.1; derivative (1 - 0) / 0.1 = 10.
  EXPECT_DOUBLE_EQ(PidStep(gains, 1.0, 0.1, &state), 2.0 + 1.0 + 5.0);
  EXPECT_DOUBLE_EQ(state.integral, 0.1);
  EXPECT_DOUBLE_EQ(state.prev_error, 1.0);
  // Same error again: no derivative, integral grows.
  EXPECT_DOUBLE_EQ(PidStep(gains, 1.0, 0.1, &state), 2.0 + 2.0);
}

TEST(PidTest, IntegralLimitStopsWindup) {
  field::PidGains gains;
  gains.kp = 0.0;
  gains.ki = 300.0;
  gains.integral_limit = 60.0;
  PidState state;
  double output = 0.0;
  for (int i = 0; i < 1000; ++i) output = PidStep(gains, 1.0, 0.02, &state);
  EXPECT_DOUBLE_EQ(output, 60.0);
  EXPECT_DOUBLE_EQ(state.integral, 0.2);
  // Unwinds at once when the error changes sign: not 1000 steps of stored integral.
  for (int i = 0; i < 20; ++i) output = PidStep(gains, -1.0, 0.02, &state);
  EXPECT_LT(output, 0.0);
  for (int i = 0; i < 1000; ++i) output = PidStep(gains, -1.0, 0.02, &state);
  EXPECT_DOUBLE_EQ(output, -60.0);
}

TEST(PidTest, NoLimitAndZeroDt) {
  field::PidGains gains;
  gains.kp = 1.0;
  gains.ki = 1.0;
  PidState state;
  for (int i = 0; i < 100; ++i) PidStep(gains, 1.0, 1.0, &state);
  EXPECT_DOUBLE_EQ(state.integral, 100.0);  // integral_limit 0 = no clamp
  EXPECT_DOUBLE_EQ(PidStep(gains, 3.0, 0.0, &state), 3.0);
  EXPECT_DOUBLE_EQ(state.integral, 100.0);
}

TEST(PidTest, ClosedLoopOnAFirstOrderPlantSettles) {
  field::PidGains gains;
  gains.kp = 0.5;
  gains.ki = 5.0;
  PidState state;
  MotorResponseOptions motor;
  double speed = 0.0;
  for (int i = 0; i < 500; ++i) {
    const double command = PidStep(gains, 1.0 - speed, 0.01, &state);
    speed = MotorResponseStep(speed, command, 0.01, motor);
  }
  EXPECT_NEAR(speed, 1.0, 1e-3);
}

TEST(MotorResponseTest, FirstOrderLag) {
  MotorResponseOptions motor;
  motor.time_constant_s = 0.1;
  EXPECT_NEAR(MotorResponseStep(0.0, 1.0, 0.1, motor), 1.0 - std::exp(-1.0), 1e-12);
  // Sub-stepping gives the same answer (exact discretisation).
  double speed = 0.0;
  for (int i = 0; i < 10; ++i) speed = MotorResponseStep(speed, 1.0, 0.01, motor);
  EXPECT_NEAR(speed, 1.0 - std::exp(-1.0), 1e-12);
  motor.time_constant_s = 0.0;
  EXPECT_DOUBLE_EQ(MotorResponseStep(0.3, 1.0, 0.01, motor), 1.0);
}

}  // namespace
}  // namespace slamo::platform
