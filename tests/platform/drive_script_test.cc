#include "platform/drive_script.h"

#include <gtest/gtest.h>
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "field_configs/loader.h"
#include "platform/sim/sim_drive_script.h"

namespace slamo::platform {
namespace {

constexpr double kDegPerRad = 180.0 / kPi;

TEST(ParseDriveScriptTest, ParsesAllCommands) {
  const std::vector<DriveStep> steps =
      ParseDriveScript("forward 0.3; turn 90;forward 0.6\n back 0.2 ;turn -90; wait 1.5;");
  ASSERT_EQ(steps.size(), 6u);
  EXPECT_EQ(steps[0].kind, DriveStepKind::kDrive);
  EXPECT_DOUBLE_EQ(steps[0].amount, 0.3);
  EXPECT_EQ(steps[0].text, "forward 0.3");
  EXPECT_EQ(steps[1].kind, DriveStepKind::kTurn);
  EXPECT_DOUBLE_EQ(steps[1].amount, 90.0);
  EXPECT_DOUBLE_EQ(steps[2].amount, 0.6);
  EXPECT_EQ(steps[3].kind, DriveStepKind::kDrive);
  EXPECT_DOUBLE_EQ(steps[3].amount, -0.2);
  EXPECT_DOUBLE_EQ(steps[4].amount, -90.0);
  EXPECT_EQ(steps[5].kind, DriveStepKind::kWait);
  EXPECT_DOUBLE_EQ(steps[5].amount, 1.5);
  EXPECT_TRUE(ParseDriveScript("  ;\n ").empty());
}

// The message of the DriveScriptError thrown for `script`, or "" if none.
std::string ErrorOf(const std::string& script) {
  try {
    ParseDriveScript(script);
  } catch (const DriveScriptError& error) {
    return error.what();
  }
  return "";
}

TEST(ParseDriveScriptTest, ErrorsNameTheBadToken) {
  EXPECT_EQ(ErrorOf("forward 0.3; jump 2"),
            "drive script statement 2 \"jump 2\": unknown command \"jump\" (expected forward, "
            "back, turn or wait)");
  EXPECT_EQ(ErrorOf("turn ninety"),
            "drive script statement 1 \"turn ninety\": expected an angle in degrees, got "
            "\"ninety\"");
  EXPECT_EQ(ErrorOf("forward 0.3m"),
            "drive script statement 1 \"forward 0.3m\": expected a distance in metres, got "
            "\"0.3m\"");
  EXPECT_EQ(ErrorOf("wait"),
            "drive script statement 1 \"wait\": missing a time in seconds "
            "after \"wait\"");
  EXPECT_EQ(ErrorOf("turn 90 left"),
            "drive script statement 1 \"turn 90 left\": unexpected "
            "\"left\"");
  EXPECT_EQ(ErrorOf("back -0.2"),
            "drive script statement 1 \"back -0.2\": expected a distance "
            "> 0, got \"-0.2\"");
  EXPECT_EQ(ErrorOf("wait -1"),
            "drive script statement 1 \"wait -1\": expected a time >= 0, "
            "got \"-1\"");
  EXPECT_NE(ErrorOf("forward nan"), "");
}

class DriveScriptRunTest : public ::testing::Test {
 protected:
  field::RobotConfig robot_ = field::LoadRobotConfig("thesis_robot");
};

TEST_F(DriveScriptRunTest, DrivesTheScriptByTheEncoders) {
  const std::vector<DriveStepResult> results = SimulateDriveScript(
      "forward 0.3; turn 90; forward 0.6; wait 1; back 0.2; turn -90", robot_, {}, 11);
  ASSERT_EQ(results.size(), 6u);
  for (const DriveStepResult& result : results) {
    EXPECT_EQ(result.status, DriveStepStatus::kDone) << result.step.text;
  }
  // The encoders say each step was done to within a few millimetres / a degree.
  EXPECT_NEAR(results[0].odometry_pose.x_m, 0.3, 0.005);
  EXPECT_NEAR(results[1].odometry_pose.theta_rad * kDegPerRad, 90.0, 1.5);
  EXPECT_NEAR(results[2].odometry_pose.y_m, 0.6, 0.02);
  EXPECT_NEAR(results[2].odometry_pose.x_m, 0.3, 0.02);
  EXPECT_NEAR(results[4].odometry_pose.y_m, 0.4, 0.02);
  EXPECT_NEAR(results[5].odometry_pose.theta_rad * kDegPerRad, 0.0, 1.5);
  // Waiting costs time and moves nothing.
  EXPECT_NEAR(results[3].end_time_s - results[2].end_time_s, 1.0, 0.03);
  EXPECT_NEAR(results[3].true_pose.x_m, results[2].true_pose.x_m, 1e-4);
  // Driving 0.3 m at 0.067 m/s takes about 4.5 s plus ramps and settling.
  EXPECT_GT(results[0].end_time_s, 4.4);
  EXPECT_LT(results[0].end_time_s, 5.5);
  // The truth is somewhere else: slip.
  const double dx = results[2].true_pose.x_m - results[2].odometry_pose.x_m;
  const double dy = results[2].true_pose.y_m - results[2].odometry_pose.y_m;
  EXPECT_GT(std::hypot(dx, dy), 0.01);
}

TEST_F(DriveScriptRunTest, SameSeedSameResult) {
  const auto a = SimulateDriveScript("forward 0.3; turn 90; forward 0.3", robot_, {}, 42);
  const auto b = SimulateDriveScript("forward 0.3; turn 90; forward 0.3", robot_, {}, 42);
  const auto c = SimulateDriveScript("forward 0.3; turn 90; forward 0.3", robot_, {}, 43);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].true_pose.x_m, b[i].true_pose.x_m);
    EXPECT_EQ(a[i].true_pose.y_m, b[i].true_pose.y_m);
    EXPECT_EQ(a[i].true_pose.theta_rad, b[i].true_pose.theta_rad);
    EXPECT_EQ(a[i].odometry_pose.x_m, b[i].odometry_pose.x_m);
    EXPECT_EQ(a[i].end_time_s, b[i].end_time_s);
  }
  EXPECT_NE(a.back().true_pose.x_m, c.back().true_pose.x_m);
}

TEST_F(DriveScriptRunTest, BlockedRobotSlipsAndFinishesByTheEncoders) {
  const std::vector<DriveStep> steps = ParseDriveScript("forward 0.3; turn 90");
  SimDriveBase sim(robot_.drive, SimDriveOptions{}, 3);
  sim.SetFreeSpaceCheck([](const Pose2D& pose) { return pose.x_m < 0.1; });
  SimClock clock;
  DriveControllerOptions options = DriveControllerOptionsFor(robot_.drive);
  options.timeout_margin_s = 1.0;
  // The wheels spin against the wall and the encoders count, so the controller believes it
  // arrived: only the truth shows the robot stuck.
  const auto results = RunDriveScript(steps, options, &sim, &clock);
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].status, DriveStepStatus::kDone);
  EXPECT_LT(results[0].true_pose.x_m, 0.1);
  EXPECT_GT(results[0].odometry_pose.x_m, 0.29);
}

TEST_F(DriveScriptRunTest, SimulateFromAStartPoseWithAWall) {
  const Pose2D start{1.0, 2.0, kPi / 2.0};
  const auto free_run = SimulateDriveScript("forward 0.3", robot_, {}, 5, start);
  EXPECT_NEAR(free_run[0].odometry_pose.x_m, 1.0, 0.01);
  EXPECT_NEAR(free_run[0].odometry_pose.y_m, 2.3, 0.005);
  const auto walled = SimulateDriveScript("forward 0.3", robot_, {}, 5, start,
                                          [](const Pose2D& pose) { return pose.y_m < 2.1; });
  EXPECT_LT(walled[0].true_pose.y_m, 2.1);
  EXPECT_GT(walled[0].odometry_pose.y_m, 2.29);
}

TEST_F(DriveScriptRunTest, StalledMotorTimesOut) {
  const std::vector<DriveStep> steps = ParseDriveScript("forward 0.3");
  SimDriveOptions sim_options;
  sim_options.left_motor_gain = 0.0;  // motors that do not turn
  sim_options.right_motor_gain = 0.0;
  SimDriveBase sim(robot_.drive, sim_options, 3);
  SimClock clock;
  DriveControllerOptions options = DriveControllerOptionsFor(robot_.drive);
  options.timeout_margin_s = 1.0;
  const auto results = RunDriveScript(steps, options, &sim, &clock);
  EXPECT_EQ(results[0].status, DriveStepStatus::kTimedOut);
  // Nominal 0.3 / 0.067 = 4.48 s, times 3, plus 1 s, plus settling.
  EXPECT_NEAR(clock.NowS(), 3.0 * 0.3 / 0.067 + 1.0, 0.5);
}

// Settling by the residual coast (DriveControllerOptions::settle_ticks): on the V5 robot's
// motor model a step ends well before the coast's last encoder tick, and what the wheels still
// coast after it is about one tick.
TEST(DriveScriptSettleTest, AStepEndsOnceTheResidualCoastIsUnderATick) {
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  ASSERT_TRUE(robot.drive.slip.has_value());
  const double tick_m = kPi * robot.drive.wheel_diameter_m / robot.drive.encoder_ticks_per_rev;
  const auto run = [&](int settle_ticks) {
    const std::vector<DriveStep> steps = ParseDriveScript("turn 5; forward 0.3; wait 1");
    SimDriveBase sim(robot.drive, SimDriveOptionsFor(robot.drive), 7);
    SimClock clock;
    DriveControllerOptions options = DriveControllerOptionsFor(robot.drive);
    if (settle_ticks > 0) {
      options.settle_s = robot.drive.slip->motor_time_constant_s;
      options.settle_ticks = settle_ticks;
    }
    return RunDriveScript(steps, options, &sim, &clock);
  };
  const std::vector<DriveStepResult> still = run(0);
  const std::vector<DriveStepResult> coast = run(1);
  ASSERT_EQ(still.size(), 3u);
  ASSERT_EQ(coast.size(), 3u);
  for (const DriveStepResult& r : coast) EXPECT_EQ(r.status, DriveStepStatus::kDone);
  // Each step is shorter: the turn's and the drive's ends come earlier (measured: 0.10 s and
  // 0.20 s).
  const double turn_saved_s = still[0].end_time_s - coast[0].end_time_s;
  const double drive_saved_s =
      (still[1].end_time_s - still[0].end_time_s) - (coast[1].end_time_s - coast[0].end_time_s);
  EXPECT_GT(turn_saved_s, 0.05);
  EXPECT_GT(drive_saved_s, 0.1);
  // After the drive, the wait sees the rest of the coast: about a tick (under 1.16 by the
  // window's arithmetic, drive_script.h) by the encoders and by the truth; after the turn,
  // which the drive's alignment would absorb, the heading moves as little.
  EXPECT_LE(std::abs(coast[2].odometry_pose.x_m - coast[1].odometry_pose.x_m), 1.2 * tick_m);
  EXPECT_LT(std::hypot(coast[2].true_pose.x_m - coast[1].true_pose.x_m,
                       coast[2].true_pose.y_m - coast[1].true_pose.y_m),
            1.2 * tick_m);
  const double track_m = robot.drive.track_width_m;
  const std::vector<DriveStepResult> turned = [&]() {
    SimDriveBase sim(robot.drive, SimDriveOptionsFor(robot.drive), 7);
    SimClock clock;
    DriveControllerOptions options = DriveControllerOptionsFor(robot.drive);
    options.settle_s = robot.drive.slip->motor_time_constant_s;
    options.settle_ticks = 1;
    return RunDriveScript(ParseDriveScript("turn 30; wait 1"), options, &sim, &clock);
  }();
  EXPECT_LT(std::abs(turned[1].odometry_pose.theta_rad - turned[0].odometry_pose.theta_rad),
            2.0 * 1.2 * tick_m / track_m);
  // The drive still covers its distance by the encoders.
  EXPECT_NEAR(coast[2].odometry_pose.x_m, 0.3 * std::cos(5.0 / kDegPerRad), 0.01);
}

// The controller's link to a simulated drive on its own clock, the truth on it.
DriveBodyLink SimBodyLink(SimDriveBase& sim, SimClock& clock) {
  DriveBodyLink body;
  body.base = &sim;
  body.metres_per_tick = sim.metres_per_tick();
  body.track_width_m = sim.drive().track_width_m;
  body.odometry_start = sim.odometry_pose();
  body.clock = &clock;
  body.advance = [&sim, &clock](double dt_s) {
    sim.Step(dt_s);
    clock.Advance(dt_s);
  };
  body.truth = [&sim]() { return sim.true_pose(); };
  return body;
}

// With a gyro on the link the controller turns and holds heading on it: the body turns what
// was asked where the wheels slip, which the encoders alone cannot see.
TEST(DriveScriptGyroTest, TurnsClosedOnTheGyroFollowTheBodyNotTheWheels) {
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  SimDriveOptions slippery = SimDriveOptionsFor(robot.drive);
  slippery.turn_slip = {0.10, 0.02, 3.0};         // the body follows 90 % of the wheels' turn
  slippery.differential_slip = {0.0, 0.04, 3.0};  // yaws unseen on the straight: twice the file
  const std::vector<DriveStep> steps = ParseDriveScript("turn 90; forward 0.6; turn -45");
  const auto run = [&](bool with_gyro, uint64_t seed) {
    SimDriveBase sim(robot.drive, slippery, seed);
    SimClock clock;
    DriveBodyLink body = SimBodyLink(sim, clock);
    if (with_gyro) body.gyro = [&]() { return std::optional<double>(sim.true_pose().theta_rad); };
    return RunDriveScript(steps, DriveControllerOptionsFor(robot.drive), body);
  };
  double encoder_error_deg = 0.0, gyro_error_deg = 0.0, gyro_worst_deg = 0.0;
  constexpr int kRuns = 20;
  for (uint64_t seed = 1; seed <= kRuns; ++seed) {
    const std::vector<DriveStepResult> encoders = run(false, seed);
    const std::vector<DriveStepResult> gyro = run(true, seed);
    ASSERT_EQ(gyro.size(), 3u);
    for (const DriveStepResult& r : gyro) EXPECT_EQ(r.status, DriveStepStatus::kDone);
    for (const DriveStepResult& r : encoders) EXPECT_EQ(r.status, DriveStepStatus::kDone);
    // The true heading after each step against the script's (90, 90, 45 degrees).
    for (size_t k = 0; k < 3; ++k) {
      const double want = k < 2 ? 90.0 : 45.0;
      const double e = std::abs(WrapAngleRad(encoders[k].true_pose.theta_rad - want / kDegPerRad));
      const double g = std::abs(WrapAngleRad(gyro[k].true_pose.theta_rad - want / kDegPerRad));
      encoder_error_deg += e * kDegPerRad / (3 * kRuns);
      gyro_error_deg += g * kDegPerRad / (3 * kRuns);
      gyro_worst_deg = std::max(gyro_worst_deg, g * kDegPerRad);
    }
  }
  std::cout << "mean true heading error: encoders " << encoder_error_deg << " deg, gyro "
            << gyro_error_deg << " deg (worst " << gyro_worst_deg << ")\n";
  // Measured: encoders 8.8 deg on average, the gyro 1.4 (worst 4.4: the wheels coast on once
  // the turn is cut).
  EXPECT_GT(encoder_error_deg, 5.0);  // the slip the encoders miss
  EXPECT_LT(gyro_error_deg, 0.3 * encoder_error_deg);
  EXPECT_LT(gyro_worst_deg, 6.0);
}

// A straight drive re-aimed from outside while under way (DriveBodyLink::correct), as
// SLAM-O's frames while driving do: where the wheels slip the body curves off the line the
// encoders hold, and a correction every 0.2 s from where the body truly is (here the truth,
// standing for the estimate) brings it to the leg's end.
TEST(DriveScriptCorrectionTest, ADriveReAimedWhileUnderWayEndsNearerItsTarget) {
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  SimDriveOptions slippery = SimDriveOptionsFor(robot.drive);
  slippery.differential_slip = {0.0, 0.04, 3.0};  // yaws unseen on the straight: twice the file
  const Eigen::Vector2d target(1.2, 0.0);
  const auto run = [&](bool steer, uint64_t seed) {
    SimDriveBase sim(robot.drive, slippery, seed);
    SimClock clock;
    DriveBodyLink body = SimBodyLink(sim, clock);
    double next_s = 0.2;
    if (steer) {
      body.correct = [&]() -> std::optional<DriveCorrection> {
        if (clock.NowS() < next_s) return std::nullopt;
        next_s += 0.2;
        const Pose2D p = sim.true_pose();
        const Eigen::Vector2d d = target - Eigen::Vector2d(p.x_m, p.y_m);
        const double change = WrapAngleRad(std::atan2(d.y(), d.x()) - p.theta_rad);
        const double remaining = d.norm() * std::cos(change);
        if (remaining < 0.1) return std::nullopt;
        return DriveCorrection{change, remaining};
      };
    }
    const std::vector<DriveStepResult> r = RunDriveScript(
        ParseDriveScript("forward 1.2"), DriveControllerOptionsFor(robot.drive), body);
    EXPECT_EQ(r[0].status, DriveStepStatus::kDone);
    return (Eigen::Vector2d(r[0].true_pose.x_m, r[0].true_pose.y_m) - target).norm();
  };
  double held = 0.0, steered = 0.0;
  constexpr int kRuns = 20;
  for (uint64_t seed = 1; seed <= kRuns; ++seed) {
    held += run(false, seed) / kRuns;
    steered += run(true, seed) / kRuns;
  }
  std::cout << "mean distance from the leg's end: held on the encoders " << held << " m, re-aimed "
            << steered << " m\n";
  EXPECT_LT(steered, 0.5 * held);
}

// A turn cut at the commanded speed overshoots: during the ramp down the wheels trail the
// command and coast on after the cut. Timed at the measured turning speed it stops nearer.
TEST(DriveScriptSettleTest, ATurnCutAtItsMeasuredSpeedOvershootsLess) {
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  ASSERT_TRUE(robot.drive.slip.has_value());
  const auto mean_overshoot_deg = [&](bool measured) {
    double sum = 0.0;
    int n = 0;
    for (uint64_t seed = 1; seed <= 20; ++seed) {
      SimDriveBase sim(robot.drive, SimDriveOptionsFor(robot.drive), seed);
      SimClock clock;
      DriveControllerOptions options = DriveControllerOptionsFor(robot.drive);
      options.cruise_speed_mps = robot.drive.match_speed_mps;  // as in a match
      options.stop_lead_s = robot.drive.slip->motor_time_constant_s;
      options.lead_on_measured_speed = measured;
      const std::vector<DriveStepResult> results = RunDriveScript(
          ParseDriveScript("turn 90; wait 0.3; turn -45; wait 0.3; turn 30; wait 0.3"), options,
          &sim, &clock);
      for (const DriveStepResult& r : results) EXPECT_EQ(r.status, DriveStepStatus::kDone);
      // By the encoders, after the coast (each wait), against the sum of the turns asked
      // (over- or undershoot).
      const double asked_deg[] = {90.0, 45.0, 75.0};
      for (int k = 0; k < 3; ++k) {
        sum += std::abs(results[2 * k + 1].odometry_pose.theta_rad * kDegPerRad - asked_deg[k]);
        ++n;
      }
    }
    return sum / n;
  };
  const double commanded = mean_overshoot_deg(false), measured = mean_overshoot_deg(true);
  std::cout << "mean turn error by the encoders: cut at the commanded speed " << commanded
            << " deg, at the measured " << measured << " deg\n";
  EXPECT_LT(measured, 0.7 * commanded);
}

// Drift statistics over many seeds: the calibration the simulator's defaults promise
// (thesis appendix B: 0.05 m per 0.3 m, 2 deg spread per 90 deg turn, ~0.1 m turn slip).
struct Stats {
  double mean = 0.0;
  double stddev = 0.0;
};
Stats StatsOf(const std::vector<double>& values) {
  Stats stats;
  for (double v : values) stats.mean += v;
  stats.mean /= static_cast<double>(values.size());
  for (double v : values) stats.stddev += (v - stats.mean) * (v - stats.mean);
  stats.stddev = std::sqrt(stats.stddev / static_cast<double>(values.size() - 1));
  return stats;
}

constexpr int kSeeds = 200;

TEST_F(DriveScriptRunTest, StraightDriftMatchesTheThesis) {
  std::vector<double> position_error_m;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const DriveStepResult r = SimulateDriveScript("forward 0.3", robot_, {}, seed).front();
    position_error_m.push_back(
        std::hypot(r.true_pose.x_m - r.odometry_pose.x_m, r.true_pose.y_m - r.odometry_pose.y_m));
  }
  const Stats stats = StatsOf(position_error_m);
  std::cout << "straight 0.3 m over " << kSeeds << " seeds: mean |position error| " << stats.mean
            << " m, std " << stats.stddev << " m\n";
  EXPECT_GE(stats.mean, 0.03);
  EXPECT_LE(stats.mean, 0.07);
}

TEST_F(DriveScriptRunTest, TurnSpreadAndSlipMatchTheThesis) {
  std::vector<double> heading_error_deg;
  std::vector<double> centre_travel_m;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const DriveStepResult r = SimulateDriveScript("turn 90", robot_, {}, seed).front();
    heading_error_deg.push_back(r.true_pose.theta_rad * kDegPerRad - 90.0);
    centre_travel_m.push_back(std::hypot(r.true_pose.x_m, r.true_pose.y_m));
  }
  const Stats heading = StatsOf(heading_error_deg);
  const Stats slip = StatsOf(centre_travel_m);
  std::cout << "turn 90 deg over " << kSeeds << " seeds: heading error mean " << heading.mean
            << " deg, std " << heading.stddev << " deg; centre slip mean " << slip.mean
            << " m, std " << slip.stddev << " m\n";
  EXPECT_GE(heading.stddev, 1.0);
  EXPECT_LE(heading.stddev, 3.0);
  EXPECT_LT(std::abs(heading.mean), 5.0);
  EXPECT_GE(slip.mean, 0.07);
  EXPECT_LE(slip.mean, 0.13);
}

}  // namespace
}  // namespace slamo::platform
