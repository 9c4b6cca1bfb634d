// `slamo match`: the match-day run on the robot. The executive (autonomy/executive.cc) runs on
// HardwareIo (autonomy/hardware_io.h): the motor-controller board over its serial link and an
// RGB-D camera, with the report of a dry run (no points or truth: there is no referee).
//
//   slamo match --port /dev/ttyACM0                      the robot: its board, its OpenNI2 camera
//   slamo match --port DEV --recording rec/              a recorded camera stream instead
//   slamo match --fake-board --recording rec/ --loop     no robot at all: the fake board (the
//                                                        firmware's logic on the simulator's
//                                                        motors) on a pseudo-terminal, the whole
//                                                        serial stack over it, simulated time
//   slamo match --fake-board --camera sim                the fake board, and the simulated
//                                                        field's camera rendered from the fake
//                                                        board's true pose (SLAM-O closes the
//                                                        loop; pose ATE against that truth)
//
// On a real board the match runs on the machine's clock; with --fake-board on simulated time
// (as fast as the computer goes; --real-time paces it). The board's watchdog stops the
// motors 50 ms after the host goes quiet; the executive stops them at the deadline.
// Exit status: 0 after a run, 1 when the board did not answer or a file cannot be written,
// 2 on bad input, 3 when the camera cannot be opened.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include "autonomy/commands/commands.h"
#include "autonomy/executive.h"
#include "autonomy/hardware_io.h"
#include "autonomy/match_report.h"
#include "field_configs/loader.h"
#include "mapping/frame_selection.h"
#include "platform/fake_board.h"
#include "platform/openni2_camera.h"
#include "platform/recording.h"
#include "platform/serial_drive_base.h"
#include "platform/sim_renderer.h"
#include "platform/sim_world.h"
#include "strategy/strategy.h"

namespace slamo::autonomy {
namespace {

struct MatchArgs {
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  std::string strategy = "planner";
  std::string frames = "covariance";
  std::string out = "match";
  std::string alliance = "red";
  int start_index = 0;
  uint64_t seed = 1;
  std::string port;
  int baud = 115200;
  bool fake_board = false;
  bool real_time = false;
  std::string camera;  // openni2 | sim (fake board only); default: recording or openni2
  std::string recording;
  bool loop = false;
  double odometry_scale = 1.0;
  double speed_mps = 0.0;
  // Fault injection on the fake board's link.
  double drop = 0.0, garbage = 0.0, duplicate = 0.0;
  double unplug_at_s = -1.0, replug_at_s = -1.0;
  std::string record;  // a TUM RGB-D folder for the match's frames, encoders (and truth)
  bool video = true;
  bool quiet = false;
};

int Match(const MatchArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  MatchSetup setup;
  setup.strategy = args.strategy;
  setup.drive_speed_mps = args.speed_mps;
  setup.gyro = false;            // the board streams no gyro (platform/PROTOCOL.md)
  setup.placement_jitter_m = 0;  // the field as its file has it
  setup.start_index = args.start_index;
  try {
    mapping::ParseFrameRule(args.frames, &setup.frames);
    strategy::MakeStrategy(args.strategy, setup.strategy_options);
    if (args.alliance != "red" && args.alliance != "blue")
      throw std::invalid_argument("--alliance: expected red or blue, got \"" + args.alliance +
                                  "\"");
    setup.alliance = args.alliance == "red" ? field::Alliance::kRed : field::Alliance::kBlue;
    StartPose(season, setup.alliance, setup.start_index);
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (args.port.empty() == !args.fake_board) {
    std::cerr << "error: give the board's serial device (--port DEV) or --fake-board\n";
    return 2;
  }
  std::string camera = args.camera;
  if (camera.empty()) camera = !args.recording.empty() ? "recording" : "openni2";
  if (camera == "recording" && args.recording.empty()) {
    std::cerr << "error: --camera recording needs --recording PATH\n";
    return 2;
  }
  if (camera == "sim" && !args.fake_board) {
    std::cerr << "error: --camera sim renders the simulated field from the fake board's motors: "
                 "it needs --fake-board\n";
    return 2;
  }
  if (camera != "recording" && camera != "openni2" && camera != "sim") {
    std::cerr << "error: --camera: expected openni2, recording or sim, got \"" << camera << "\"\n";
    return 2;
  }
  if (!CreateOutputDir(args.out)) return 1;

  // The clock: the machine's on the robot; simulated with the fake board unless --real-time.
  platform::SteadyClock steady;
  platform::SimClock simulated;
  const bool sim_time = args.fake_board && !args.real_time;
  const platform::Clock& base_clock =
      sim_time ? static_cast<const platform::Clock&>(simulated) : steady;

  // The board: on its serial device, or the fake one on a pseudo-terminal in this process.
  std::unique_ptr<platform::PtyFakeBoard> fake;
  std::string device = args.port;
  if (args.fake_board) {
    platform::FakeBoardOptions options;
    options.seed = args.seed;
    options.faults.drop_probability = args.drop;
    options.faults.garbage_probability = args.garbage;
    options.faults.duplicate_probability = args.duplicate;
    fake = std::make_unique<platform::PtyFakeBoard>(robot.drive, options);
    device = fake->device_path();
  }
  platform::SerialDriveOptions link_options;
  link_options.pid = robot.drive.pid;
  platform::SerialDriveBase board(platform::MakeMrptSerialTransport(device, args.baud), base_clock,
                                  link_options);
  bool unplugged = false, replugged = false;
  const auto pace = [&](double dt_s) {
    if (fake) {
      fake->Pump(dt_s);
      if (args.unplug_at_s >= 0 && !unplugged && base_clock.NowS() >= args.unplug_at_s) {
        fake->Unplug();
        unplugged = true;
        std::cout << "  [board clock " << base_clock.NowS() << " s] fake board unplugged\n";
      }
      if (unplugged && !replugged && args.replug_at_s >= 0 &&
          base_clock.NowS() >= args.replug_at_s) {
        fake->Replug();
        replugged = true;
        std::cout << "  [board clock " << base_clock.NowS() << " s] fake board plugged in again\n";
      }
    }
    if (sim_time) {
      // The kernel passes the pty's bytes on in its own time: give it a moment per step.
      ::usleep(150);
      simulated.Advance(dt_s);
    } else {
      std::this_thread::sleep_for(std::chrono::duration<double>(dt_s));
    }
  };

  // The camera.
  const platform::Pose2D start = StartPose(season, setup.alliance, setup.start_index);
  // The match clock (0 at the start) for a recorded stream is the base clock from Start();
  // the stream camera reads the HardwareIo's match clock, so it is created after it.
  HardwareIoOptions io_options;
  io_options.alliance = setup.alliance;
  io_options.odometry_scale = args.odometry_scale;
  io_options.board_name = args.fake_board ? "fake board on " + device : device;
  std::unique_ptr<platform::RgbdCamera> camera_device;
  std::unique_ptr<FakeBoardCamera> sim_camera;
  std::unique_ptr<platform::RecordingReader> reader;
  try {
    if (camera == "recording") {
      reader = platform::OpenRecording(args.recording);
      io_options.camera_name = "recording " + args.recording;
    } else if (camera == "sim") {
      sim_camera = std::make_unique<FakeBoardCamera>(season, robot, fake->board(), start,
                                                     base_clock, args.seed);
      io_options.camera_name = "simulated field seen from the fake board's motors";
      FakeBoardCamera* c = sim_camera.get();
      io_options.truth = [c]() { return std::optional<platform::Pose2D>(c->Truth()); };
    } else {
      camera_device = std::make_unique<platform::OpenNI2Camera>(robot.camera);
      io_options.camera_name = "openni2 " + robot.camera.model;
    }
  } catch (const platform::RecordingError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const platform::CameraError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 3;
  }

  std::unique_ptr<platform::RecordingWriter> recorder;
  if (!args.record.empty()) {
    try {
      platform::RecordingInfo info = platform::RecordingInfoFor(robot);
      info.source = args.fake_board ? "fake board" : "robot";
      info.description = "slamo match on " + season.season + ": board " + io_options.board_name +
                         ", camera " + io_options.camera_name;
      recorder = platform::OpenTumWriter(args.record, info);
    } catch (const platform::RecordingError& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
    io_options.recorder = recorder.get();
  }

  // A recorded stream plays against the match clock, which only exists inside HardwareIo:
  // a small forwarding camera resolves it on first use.
  struct Forward : platform::RgbdCamera {
    std::function<std::optional<platform::RgbdFrame>()> grab;
    std::optional<platform::RgbdFrame> Grab() override { return grab(); }
  } forward;
  auto io = std::make_unique<HardwareIo>(&board, &forward, base_clock, pace, io_options);
  std::unique_ptr<RecordedStreamCamera> stream;
  if (reader)
    stream = std::make_unique<RecordedStreamCamera>(std::move(reader), io->clock(), args.loop);
  forward.grab = [&]() -> std::optional<platform::RgbdFrame> {
    if (stream) return stream->Grab();
    if (sim_camera) return sim_camera->Grab();
    return camera_device->Grab();
  };

  std::cout << "match: " << season.name << " (" << season.season << "), "
            << season.rules.autonomous_s << " s autonomous, robot " << robot.name << ", strategy "
            << args.strategy << "\n  board  " << io_options.board_name << "\n  camera "
            << io_options.camera_name << "\n";
  if (!io->Connect()) {
    std::cerr << "error: the board on " << device << " did not answer within "
              << io_options.connect_timeout_s << " s (link "
              << platform::LinkStateName(board.link_state())
              << "); check the cable and `slamo board ping --port " << device << "`\n";
    return 1;
  }
  std::cout << "  link up after " << base_clock.NowS() << " s; the match starts now\n";

  MatchResult result;
  try {
    result = RunMatchOn(
        std::move(io), strategy::MakeStrategy(args.strategy, setup.strategy_options), season, robot,
        setup, args.seed, args.out, [&](const TimelineEntry& e) {
          if (!args.quiet)
            std::cout << "  [" << e.t_s << " s] " << e.action << " " << e.detail << std::endl;
        });
  } catch (const platform::RecordingError& e) {
    board.Stop();
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const platform::CameraError& e) {
    board.Stop();
    std::cerr << "error: the camera failed during the match: " << e.what() << "\n";
    return 3;
  }
  board.Stop();
  if (recorder) {
    try {
      recorder->Close();
    } catch (const platform::RecordingError& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 1;
    }
  }
  PrintSummary(result, std::cout);
  if (fake) {
    const platform::FakeBoard& b = fake->board();
    std::cout << "  fake board      motors stopped at board time " << b.last_stop_s()
              << " s; PWM now " << static_cast<int>(b.logic().left_pwm()) << "/"
              << static_cast<int>(b.logic().right_pwm()) << "; watchdog trips "
              << b.logic().watchdog_trips() << "\n";
  }
  try {
    const std::vector<std::string> written = WriteMatchFiles(result, args.out, args.video);
    std::cout << "wrote " << args.out << "/{" << Join(written) << ", objects.bt}\n";
    if (recorder) std::cout << "recorded the match in " << args.record << "\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

void RegisterMatchCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<MatchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "match",
      "the match-day autonomous run on the robot: the board over its serial link and an RGB-D "
      "camera (or a fake board and a recorded stream), with a report");
  cmd->add_option("--season", args->season, "season name or YAML file")->capture_default_str();
  cmd->add_option("--robot", args->robot, "robot YAML file")->capture_default_str();
  cmd->add_option("--strategy", args->strategy, "planner | greedy | scripted | thesis")
      ->capture_default_str();
  cmd->add_option("--frames", args->frames,
                  "frame rule at every observation: fixed:N | covariance | gmm")
      ->capture_default_str();
  cmd->add_option("--alliance", args->alliance, "red | blue")->capture_default_str();
  cmd->add_option("--start", args->start_index, "starting tile, among the alliance's")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "seeds the planners (and the fake board)")
      ->capture_default_str();
  cmd->add_option("--out", args->out, "directory for report.json, map.png, trajectory.tum, ...")
      ->capture_default_str();
  cmd->add_option("--port", args->port, "the motor-controller board's serial device");
  cmd->add_option("--baud", args->baud, "serial speed")->capture_default_str();
  cmd->add_flag("--fake-board", args->fake_board,
                "the fake board on a pseudo-terminal in this process, instead of --port");
  cmd->add_flag("--real-time", args->real_time,
                "with --fake-board: run on the machine's clock, not simulated time");
  cmd->add_option("--camera", args->camera,
                  "openni2 | recording | sim (default: recording with --recording, else "
                  "openni2)");
  cmd->add_option("--recording", args->recording,
                  "a recorded camera stream (TUM folder or rawlog) played against the match clock");
  cmd->add_flag("--loop", args->loop, "start the recording again when it ends");
  cmd->add_option("--odometry-scale", args->odometry_scale,
                  "true distance per encoder distance, measured on the robot's floor")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 1.5));
  cmd->add_option("--speed", args->speed_mps, "driving speed (m/s); 0: the robot's match_speed_mps")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 5.0));
  cmd->add_option("--drop", args->drop, "fake board: drop each frame with this probability")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--garbage", args->garbage,
                  "fake board: garbage bytes before a frame with this probability")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--duplicate", args->duplicate,
                  "fake board: send a frame twice with this probability")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--unplug-at", args->unplug_at_s, "fake board: pull the cable at this time (s)");
  cmd->add_option("--replug-at", args->replug_at_s,
                  "fake board: plug it in again at this time (s)");
  cmd->add_option("--record", args->record,
                  "record the match (frames, encoder ticks, the truth when known) as a TUM RGB-D "
                  "folder, for `slamo dry-run --from-recording`");
  cmd->add_flag("!--no-video", args->video, "skip replay.avi");
  cmd->add_flag("--quiet", args->quiet, "no line per action");
  cmd->callback([args, action]() { *action = [args]() { return Match(*args); }; });
}

}  // namespace slamo::autonomy
