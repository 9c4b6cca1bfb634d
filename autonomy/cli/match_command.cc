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
#include <cmath>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include "autonomy/cli/commands.h"
#include "autonomy/cli/options.h"
#include "autonomy/io/robot_rig.h"
#include "autonomy/loop/executive.h"
#include "autonomy/reports/match_report.h"
#include "field_configs/loader.h"
#include "mapping/frame_selection.h"
#include "platform/field_geometry.h"
#include "platform/openni2_camera.h"
#include "platform/recording.h"
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
  BoardArgs board;  // camera: openni2 | sim (fake board only); default: recording or openni2
  bool real_time = false;
  std::string recording;
  bool loop = false;
  double odometry_scale = 1.0;
  double speed_mps = 0.0;
  double moving_frames_s = 0.0;  // frames while driving: off on the robot until tried there
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
  // Frames while driving (and the legs steered from them) are the simulator's default, but
  // here they are opt-in: the camera's Grab may wait for its next frame, and the frame's
  // processing runs inside the drive controller's period with no heartbeat to the board (its
  // watchdog stops the motors after 50 ms). Not yet tried on a robot.
  setup.moving_frame_period_s = args.moving_frames_s;
  setup.steer_on_estimate = args.moving_frames_s > 0.0;
  try {
    mapping::ParseFrameRule(args.frames, &setup.frames);
    strategy::MakeStrategy(args.strategy, setup.strategy_options);
    if (args.alliance != "red" && args.alliance != "blue")
      throw std::invalid_argument("--alliance: expected red or blue, got \"" + args.alliance +
                                  "\"");
    setup.alliance = args.alliance == "red" ? field::Alliance::kRed : field::Alliance::kBlue;
    platform::StartPose(season, setup.alliance, setup.start_index);
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  RigOptions rig_options = RigOptionsFrom(args.board);
  rig_options.real_time = args.real_time;
  rig_options.recording = args.recording;
  rig_options.loop = args.loop;
  rig_options.seed = args.seed;
  rig_options.faults.drop_probability = args.drop;
  rig_options.faults.garbage_probability = args.garbage;
  rig_options.faults.duplicate_probability = args.duplicate;
  rig_options.unplug_at_s = args.unplug_at_s;
  rig_options.replug_at_s = args.replug_at_s;
  rig_options.io.alliance = setup.alliance;
  rig_options.io.odometry_scale = args.odometry_scale;
  std::unique_ptr<Rig> rig;
  std::unique_ptr<platform::RecordingWriter> recorder;
  try {
    rig = std::make_unique<Rig>(rig_options, season, robot,
                                platform::StartPose(season, setup.alliance, setup.start_index));
    if (!CreateOutputDir(args.out)) return 1;
    if (!args.record.empty()) {
      platform::RecordingInfo info = platform::RecordingInfoFor(robot);
      info.source = args.board.fake_board ? "fake board" : "robot";
      info.description = "slamo match on " + season.season + ": board " + rig->board_name() +
                         ", camera " + rig->camera_name();
      recorder = platform::OpenTumWriter(args.record, info);
      rig->SetRecorder(recorder.get());
    }
    std::cout << "match: " << season.name << " (" << season.season << "), "
              << season.rules.autonomous_s << " s autonomous, robot " << robot.name << ", strategy "
              << args.strategy << "\n  board  " << rig->board_name() << "\n  camera "
              << rig->camera_name() << "\n";
    rig->Connect();
  } catch (const RigError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return e.exit_status;
  } catch (const platform::RecordingError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  std::cout << "  link up after " << rig->base_clock().NowS() << " s; the match starts now\n";
  platform::SerialDriveBase& board = rig->board();

  MatchResult result;
  try {
    result = RunMatchOn(
        rig->TakeIo(), strategy::MakeStrategy(args.strategy, setup.strategy_options), season, robot,
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
  if (platform::PtyFakeBoard* fake = rig->fake()) {
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
  AddSeasonRobotOptions(cmd, &args->season, &args->robot);
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
  AddBoardOptions(cmd, &args->board,
                  {"the motor-controller board's serial device",
                   "the fake board on a pseudo-terminal in this process, instead of --port",
                   "openni2 | recording | sim (default: recording with --recording, else "
                   "openni2)"});
  cmd->add_flag("--real-time", args->real_time,
                "with --fake-board: run on the machine's clock, not simulated time");
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
  cmd->add_option("--moving-frames", args->moving_frames_s,
                  "s between frames taken while driving, legs steered from them and a quick "
                  "look every 2.4 m of path instead of 1.2 (0: frames only at stops; not yet "
                  "tried on a robot)")
      ->check(CLI::Range(0.0, 5.0))
      ->capture_default_str();
  cmd->callback([args, action]() { *action = [args]() { return Match(*args); }; });
}

}  // namespace slamo::autonomy
