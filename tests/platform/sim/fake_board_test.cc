// The host driver against the fake board (the firmware's logic on the simulator's motors):
// on simulated time through an in-memory link for the timing requirements, and through a
// real pseudo-terminal and MRPT's serial port for unplug / replug.
#include "platform/sim/fake_board.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <variant>

#include "field_configs/loader.h"
#include "platform/clock.h"
#include "platform/serial_drive_base.h"

namespace slamo::platform {
namespace {

field::DriveConfig ThesisDrive() { return field::LoadRobotConfig("thesis_robot").drive; }

// The cable between SerialDriveBase and a FakeBoard, in memory: an unplugged board is a
// device that is gone.
class BoardLink : public SerialTransport {
 public:
  explicit BoardLink(FakeBoard* board) : board_(board) {}
  bool Open() override {
    if (!board_->plugged()) return false;
    board_->TakeOutput();  // opening a port flushes what was waiting
    open_ = true;
    return true;
  }
  void Close() override { open_ = false; }
  bool IsOpen() const override { return open_; }
  bool Read(std::vector<uint8_t>* out) override {
    if (!open_ || !board_->plugged()) return open_ = false;
    const std::vector<uint8_t> bytes = board_->TakeOutput();
    out->insert(out->end(), bytes.begin(), bytes.end());
    return true;
  }
  bool Write(const std::vector<uint8_t>& bytes) override {
    if (!open_ || !board_->plugged()) return open_ = false;
    board_->Receive(bytes);
    return true;
  }
  std::string last_error() const override { return open_ ? "" : "unplugged"; }

 private:
  FakeBoard* board_;
  bool open_ = false;
};

// Host and board on one simulated clock, 1 ms steps.
struct Rig {
  explicit Rig(const FakeBoardOptions& options = {}, const SerialDriveOptions& host_options = {})
      : drive(ThesisDrive()),
        board(drive, options),
        host(std::make_unique<BoardLink>(&board), clock, host_options) {}

  // host_alive = false: the host process is hung (sends and reads nothing).
  void Run(double duration_s, bool host_alive = true) {
    const int steps = static_cast<int>(std::lround(duration_s / 0.001));
    for (int i = 0; i < steps; ++i) {
      clock.Advance(0.001);
      board.Advance(0.001);
      if (host_alive) host.Poll();
    }
  }
  double MetresPerTick() const {
    return kPi * drive.wheel_diameter_m / drive.encoder_ticks_per_rev;
  }
  // Mean wheel speeds from the host's encoder readings over the next duration_s.
  std::pair<double, double> MeasureSpeed(double duration_s) {
    const EncoderTicks a = host.ReadEncoders();
    Run(duration_s);
    const EncoderTicks b = host.ReadEncoders();
    const double dt = b.t_s - a.t_s;
    return {(b.left - a.left) * MetresPerTick() / dt, (b.right - a.right) * MetresPerTick() / dt};
  }

  SimClock clock;
  field::DriveConfig drive;
  FakeBoard board;
  SerialDriveBase host;
};

TEST(FakeBoardTest, HostDrivesAtCruiseSpeedThroughTheProtocol) {
  Rig rig;
  rig.host.SetPidGains(rig.drive.pid);
  rig.Run(0.1);
  ASSERT_TRUE(rig.host.link_up());
  rig.host.SetSpeedTargets(0.067, 0.067);
  rig.Run(3.0);
  const auto [left, right] = rig.MeasureSpeed(1.0);
  EXPECT_NEAR(left, 0.067, 0.003);
  EXPECT_NEAR(right, 0.067, 0.003);
  EXPECT_TRUE(rig.board.logic().speed_mode());
  EXPECT_LT(rig.board.logic().left_pwm(), 90 - rig.drive.pwm.deadband);  // 0 = full forward
  // Every command was acknowledged; the host saw heartbeats answered.
  EXPECT_GT(rig.host.stats().acks, 0u);
  EXPECT_EQ(rig.host.stats().errors, 0u);
  ASSERT_TRUE(rig.host.stats().last_rtt_s.has_value());
  EXPECT_LE(*rig.host.stats().last_rtt_s, 0.003);
  // Encoder frames at 50 Hz, timestamps from the board's clock.
  EXPECT_NEAR(static_cast<double>(rig.host.stats().encoder_frames), 4.1 * 50, 3);
  EXPECT_EQ(rig.host.stats().link_losses, 0u);
}

TEST(FakeBoardTest, PwmStopAndPidGainsReachTheBoard) {
  Rig rig;
  rig.Run(0.1);
  rig.host.SetPwm(40, 140);
  rig.Run(0.05);
  EXPECT_EQ(rig.board.logic().left_pwm(), 40);
  EXPECT_EQ(rig.board.logic().right_pwm(), 140);
  EXPECT_FALSE(rig.board.logic().speed_mode());
  rig.Run(1.0);
  const EncoderTicks turning = rig.host.ReadEncoders();
  EXPECT_GT(turning.left, 100);  // forward
  EXPECT_LT(turning.right, -100);
  rig.host.Stop();
  rig.Run(0.01);
  EXPECT_EQ(rig.board.logic().left_pwm(), 90);
  EXPECT_EQ(rig.board.logic().right_pwm(), 90);
  // A PWM out of range is refused with an ERROR, and the motors stay stopped.
  rig.host.SetPwm(200, 90);
  rig.Run(0.05);
  EXPECT_EQ(rig.host.stats().errors, 1u);
  EXPECT_EQ(rig.board.logic().left_pwm(), 90);
  field::PidGains gains = rig.drive.pid;
  gains.kp = 12.5;
  gains.ki = 0.25;
  rig.host.SetPidGains(gains);
  rig.Run(0.01);
  EXPECT_FLOAT_EQ(rig.board.logic().pid().kp, 12.5f);
  EXPECT_FLOAT_EQ(rig.board.logic().pid().ki, 0.25f);
}

// The requirement: motors stopped (PWM 90) within 100 ms of a lost link, on the board's clock.
TEST(FakeBoardTest, WatchdogStopsMotorsWithin100msWhenHeartbeatsStop) {
  Rig rig;
  rig.Run(0.1);
  rig.host.SetSpeedTargets(0.2, 0.2);
  rig.Run(1.0);
  ASSERT_NE(rig.board.logic().left_pwm(), 90);
  const double hung_at_s = rig.board.time_s();
  rig.Run(0.3, /*host_alive=*/false);  // the host process hangs: no heartbeat, no command
  const double last_rx_s = 1e-6 * rig.board.logic().last_rx_us();
  EXPECT_LE(last_rx_s, hung_at_s);
  const double stop_delay_s = rig.board.last_stop_s() - last_rx_s;
  EXPECT_GT(rig.board.last_stop_s(), hung_at_s);
  EXPECT_LE(stop_delay_s, 0.1);
  EXPECT_NEAR(stop_delay_s, 0.051, 0.0015);  // 50 ms timeout, checked every 1 ms loop
  EXPECT_EQ(rig.board.logic().left_pwm(), 90);
  EXPECT_EQ(rig.board.logic().right_pwm(), 90);
  EXPECT_TRUE(rig.board.logic().watchdog_stopped());
  EXPECT_EQ(rig.board.logic().watchdog_trips(), 1);
  EXPECT_LT(std::abs(rig.board.motors().left_wheel_speed_mps()), 0.01);  // wheels have stopped
}

TEST(FakeBoardTest, UnplugStopsBoardAndHostThenHostReconnects) {
  SerialDriveOptions host_options;
  host_options.pid = ThesisDrive().pid;
  Rig rig({}, host_options);
  rig.Run(0.1);
  rig.host.SetSpeedTargets(0.1, 0.1);
  rig.Run(1.0);
  const EncoderTicks before = rig.host.ReadEncoders();
  EXPECT_GT(before.left, 100);
  rig.board.Unplug();
  const double unplugged_s = rig.board.time_s();
  rig.Run(0.5);
  // The board stopped the motors within 100 ms; the host saw the device go and closed it.
  EXPECT_LE(rig.board.last_stop_s() - unplugged_s, 0.1);
  EXPECT_EQ(rig.board.logic().left_pwm(), 90);
  EXPECT_EQ(rig.host.link_state(), LinkState::kClosed);
  EXPECT_EQ(rig.host.stats().link_losses, 1u);
  // Replug a board that restarted (counts from 0): the host reopens and counts continue.
  rig.board.Replug(/*reset_board=*/true);
  rig.Run(0.5);
  EXPECT_EQ(rig.host.link_state(), LinkState::kUp);
  EXPECT_EQ(rig.host.stats().link_ups, 2u);
  EXPECT_GE(rig.host.stats().port_opens, 2u);
  const EncoderTicks after = rig.host.ReadEncoders();
  EXPECT_GE(after.left, before.left);  // no jump back to 0
  EXPECT_GT(after.t_s, before.t_s);
  // After a lost link the robot stays stopped until it is told to move again.
  EXPECT_EQ(rig.board.logic().left_pwm(), 90);
  rig.Run(0.5);
  EXPECT_LE(rig.host.ReadEncoders().left - after.left, 2);
  rig.host.SetSpeedTargets(0.1, 0.1);
  rig.Run(1.0);
  EXPECT_GT(rig.host.ReadEncoders().left - after.left, 100);
  // The gains were sent again at the new link-up.
  EXPECT_FLOAT_EQ(rig.board.logic().pid().kp, static_cast<float>(rig.drive.pid.kp));
}

TEST(FakeBoardTest, SilentLinkIsLostAndComesBackWithoutReopening) {
  Rig rig;
  rig.Run(0.1);
  rig.host.SetSpeedTargets(0.1, 0.1);
  rig.Run(0.5);
  LinkFaults cut;
  cut.drop_probability = 1.0;  // every frame lost both ways, the port stays open
  rig.board.set_faults(cut);
  const double cut_s = rig.board.time_s();
  rig.Run(0.3);
  EXPECT_EQ(rig.host.link_state(), LinkState::kWaiting);
  EXPECT_EQ(rig.host.stats().link_losses, 1u);
  EXPECT_LE(rig.board.last_stop_s() - cut_s, 0.1);
  EXPECT_EQ(rig.board.logic().left_pwm(), 90);
  rig.board.set_faults({});
  rig.Run(0.2);
  EXPECT_TRUE(rig.host.link_up());
  EXPECT_EQ(rig.host.stats().port_opens, 1u);
  EXPECT_EQ(rig.board.logic().left_pwm(), 90);  // stays stopped: the old command is forgotten
}

TEST(FakeBoardTest, SurvivesGarbageDropsDuplicatesAndDelays) {
  FakeBoardOptions options;
  options.faults.garbage_probability = 0.2;
  options.faults.drop_probability = 0.05;
  options.faults.duplicate_probability = 0.1;
  options.faults.delay_s = 0.004;
  options.faults.delay_jitter_s = 0.004;
  Rig rig(options);
  rig.host.SetPidGains(rig.drive.pid);
  rig.Run(0.2);
  rig.host.SetSpeedTargets(0.067, 0.067);
  rig.Run(2.0);
  const auto [left, right] = rig.MeasureSpeed(3.0);
  // Drops cost the odd watchdog stop; the refreshed command restarts the loop.
  EXPECT_NEAR(left, 0.067, 0.015);
  EXPECT_NEAR(right, 0.067, 0.015);
  const SerialDriveStats& s = rig.host.stats();
  EXPECT_GT(s.parser.crc_errors + s.parser.length_errors + s.parser.bytes_skipped, 0u);
  EXPECT_GT(s.duplicate_encoder_frames, 0u);
  const slamo_parser& board_parser = rig.board.logic().parser();
  EXPECT_GT(board_parser.crc_errors + board_parser.length_errors + board_parser.bytes_skipped, 0u);
  EXPECT_GT(rig.board.stats().dropped, 0u);
  EXPECT_GT(rig.board.stats().duplicated, 0u);
  EXPECT_GT(rig.board.stats().garbage_bursts, 0u);
  // Encoder totals never go backwards while driving forward.
  EncoderTicks last = rig.host.ReadEncoders();
  for (int i = 0; i < 200; ++i) {
    rig.Run(0.005);
    const EncoderTicks now = rig.host.ReadEncoders();
    EXPECT_GE(now.left, last.left);
    EXPECT_GE(now.t_s, last.t_s);
    last = now;
  }
}

// The longest the motors ran on after Stop() over 40 stops on a link that drops a fifth of
// its frames.
double WorstStopDelay(const SerialDriveOptions& host_options) {
  FakeBoardOptions options;
  options.faults.drop_probability = 0.2;
  Rig rig(options, host_options);
  rig.Run(0.2);
  double worst_s = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    rig.host.SetPwm(40, 140);
    rig.Run(0.1);
    rig.host.Stop();
    double t = 0.0;
    while (t < 0.5 && (rig.board.logic().left_pwm() != 90 || rig.board.logic().right_pwm() != 90)) {
      rig.Run(0.001);
      t += 0.001;
    }
    worst_s = std::max(worst_s, t);
  }
  return worst_s;
}

// A lost stop is sent again within a control period, not at the next command refresh: at the
// match's deadline the motors must not run on (a 2 % lossy link once drove 0.1 s past it).
TEST(FakeBoardTest, ALostStopIsResentWithinAControlPeriod) {
  SerialDriveOptions as_before;
  as_before.stop_refresh_s = as_before.command_refresh_s;
  const double before_s = WorstStopDelay(as_before);
  const double now_s = WorstStopDelay(SerialDriveOptions{});
  EXPECT_GE(before_s, 0.09);
  EXPECT_LE(now_s, 0.085);  // measured 0.064: three stops in a row lost
}

// The cable of BoardLink with a fault of its own: the board's frames lost on the way to the
// host (the host loses the link while the board still hears it), and the host's STOP frames
// lost on the way to the board until lose_stops_until_s (its heartbeats pass and keep the
// board's watchdog fed).
class LossyLink : public BoardLink {
 public:
  LossyLink(FakeBoard* board, const Clock& clock) : BoardLink(board), clock_(clock) {}
  bool Read(std::vector<uint8_t>* out) override {
    std::vector<uint8_t> bytes;
    const bool open = BoardLink::Read(&bytes);
    if (!deaf) out->insert(out->end(), bytes.begin(), bytes.end());
    return open;
  }
  bool Write(const std::vector<uint8_t>& bytes) override {
    for (const serial::Frame& frame : parser_.Feed(bytes)) {
      const std::optional<serial::Message> m = serial::Decode(frame);
      if (m && std::holds_alternative<serial::Stop>(*m) && clock_.NowS() < lose_stops_until_s) {
        ++stops_lost;
        return true;  // gone on the way
      }
    }
    return BoardLink::Write(bytes);
  }
  bool deaf = false;
  double lose_stops_until_s = 0.0;
  int stops_lost = 0;

 private:
  const Clock& clock_;
  serial::Parser parser_;
};

// After a link loss the host keeps sending the stop: every stop up to and including the one of
// the link loss (60 ms after the board fell silent) lost, a later one arrives (before, the host
// forgot its command after the link loss and the motors ran on for as long as its heartbeats
// kept the board's watchdog fed).
TEST(FakeBoardTest, TheStopIsResentWhileTheLinkIsDown) {
  field::DriveConfig drive = ThesisDrive();
  FakeBoard board(drive, FakeBoardOptions{});
  SimClock clock;
  auto owned = std::make_unique<LossyLink>(&board, clock);
  LossyLink* link = owned.get();
  SerialDriveBase host(std::move(owned), clock, SerialDriveOptions{});
  const auto run = [&](double duration_s) {
    for (int i = 0; i < static_cast<int>(std::lround(duration_s / 0.001)); ++i) {
      clock.Advance(0.001);
      board.Advance(0.001);
      host.Poll();
    }
  };
  run(0.1);
  ASSERT_TRUE(host.link_up());
  host.SetPwm(40, 140);
  run(0.1);
  ASSERT_EQ(static_cast<int>(board.logic().left_pwm()), 40);
  link->deaf = true;
  link->lose_stops_until_s = clock.NowS() + 0.065;
  host.Stop();
  run(0.065);
  EXPECT_EQ(host.link_state(), LinkState::kWaiting);  // lost after 60 ms
  EXPECT_EQ(static_cast<int>(board.logic().left_pwm()), 40) << "every stop so far lost";
  EXPECT_GE(link->stops_lost, 2);
  run(0.1);
  EXPECT_EQ(static_cast<int>(board.logic().left_pwm()), 90);
  EXPECT_EQ(static_cast<int>(board.logic().right_pwm()), 90);
  EXPECT_EQ(board.logic().watchdog_trips(), 0) << "the heartbeats got through";
}

TEST(FakeBoardTest, BoardIgnoresPureGarbageAndAnswersUnhandledTypes) {
  FakeBoard board(ThesisDrive(), {});
  std::mt19937 rng(3);
  std::vector<uint8_t> junk(20000);
  for (uint8_t& b : junk) b = rng() % 5 == 0 ? serial::kFrameStart : static_cast<uint8_t>(rng());
  board.Receive(junk);
  board.Advance(0.1);
  EXPECT_EQ(static_cast<int>(board.logic().left_pwm()), 90);
  EXPECT_EQ(static_cast<int>(board.logic().right_pwm()), 90);
  EXPECT_FALSE(board.logic().speed_mode());
  // A valid frame of a type the board does not handle (its own ENCODERS) gets an ERROR back.
  const std::vector<uint8_t> frame = serial::Encode(serial::Encoders{}, 5);
  board.TakeOutput();
  board.Receive(frame);
  board.Advance(0.002);
  serial::Parser parser;
  bool saw_error = false;
  for (const serial::Frame& f : parser.Feed(board.TakeOutput())) {
    const auto m = serial::Decode(f);
    if (m && std::holds_alternative<serial::Error>(*m)) {
      const auto& e = std::get<serial::Error>(*m);
      EXPECT_EQ(e.code, SLAMO_ERR_UNKNOWN_TYPE);
      EXPECT_EQ(e.type, SLAMO_MSG_ENCODERS);
      EXPECT_EQ(e.seq, 5);
      saw_error = true;
    }
  }
  EXPECT_TRUE(saw_error);
}

// The real serial stack: MRPT's CSerialPort on a pseudo-terminal behind a symlink. Real I/O,
// so the loop sleeps 0.2 ms per simulated millisecond for the kernel to pass bytes on; about
// 1 s of wall time.
TEST(FakeBoardPtyTest, HostReconnectsAfterUnplugAndReplugOnAPty) {
  const std::string link = testing::TempDir() + "/slamo_fake_board_" + std::to_string(::getpid());
  PtyFakeBoard board(ThesisDrive(), {}, link);
  ASSERT_TRUE(std::filesystem::is_symlink(link));
  SimClock clock;
  SerialDriveOptions host_options;
  host_options.reconnect_period_s = 0.05;
  SerialDriveBase host(MakeMrptSerialTransport(link), clock, host_options);
  const auto run = [&](double duration_s) {
    for (int i = 0; i < static_cast<int>(duration_s * 1000); ++i) {
      board.Pump(0.001);
      ::usleep(200);
      clock.Advance(0.001);
      host.Poll();
    }
  };
  run(0.3);
  ASSERT_TRUE(host.link_up()) << LinkStateName(host.link_state());
  host.SetSpeedTargets(0.1, 0.1);
  run(1.0);
  const EncoderTicks before = host.ReadEncoders();
  EXPECT_GT(before.left, 100);

  const std::string first_slave = board.slave_path();
  const double unplugged_s = board.board().time_s();
  board.Unplug();
  run(0.3);
  EXPECT_EQ(host.link_state(), LinkState::kClosed);
  EXPECT_LE(board.board().last_stop_s() - unplugged_s, 0.1);
  EXPECT_EQ(board.board().logic().left_pwm(), 90);

  board.Replug();
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  run(0.5);
  EXPECT_TRUE(host.link_up()) << LinkStateName(host.link_state());
  EXPECT_EQ(host.stats().link_ups, 2u);
  EXPECT_GE(host.stats().port_opens, 2u);
  host.SetSpeedTargets(0.1, 0.1);
  run(0.5);
  EXPECT_GT(host.ReadEncoders().left, before.left + 50);
  EXPECT_EQ(host.stats().errors, 0u);
  (void)first_slave;
}

}  // namespace
}  // namespace slamo::platform
