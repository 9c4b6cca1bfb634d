// The match-day run with no robot: the executive on HardwareIo over the fake board on a
// pseudo-terminal (the real serial stack: MRPT's CSerialPort, the protocol, heartbeats, the
// firmware's logic and watchdog) on simulated time, seeing either the simulated field rendered
// from the fake board's motors (SLAM-O closes the loop, scored against that truth) or a
// recorded stream played against the match clock. Each match is shortened to 15 s; real pty
// I/O takes about 0.2 ms per simulated millisecond.
#include "autonomy/io/hardware_io.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "autonomy/loop/executive.h"
#include "field_configs/loader.h"
#include "platform/field_geometry.h"
#include "platform/recording.h"
#include "platform/sim/sim_recording.h"

namespace slamo::autonomy {
namespace {

// The fake board in this process and the host's link to it, on one simulated clock. The host
// opens the board through a symlink of this process's own: a replugged pty gets whichever
// /dev/pts number is free, and with tests running in parallel (ctest -j) the old number can
// go to another process's pty, which the host would then open instead (seen once in CI:
// no reconnection).
struct Bench {
  explicit Bench(const field::RobotConfig& robot, const platform::FakeBoardOptions& options = {})
      : board(robot.drive, options, LinkPath()),
        link(platform::MakeMrptSerialTransport(board.device_path()), clock, LinkOptions(robot)) {}
  static std::string LinkPath() {
    static int count = 0;
    return ::testing::TempDir() + "/slamo_hardware_match_" + std::to_string(::getpid()) + "_" +
           std::to_string(count++);
  }
  static platform::SerialDriveOptions LinkOptions(const field::RobotConfig& robot) {
    platform::SerialDriveOptions o;
    o.pid = robot.drive.pid;
    o.reconnect_period_s = 0.05;
    return o;
  }
  // Lets dt_s pass: the board runs, the kernel passes the bytes on, the clock moves.
  void Pace(double dt_s) {
    board.Pump(dt_s);
    ::usleep(150);
    clock.Advance(dt_s);
  }
  platform::SimClock clock;
  platform::PtyFakeBoard board;
  platform::SerialDriveBase link;
};

field::SeasonConfig ShortSeason() {
  field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  season.rules.autonomous_s = 15.0;
  return season;
}

// As `slamo match` sets it up: no gyro, the field as its file has it, frames only at stops.
MatchSetup HardwareSetup() {
  MatchSetup setup;
  setup.gyro = false;  // the board streams no gyro
  setup.placement_jitter_m = 0.0;
  setup.moving_frame_period_s = 0.0;
  setup.steer_on_estimate = false;
  return setup;
}

TEST(HardwareMatch, ClosesTheLoopOverTheFakeBoardsSerialLink) {
  const field::SeasonConfig season = ShortSeason();
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  MatchSetup setup = HardwareSetup();
  // With frames while driving (`slamo match --moving-frames 0.2`), taken only when the camera
  // has one ready.
  setup.moving_frame_period_s = 0.2;
  setup.steer_on_estimate = true;
  Bench bench(robot);
  const platform::Pose2D start = platform::StartPose(season, setup.alliance, 0);
  FakeBoardCamera camera(season, robot, bench.board.board(), start, bench.clock, 1);
  HardwareIoOptions options;
  double farthest_m = 0.0;  // the truth's farthest from the start, wherever it was asked for
  options.truth = [&]() {
    const platform::Pose2D now = camera.Truth();
    farthest_m = std::max(farthest_m, std::hypot(now.x_m - start.x_m, now.y_m - start.y_m));
    return std::optional<platform::Pose2D>(now);
  };
  auto io = std::make_unique<HardwareIo>(
      &bench.link, &camera, bench.clock, [&](double dt) { bench.Pace(dt); }, options);
  ASSERT_TRUE(io->Connect()) << platform::LinkStateName(bench.link.link_state());
  const double match_start_s = bench.board.board().time_s();

  const MatchResult r =
      RunMatchOn(std::move(io), strategy::MakeStrategy("planner", {}), season, robot, setup, 1);
  bench.link.Stop();
  // The run: the robot really moved (the fake board's motor model says so), and SLAM-O,
  // seeing the field from there, kept up with it.
  EXPECT_FALSE(r.truth_known);
  EXPECT_GT(r.frames_taken, 10);
  EXPECT_GT(r.moving_frames, 0);
  ASSERT_FALSE(std::isnan(r.pose_ate_m));
  EXPECT_LT(r.pose_ate_m, 0.15);
  // (How far it went, not where it ended: on this seed it drives towards the middle zone,
  // releases there and sets off to knock a barrier ball, 0.84 m out at most; 0.46 m with
  // frames only at stops, when it released from where it stood and came back.)
  const platform::Pose2D end = camera.Truth();
  EXPECT_GT(farthest_m, 0.3);
  EXPECT_LT((r.samples.back().estimate.head<2>() - Eigen::Vector2d(end.x_m, end.y_m)).norm(), 0.25);
  // The deadline: nothing driven after it, on the host's account and on the board's.
  EXPECT_EQ(r.overrun_s, 0.0);
  EXPECT_LE(bench.board.board().last_stop_s() - match_start_s, season.rules.autonomous_s + 0.05);
  EXPECT_EQ(bench.board.board().logic().left_pwm(), robot.drive.pwm.stop);
  EXPECT_EQ(bench.board.board().logic().right_pwm(), robot.drive.pwm.stop);
  // A clean link.
  EXPECT_EQ(r.board.at("link_losses"), 0.0);
  EXPECT_EQ(r.board.at("board_errors"), 0.0);
  EXPECT_GT(r.board.at("encoder_frames"), 500.0);
}

// A camera with nothing to give.
class SilentCamera : public platform::RgbdCamera {
 public:
  std::optional<platform::RgbdFrame> Grab() override {
    ++grabs;
    return std::nullopt;
  }
  int grabs = 0;
};

// A frame while driving is taken only if the camera has one ready: the drive controller gets
// its period back. A look at a stop waits up to frame_wait_s for one.
TEST(HardwareMatch, AFrameWhileDrivingNeverWaitsForTheCamera) {
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  Bench bench(robot);
  SilentCamera camera;
  HardwareIoOptions options;
  options.frame_wait_s = 0.1;
  HardwareIo io(
      &bench.link, &camera, bench.clock, [&](double dt) { bench.Pace(dt); }, options);
  const double t0 = bench.clock.NowS();
  EXPECT_FALSE(io.CaptureReady());
  EXPECT_EQ(bench.clock.NowS(), t0);
  EXPECT_EQ(camera.grabs, 1);
  EXPECT_FALSE(io.Capture());
  EXPECT_GE(bench.clock.NowS() - t0, options.frame_wait_s);
  EXPECT_GT(camera.grabs, 10);
}

TEST(HardwareMatch, SurvivesAnUnpluggedCableAndANoisyLink) {
  const field::SeasonConfig season = ShortSeason();
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  const MatchSetup setup = HardwareSetup();
  platform::FakeBoardOptions board_options;
  board_options.faults.drop_probability = 0.02;
  board_options.faults.garbage_probability = 0.02;
  board_options.faults.duplicate_probability = 0.02;
  Bench bench(robot, board_options);
  const platform::Pose2D start = platform::StartPose(season, setup.alliance, 0);
  FakeBoardCamera camera(season, robot, bench.board.board(), start, bench.clock, 2);
  // The cable comes out for 0.3 s while the robot drives: at the first moment from 3 s on the
  // board's clock that its motors turn (when the strategy drives first depends on the field).
  double unplugged_s = -1.0;
  bool replugged = false;
  const auto pace = [&](double dt) {
    bench.Pace(dt);
    const platform::FakeBoard& b = bench.board.board();
    const bool driving = b.logic().left_pwm() != robot.drive.pwm.stop ||
                         b.logic().right_pwm() != robot.drive.pwm.stop;
    if (unplugged_s < 0.0 && b.time_s() >= 3.0 && driving) {
      unplugged_s = b.time_s();
      bench.board.Unplug();
    }
    if (unplugged_s >= 0.0 && !replugged && b.time_s() >= unplugged_s + 0.3) {
      // The motors were stopped by the board's own watchdog within 100 ms of the last frame.
      EXPECT_EQ(b.logic().left_pwm(), robot.drive.pwm.stop);
      EXPECT_LE(b.last_stop_s() - unplugged_s, 0.1);
      bench.board.Replug();
      replugged = true;
    }
  };
  HardwareIoOptions options;
  options.truth = [&]() { return std::optional<platform::Pose2D>(camera.Truth()); };
  auto io = std::make_unique<HardwareIo>(&bench.link, &camera, bench.clock, pace, options);
  ASSERT_TRUE(io->Connect());
  const MatchResult r =
      RunMatchOn(std::move(io), strategy::MakeStrategy("planner", {}), season, robot, setup, 1);
  bench.link.Stop();
  ASSERT_TRUE(replugged) << "the robot never drove after 3 s";
  EXPECT_LT(unplugged_s, season.rules.autonomous_s - 1.0);
  EXPECT_GE(r.board.at("link_losses"), 1.0);
  EXPECT_GE(r.board.at("port_opens"), 2.0);  // reconnected
  EXPECT_GT(r.board.at("crc_errors") + r.board.at("bytes_skipped"), 0.0);
  EXPECT_EQ(r.overrun_s, 0.0);
  EXPECT_EQ(bench.board.board().logic().left_pwm(), robot.drive.pwm.stop);
  // The match went on after the reconnection.
  ASSERT_FALSE(r.timeline.empty());
  EXPECT_GT(r.timeline.back().end_s, 10.0);
  ASSERT_FALSE(std::isnan(r.pose_ate_m));
  EXPECT_LT(r.pose_ate_m, 0.3);
}

// A recorded stream as the camera: frames come out at their recorded times on the match
// clock, the ones between two grabs are skipped, and a looped stream starts again.
TEST(RecordedStreamCamera, PlaysARecordingAgainstTheClock) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  const std::string rec = ::testing::TempDir() + "/stream_camera_rec";
  std::filesystem::remove_all(rec);
  platform::SimRecordingOptions options;
  options.script = "wait 1";
  options.fps = 5.0;  // frames at 0, 0.2, ..., 1.0 s
  {
    const auto writer = platform::OpenTumWriter(rec, platform::RecordingInfoFor(robot));
    const platform::SimRecordingSummary summary =
        platform::RecordSimulatedRun(season, robot, options, {writer.get()});
    writer->Close();
    ASSERT_EQ(summary.frames, 6);
  }
  for (const bool loop : {false, true}) {
    platform::SimClock clock;
    RecordedStreamCamera camera(platform::OpenRecording(rec), clock, loop);
    auto first = camera.Grab();
    ASSERT_TRUE(first);
    EXPECT_EQ(first->index, 0);
    EXPECT_NEAR(first->t_s, 0.0, 1e-6);
    clock.Advance(0.1);
    EXPECT_FALSE(camera.Grab()) << "no new frame before 0.2 s";
    clock.Advance(0.35);  // 0.45 s: the 0.2 s frame was missed, the 0.4 s one is shown
    auto later = camera.Grab();
    ASSERT_TRUE(later);
    EXPECT_EQ(later->index, 2);  // its number in the recording
    EXPECT_NEAR(later->t_s, 0.4, 1e-6);
    clock.Advance(0.6);  // 1.05 s: the last frame
    auto last = camera.Grab();
    ASSERT_TRUE(last);
    EXPECT_NEAR(last->t_s, 1.0, 1e-6);
    clock.Advance(0.2);  // 1.25 s: past the end; a loop's second pass starts at 1.2 s
    auto again = camera.Grab();
    EXPECT_EQ(again.has_value(), loop);
    if (again) {
      EXPECT_NEAR(again->t_s, 1.2, 1e-6);
    }
    EXPECT_EQ(camera.loops(), loop ? 1 : 0);
  }
}

}  // namespace
}  // namespace slamo::autonomy
