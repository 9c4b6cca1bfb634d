#include "platform/sim/sim_drive.h"

#include <gtest/gtest.h>

#include <cmath>

#include "field_configs/loader.h"

namespace slamo::platform {
namespace {

field::DriveConfig ThesisDrive() { return field::LoadRobotConfig("thesis_robot").drive; }

// Runs the speed loop at constant targets for duration_s and returns the mean wheel
// speeds measured by the encoders over the last second.
struct MeanSpeeds {
  double left_mps;
  double right_mps;
};
MeanSpeeds HoldSpeed(SimDriveBase* sim, double left_mps, double right_mps, double duration_s) {
  sim->SetSpeedTargets(left_mps, right_mps);
  const double dt_s = 0.01;
  for (double t = 0.0; t < duration_s - 1.0; t += dt_s) sim->Step(dt_s);
  const EncoderTicks before = sim->ReadEncoders();
  for (int i = 0; i < 100; ++i) sim->Step(dt_s);
  const EncoderTicks after = sim->ReadEncoders();
  const double span_s = after.t_s - before.t_s;
  return {static_cast<double>(after.left - before.left) * sim->metres_per_tick() / span_s,
          static_cast<double>(after.right - before.right) * sim->metres_per_tick() / span_s};
}

TEST(SimDriveTest, SpeedLoopReachesCruiseSpeed) {
  const field::DriveConfig drive = ThesisDrive();
  SimDriveBase sim(drive, SimDriveOptions{}, 1);
  const MeanSpeeds speeds = HoldSpeed(&sim, drive.cruise_speed_mps, drive.cruise_speed_mps, 4.0);
  EXPECT_NEAR(speeds.left_mps, 0.067, 0.002);
  EXPECT_NEAR(speeds.right_mps, 0.067, 0.002);
  EXPECT_NEAR(sim.left_wheel_speed_mps(), 0.067, 0.01);
  EXPECT_NEAR(sim.right_wheel_speed_mps(), 0.067, 0.01);
  // The PWM is on the forward side of stop (0 = full forward).
  EXPECT_LT(sim.left_pwm(), 90 - drive.pwm.deadband);
}

TEST(SimDriveTest, SpeedLoopMakesUpForWeakMotorsWithoutFeedforward) {
  const field::DriveConfig drive = ThesisDrive();
  SimDriveOptions options;
  options.speed_feedforward = false;
  options.left_motor_gain = 0.8;
  SimDriveBase sim(drive, options, 1);
  const MeanSpeeds speeds = HoldSpeed(&sim, 0.067, 0.067, 6.0);
  EXPECT_NEAR(speeds.left_mps, 0.067, 0.003);
  EXPECT_NEAR(speeds.right_mps, 0.067, 0.003);
}

TEST(SimDriveTest, ReverseAndTurnInPlace) {
  const field::DriveConfig drive = ThesisDrive();
  SimDriveBase sim(drive, SimDriveOptions{}, 2);
  const MeanSpeeds speeds = HoldSpeed(&sim, 0.05, -0.05, 3.0);
  EXPECT_NEAR(speeds.left_mps, 0.05, 0.003);
  EXPECT_NEAR(speeds.right_mps, -0.05, 0.003);
  EXPECT_GT(sim.right_pwm(), 90);  // reverse side of stop
  // Clockwise turn: odometry heading goes negative.
  EXPECT_LT(sim.odometry_pose().theta_rad, -0.1);
  EXPECT_LT(sim.true_pose().theta_rad, -0.1);
}

TEST(SimDriveTest, OpenLoopPwmAndStop) {
  const field::DriveConfig drive = ThesisDrive();
  SimDriveBase sim(drive, SimDriveOptions{}, 3);
  sim.SetPwm(0, 0);  // full forward
  for (int i = 0; i < 200; ++i) sim.Step(0.01);
  EXPECT_NEAR(sim.left_wheel_speed_mps(), drive.max_speed_mps, 1e-3);
  EXPECT_NEAR(sim.right_wheel_speed_mps(), drive.max_speed_mps * SimDriveOptions{}.right_motor_gain,
              1e-3);
  sim.Stop();
  for (int i = 0; i < 200; ++i) sim.Step(0.01);
  EXPECT_NEAR(sim.left_wheel_speed_mps(), 0.0, 1e-6);
  const EncoderTicks stopped = sim.ReadEncoders();
  sim.Step(1.0);
  EXPECT_EQ(sim.ReadEncoders().left, stopped.left);
  EXPECT_NEAR(sim.ReadEncoders().t_s, 5.0, 1e-9);
  // Within the deadband nothing turns.
  sim.SetPwm(90 - drive.pwm.deadband, 90 + drive.pwm.deadband);
  sim.Step(1.0);
  EXPECT_EQ(sim.ReadEncoders().left, stopped.left);
  EXPECT_EQ(sim.ReadEncoders().right, stopped.right);
}

TEST(SimDriveTest, EncodersCountWheelRotationNotGroundMotion) {
  const field::DriveConfig drive = ThesisDrive();
  SimDriveOptions options;
  options.straight_slip = {0.2, 0.0, 3.0};
  options.differential_slip = {0.0, 0.0, 3.0};
  SimDriveBase sim(drive, options, 4);
  sim.SetSpeedTargets(0.067, 0.067);
  for (int i = 0; i < 500; ++i) sim.Step(0.01);
  const double encoder_m = 0.5 *
                           static_cast<double>(sim.ReadEncoders().left + sim.ReadEncoders().right) *
                           sim.metres_per_tick();
  EXPECT_NEAR(sim.odometry_pose().x_m, encoder_m, 2e-3);
  EXPECT_NEAR(sim.true_pose().x_m, 0.8 * sim.odometry_pose().x_m, 2e-3);
  // Quantised: one tick is pi * 2.75 in / 627.2.
  EXPECT_NEAR(sim.metres_per_tick(), 3.14159265 * 0.06985 / 627.2, 1e-9);
}

TEST(SimDriveTest, SameSeedSameRunDifferentSeedDifferentRun) {
  const field::DriveConfig drive = ThesisDrive();
  const auto run = [&](uint64_t seed) {
    SimDriveBase sim(drive, SimDriveOptions{}, seed);
    sim.SetSpeedTargets(0.067, 0.06);
    for (int i = 0; i < 300; ++i) sim.Step(0.013);  // steps not aligned with the PID period
    return sim.true_pose();
  };
  const Pose2D a = run(7);
  const Pose2D b = run(7);
  const Pose2D c = run(8);
  EXPECT_EQ(a.x_m, b.x_m);
  EXPECT_EQ(a.y_m, b.y_m);
  EXPECT_EQ(a.theta_rad, b.theta_rad);
  EXPECT_NE(a.x_m, c.x_m);
}

TEST(SimDriveTest, BlockedRobotStaysPutWhileWheelsSpin) {
  const field::DriveConfig drive = ThesisDrive();
  SimDriveBase sim(drive, SimDriveOptions{}, 5);
  sim.SetFreeSpaceCheck([](const Pose2D& pose) { return pose.x_m < 0.05; });  // wall at 5 cm
  sim.SetSpeedTargets(0.067, 0.067);
  for (int i = 0; i < 400; ++i) sim.Step(0.01);
  EXPECT_LT(sim.true_pose().x_m, 0.05);
  EXPECT_GT(sim.true_pose().x_m, 0.04);
  EXPECT_GT(sim.odometry_pose().x_m, 0.2);  // the encoders believe it kept going
}

TEST(SimDriveDeathTest, NegativeStepAborts) {
  SimDriveBase sim(ThesisDrive(), SimDriveOptions{}, 1);
  EXPECT_DEATH(sim.Step(-1.0), "dt_s must be >= 0");
}

}  // namespace
}  // namespace slamo::platform
