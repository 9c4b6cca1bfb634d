// `slamo board`: the motor-controller board link. `board fake` runs the fake board (the
// firmware's logic on the simulator's motors) on a pseudo-terminal in real time, with fault
// injection; `board ping` talks to a real or fake board: heartbeat round trips and the encoder
// stream for a few seconds. Exit status: 0 on success, 1 when the board did not answer, 2 on
// bad arguments.
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>

#include "autonomy/cli/commands.h"
#include "field_configs/loader.h"
#include "platform/clock.h"
#include "platform/serial_drive_base.h"
#include "platform/sim/fake_board.h"

namespace slamo::autonomy {
namespace {

volatile std::sig_atomic_t g_stop = 0;
volatile std::sig_atomic_t g_toggle_plug = 0;
void OnStopSignal(int) { g_stop = 1; }
void OnToggleSignal(int) { g_toggle_plug = 1; }

struct FakeArgs {
  std::string robot = field::kDefaultRobot;
  std::string link;
  uint64_t seed = 1;
  double duration_s = 0.0;  // 0: until SIGINT / SIGTERM
  double garbage = 0.0;
  double drop = 0.0;
  double duplicate = 0.0;
  double delay_ms = 0.0;
  double jitter_ms = 0.0;
  double unplug_at_s = -1.0;
  double replug_at_s = -1.0;
  bool reset_on_replug = false;
  bool verbose = false;
};

struct PingArgs {
  std::string port;
  int baud = 115200;
  double seconds = 2.0;
  double speed_mps = 0.0;  // drive both sides at this speed while pinging (0: no motion)
};

void PrintBoardStatus(const platform::FakeBoard& board) {
  const slamo_fw::BoardLogic& logic = board.logic();
  std::printf(
      "t %.1f s  %s  link %s  pwm %d/%d  ticks %lld/%lld  watchdog trips %u  rx errors %u  "
      "dropped %llu  duplicated %llu  garbage %llu\n",
      board.time_s(), board.plugged() ? "plugged" : "UNPLUGGED", logic.link_up() ? "up" : "down",
      logic.left_pwm(), logic.right_pwm(), static_cast<long long>(board.board_ticks().left),
      static_cast<long long>(board.board_ticks().right), logic.watchdog_trips(),
      static_cast<unsigned>(logic.parser().crc_errors + logic.parser().length_errors +
                            logic.parser().type_errors),
      static_cast<unsigned long long>(board.stats().dropped),
      static_cast<unsigned long long>(board.stats().duplicated),
      static_cast<unsigned long long>(board.stats().garbage_bursts));
  std::fflush(stdout);
}

int RunFake(const FakeArgs& args) {
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  platform::FakeBoardOptions options;
  options.seed = args.seed;
  options.faults.garbage_probability = args.garbage;
  options.faults.drop_probability = args.drop;
  options.faults.duplicate_probability = args.duplicate;
  options.faults.delay_s = args.delay_ms * 1e-3;
  options.faults.delay_jitter_s = args.jitter_ms * 1e-3;
  platform::PtyFakeBoard board(robot.drive, options, args.link);
  std::printf("fake board on %s", board.slave_path().c_str());
  if (!args.link.empty()) std::printf(" (link %s)", board.link_path().c_str());
  std::printf("\n");
  std::fflush(stdout);

  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
  std::signal(SIGUSR1, OnToggleSignal);
  platform::SteadyClock clock;
  double last_s = clock.NowS();
  double next_status_s = 1.0;
  bool unplugged_by_schedule = false;
  bool replugged_by_schedule = false;
  while (!g_stop) {
    const double now_s = clock.NowS();
    if (args.duration_s > 0.0 && now_s >= args.duration_s) break;
    board.Pump(now_s - last_s);
    last_s = now_s;
    const bool plugged = board.board().plugged();
    if (args.unplug_at_s >= 0.0 && !unplugged_by_schedule && now_s >= args.unplug_at_s) {
      unplugged_by_schedule = true;
      board.Unplug();
      std::printf("t %.3f s: unplugged\n", now_s);
      std::fflush(stdout);
    } else if (args.replug_at_s >= 0.0 && unplugged_by_schedule && !replugged_by_schedule &&
               now_s >= args.replug_at_s) {
      replugged_by_schedule = true;
      board.Replug(args.reset_on_replug);
      std::printf("t %.3f s: replugged on %s\n", now_s, board.slave_path().c_str());
      std::fflush(stdout);
    } else if (g_toggle_plug) {
      g_toggle_plug = 0;
      if (plugged) {
        board.Unplug();
        std::printf("t %.3f s: unplugged (SIGUSR1)\n", now_s);
      } else {
        board.Replug(args.reset_on_replug);
        std::printf("t %.3f s: replugged on %s (SIGUSR1)\n", now_s, board.slave_path().c_str());
      }
      std::fflush(stdout);
    }
    if (args.verbose && now_s >= next_status_s) {
      PrintBoardStatus(board.board());
      next_status_s += 1.0;
    }
    ::usleep(500);
  }
  PrintBoardStatus(board.board());
  return 0;
}

int RunPing(const PingArgs& args) {
  platform::SteadyClock clock;
  platform::SerialDriveBase drive(platform::MakeMrptSerialTransport(args.port, args.baud), clock);
  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
  double first_frame_s = -1.0;
  platform::EncoderTicks first{};
  bool commanded = false;
  while (!g_stop && clock.NowS() < args.seconds) {
    drive.Poll();
    if (drive.link_up() && first_frame_s < 0.0 && drive.stats().encoder_frames > 0) {
      first_frame_s = clock.NowS();
      first = drive.ReadEncoders();
    }
    if (drive.link_up() && args.speed_mps != 0.0 && !commanded) {
      drive.SetSpeedTargets(args.speed_mps, args.speed_mps);
      commanded = true;
    }
    ::usleep(1000);
  }
  if (commanded) {
    drive.Stop();
    for (int i = 0; i < 20; ++i) {  // let the STOP go out and be acknowledged
      drive.Poll();
      ::usleep(1000);
    }
  }
  const platform::SerialDriveStats& s = drive.stats();
  const platform::EncoderTicks last = drive.ReadEncoders();
  std::printf(
      "port %s: link %s (opened %llu times, up %llu times, lost %llu times)\n", args.port.c_str(),
      platform::LinkStateName(drive.link_state()), static_cast<unsigned long long>(s.port_opens),
      static_cast<unsigned long long>(s.link_ups), static_cast<unsigned long long>(s.link_losses));
  if (s.rtt_samples > 0) {
    std::printf("heartbeats: %llu answered, round trip mean %.2f ms, max %.2f ms\n",
                static_cast<unsigned long long>(s.rtt_samples),
                1e3 * s.sum_rtt_s / static_cast<double>(s.rtt_samples), 1e3 * s.max_rtt_s);
  } else {
    std::printf("heartbeats: none answered\n");
  }
  if (s.encoder_frames > 0 && first_frame_s >= 0.0) {
    const double span_s = std::max(1e-9, last.t_s - first.t_s);
    std::printf("encoders: %llu frames (%.1f Hz), ticks left %lld right %lld",
                static_cast<unsigned long long>(s.encoder_frames),
                static_cast<double>(s.encoder_frames - 1) / span_s,
                static_cast<long long>(last.left), static_cast<long long>(last.right));
    if (const auto& raw = drive.last_encoder_frame()) {
      std::printf(", pwm %d/%d, flags 0x%02x", raw->left_pwm, raw->right_pwm, raw->flags);
    }
    std::printf("\n");
  } else {
    std::printf("encoders: no frames\n");
  }
  std::printf(
      "host rx: %llu frames, %llu CRC errors, %llu length errors, %llu type errors, %llu bytes "
      "skipped, %llu duplicates; board rx errors %u, watchdog trips %u\n",
      static_cast<unsigned long long>(s.parser.frames_ok),
      static_cast<unsigned long long>(s.parser.crc_errors),
      static_cast<unsigned long long>(s.parser.length_errors),
      static_cast<unsigned long long>(s.parser.type_errors),
      static_cast<unsigned long long>(s.parser.bytes_skipped),
      static_cast<unsigned long long>(s.duplicate_encoder_frames), s.board_rx_errors,
      s.board_watchdog_trips);
  return s.rtt_samples > 0 && s.encoder_frames > 0 ? 0 : 1;
}

}  // namespace

void RegisterBoardCommand(CLI::App& app, CommandAction* action) {
  CLI::App* board =
      app.add_subcommand("board",
                         "The motor-controller board link: a fake board on a pty, ping a board.   "
                         "e.g. slamo board fake --link /tmp/slamo-board");
  board->require_subcommand(1);

  auto fake_args = std::make_shared<FakeArgs>();
  CLI::App* fake = board->add_subcommand(
      "fake",
      "Run the fake board (firmware logic + simulated motors) on a pseudo-terminal; prints the "
      "device path.   e.g. slamo board fake --link /tmp/slamo-board --drop 0.05");
  fake->add_option("--robot", fake_args->robot, "robot name or .yaml file")->capture_default_str();
  fake->add_option("--link", fake_args->link,
                   "also keep a symlink here to the current pty (survives replugging)");
  fake->add_option("--seed", fake_args->seed, "random seed (slip, faults)")->capture_default_str();
  fake->add_option("--duration", fake_args->duration_s, "seconds to run (0: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  fake->add_option("--garbage", fake_args->garbage, "probability of garbage before a frame")
      ->check(CLI::Range(0.0, 1.0));
  fake->add_option("--drop", fake_args->drop, "probability a frame is dropped (both ways)")
      ->check(CLI::Range(0.0, 1.0));
  fake->add_option("--duplicate", fake_args->duplicate, "probability a frame is sent twice")
      ->check(CLI::Range(0.0, 1.0));
  fake->add_option("--delay-ms", fake_args->delay_ms, "delay added to every frame (ms)")
      ->check(CLI::NonNegativeNumber);
  fake->add_option("--jitter-ms", fake_args->jitter_ms, "plus a uniform random delay (ms)")
      ->check(CLI::NonNegativeNumber);
  fake->add_option("--unplug-at", fake_args->unplug_at_s, "close the pty after this many s")
      ->check(CLI::NonNegativeNumber);
  fake->add_option("--replug-at", fake_args->replug_at_s, "open a new pty after this many s")
      ->check(CLI::NonNegativeNumber);
  fake->add_flag("--reset-on-replug", fake_args->reset_on_replug,
                 "the board restarts when replugged (USB-powered), counts from 0");
  fake->add_flag("--verbose,-v", fake_args->verbose, "a status line every second");
  fake->footer("SIGUSR1 unplugs / replugs the board.");
  fake->callback([action, fake_args] { *action = [fake_args] { return RunFake(*fake_args); }; });

  auto ping_args = std::make_shared<PingArgs>();
  CLI::App* ping = board->add_subcommand(
      "ping",
      "Heartbeat round trips and the encoder stream of a real or fake board.   "
      "e.g. slamo board ping --port /dev/ttyACM0 --seconds 3");
  ping->add_option("--port", ping_args->port, "serial device (or the fake board's pty/link)")
      ->required();
  ping->add_option("--baud", ping_args->baud, "baud rate")->capture_default_str();
  ping->add_option("--seconds", ping_args->seconds, "how long to listen")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  ping->add_option("--speed", ping_args->speed_mps,
                   "drive both sides at this speed (m/s) meanwhile; stops at the end")
      ->check(CLI::Range(-0.5, 0.5));
  ping->callback([action, ping_args] { *action = [ping_args] { return RunPing(*ping_args); }; });
}

}  // namespace slamo::autonomy
