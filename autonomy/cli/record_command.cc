// `slamo record`: save a run as a TUM RGB-D folder and / or an MRPT rawlog (formats in
// platform/RECORDING.md). With --sim the simulator drives a script on the whole field and
// renders the camera; with --port DEV (or --fake-board) the board drives the script over its
// serial link and its encoder ticks are recorded with the camera's frames (the OpenNI2
// camera; with the fake board, the simulated field seen from its motors); with neither, a real
// OpenNI2 camera alone is recorded.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/cli/commands.h"
#include "autonomy/cli/options.h"
#include "autonomy/io/robot_rig.h"
#include "field_configs/config_error.h"
#include "field_configs/loader.h"
#include "platform/clock.h"
#include "platform/drive_script.h"
#include "platform/field_geometry.h"
#include "platform/openni2_camera.h"
#include "platform/recording.h"
#include "platform/sim/sim_recording.h"

namespace slamo::autonomy {
namespace {

namespace fs = std::filesystem;
using platform::kPi;
using platform::Pose2D;

constexpr const char* kRawlogName = "recording.rawlog";

struct RecordArgs {
  bool sim = false;
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  uint64_t seed = 1;
  std::string pose;  // "X,Y,THETA_DEG"; empty: the first red starting tile
  std::string script = "forward 0.3; turn 90; forward 0.3";
  double fps = 5.0;
  double duration_s = 10.0;  // real camera only
  std::string out;
  std::string format = "both";
  bool overwrite = false;
  // The board (--port or --fake-board) and the camera with it (autonomy/robot_rig.h).
  BoardArgs board;
};

// Every frame and reading into each writer the format asked for, counted.
class TeeWriter : public platform::RecordingWriter {
 public:
  explicit TeeWriter(std::vector<platform::RecordingWriter*> writers)
      : writers_(std::move(writers)) {}
  void AddFrame(const platform::RgbdFrame& frame) override {
    for (auto* w : writers_) w->AddFrame(frame);
    ++frames;
  }
  void AddEncoders(const platform::EncoderTicks& ticks) override {
    for (auto* w : writers_) w->AddEncoders(ticks);
    ++encoder_readings;
  }
  void AddGroundTruth(const platform::StampedPose& pose) override {
    for (auto* w : writers_) w->AddGroundTruth(pose);
    ++ground_truth_poses;
  }
  void Close() override {
    for (auto* w : writers_) w->Close();
  }
  const std::string& path() const override { return writers_.front()->path(); }
  int frames = 0, encoder_readings = 0, ground_truth_poses = 0;

 private:
  std::vector<platform::RecordingWriter*> writers_;
};

bool WantTum(const RecordArgs& args) { return args.format == "tum" || args.format == "both"; }
bool WantRawlog(const RecordArgs& args) { return args.format == "rawlog" || args.format == "both"; }

// Removes what an earlier recording left in `dir` (only the entries a recording writes).
void RemoveOldRecording(const std::string& dir) {
  for (const char* entry : {"rgb", "depth", "rgb.txt", "depth.txt", "groundtruth.txt",
                            "encoders.txt", "recording.json", kRawlogName}) {
    std::error_code ec;
    fs::remove_all(fs::path(dir) / entry, ec);
  }
}

// The writers the format asks for; throws RecordingError.
std::vector<std::unique_ptr<platform::RecordingWriter>> OpenWriters(
    const RecordArgs& args, const platform::RecordingInfo& info) {
  if (args.overwrite) RemoveOldRecording(args.out);
  std::vector<std::unique_ptr<platform::RecordingWriter>> writers;
  if (WantTum(args)) writers.push_back(platform::OpenTumWriter(args.out, info));
  if (WantRawlog(args)) {
    std::error_code ec;
    fs::create_directories(args.out, ec);
    const std::string rawlog = (fs::path(args.out) / kRawlogName).string();
    if (!args.overwrite && fs::exists(rawlog, ec)) {
      throw platform::RecordingError(rawlog + ": already exists (--overwrite replaces it)");
    }
    writers.push_back(platform::OpenRawlogWriter(rawlog, info));
  }
  return writers;
}

void PrintWritten(const RecordArgs& args, bool truth, bool encoders) {
  if (WantTum(args)) {
    std::printf("  TUM RGB-D folder: %s (rgb/, depth/, rgb.txt, depth.txt, %s%srecording.json)\n",
                args.out.c_str(), truth ? "groundtruth.txt, " : "",
                encoders ? "encoders.txt, " : "");
  }
  if (WantRawlog(args)) {
    std::printf("  MRPT rawlog:      %s\n", (fs::path(args.out) / kRawlogName).string().c_str());
  }
}

int RecordSim(const RecordArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  const Pose2D start = PoseOrFirstStart(season, args.pose);
  if (!platform::FootprintIsFree(season, start, robot.length_m, robot.width_m, robot.height_m)) {
    std::cerr << "error: --pose " << args.pose
              << ": the robot does not fit there (wall or structure)\n";
    return 2;
  }
  try {
    platform::ParseDriveScript(args.script);
  } catch (const platform::DriveScriptError& e) {
    std::cerr << "error: --script: " << e.what() << "\n";
    return 2;
  }
  if (!(args.fps > 0.0 && args.fps <= 50.0)) {
    std::cerr << "error: --fps must be in (0, 50] (one frame per 20 ms control step at most)\n";
    return 2;
  }

  platform::RecordingInfo info = platform::RecordingInfoFor(robot);
  info.source = "sim";
  std::ostringstream description;
  description << "slamo simulator: season " << season.season << ", seed " << args.seed << ", start "
              << start.x_m << "," << start.y_m << "," << start.theta_rad * 180.0 / kPi
              << " deg, script \"" << args.script << "\"";
  info.description = description.str();

  std::vector<std::unique_ptr<platform::RecordingWriter>> writers;
  try {
    writers = OpenWriters(args, info);
  } catch (const platform::RecordingError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  std::vector<platform::RecordingWriter*> raw;
  for (const auto& w : writers) raw.push_back(w.get());

  platform::SimRecordingOptions options;
  options.seed = args.seed;
  options.start = start;
  options.script = args.script;
  options.fps = args.fps;
  const bool tty = isatty(STDERR_FILENO) != 0;
  double next_report_s = 0.0;
  auto progress = [&](const platform::SimRecordingSummary& s, double t_s) {
    if (tty) {
      std::fprintf(stderr, "\rrecording: %6.2f s simulated, %d frames, %d encoder readings", t_s,
                   s.frames, s.encoder_readings);
    } else if (t_s >= next_report_s) {
      std::fprintf(stderr, "recording: %6.2f s simulated, %d frames, %d encoder readings\n", t_s,
                   s.frames, s.encoder_readings);
      next_report_s += 5.0;
    }
    std::fflush(stderr);
  };
  platform::SimRecordingSummary summary;
  try {
    summary = platform::RecordSimulatedRun(season, robot, options, raw, progress);
    for (const auto& w : writers) w->Close();
  } catch (const platform::RecordingError& e) {
    if (tty) std::fprintf(stderr, "\n");
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  if (tty) std::fprintf(stderr, "\n");
  int timed_out = 0;
  for (const auto& r : summary.steps) timed_out += r.status != platform::DriveStepStatus::kDone;
  std::printf(
      "recorded %.2f s of %s driving \"%s\" on %s (seed %llu): %d frames at %g Hz, %d encoder "
      "readings, %d ground-truth poses%s\n",
      summary.duration_s, robot.name.c_str(), args.script.c_str(), season.season.c_str(),
      static_cast<unsigned long long>(args.seed), summary.frames, args.fps,
      summary.encoder_readings, summary.ground_truth_poses,
      timed_out > 0 ? " (a step timed out)" : "");
  PrintWritten(args, true, true);
  return 0;
}

int RecordCamera(const RecordArgs& args) {
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  if (!platform::IsOpenNI2CameraModel(robot.camera.model)) {
    std::cerr << "error: without --sim, slamo record records the robot's real camera through the "
                 "OpenNI2 backend, and camera.model '"
              << robot.camera.model << "' in " << robot.source_file
              << " is not an OpenNI2 device (OpenNI2 drives " << platform::kOpenNI2Models
              << "; a Kinect V2 needs libfreenect2, which slamo does not use). For encoder "
                 "ticks give the board's serial device (--port DEV, or --fake-board); use --sim "
                 "to record the simulator.\n";
    return 2;
  }
  if (!(args.fps > 0.0) || !(args.duration_s > 0.0)) {
    std::cerr << "error: --fps and --duration must be positive\n";
    return 2;
  }
  std::unique_ptr<platform::OpenNI2Camera> camera;
  try {
    camera = std::make_unique<platform::OpenNI2Camera>(robot.camera);
  } catch (const platform::CameraError& e) {
    std::cerr << "error: " << e.what() << " (use --sim to record the simulator)\n";
    return 2;
  }
  platform::RecordingInfo info = platform::RecordingInfoFor(robot);
  info.source = "openni2";
  info.description = "OpenNI2 camera " + robot.camera.model + "; no encoders (no board)";
  std::vector<std::unique_ptr<platform::RecordingWriter>> writers;
  try {
    writers = OpenWriters(args, info);
  } catch (const platform::RecordingError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  std::fprintf(stderr, "recording %s for %.1f s at up to %g Hz; encoders are not recorded\n",
               robot.camera.model.c_str(), args.duration_s, args.fps);
  const platform::SteadyClock clock;
  int frames = 0;
  double last_t = -1e300;
  try {
    while (clock.NowS() < args.duration_s) {
      std::optional<platform::RgbdFrame> frame = camera->Grab();
      if (!frame || frame->t_s < last_t + 1.0 / args.fps) continue;
      for (const auto& w : writers) w->AddFrame(*frame);
      last_t = frame->t_s;
      ++frames;
      std::fprintf(stderr, "\rrecording: %6.2f s, %d frames", clock.NowS(), frames);
    }
    for (const auto& w : writers) w->Close();
  } catch (const std::exception& e) {
    std::cerr << "\nerror: " << e.what() << "\n";
    return 1;
  }
  std::printf("\nrecorded %d frames from %s\n", frames, robot.camera.model.c_str());
  PrintWritten(args, false, false);
  return 0;
}

// The board drives the script over its serial link with the drive controller the simulator
// uses; the camera is grabbed at --fps and every control period's encoder ticks (and the truth,
// on the fake board) are recorded on the run's clock (0 at the start).
int RecordBoard(const RecordArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  std::vector<platform::DriveStep> steps;
  Pose2D start;
  try {
    start = PoseOrFirstStart(season, args.pose);
    steps = platform::ParseDriveScript(args.script);
  } catch (const platform::DriveScriptError& e) {
    std::cerr << "error: --script: " << e.what() << "\n";
    return 2;
  }
  if (!(args.fps > 0.0 && args.fps <= 50.0)) {
    std::cerr << "error: --fps must be in (0, 50]\n";
    return 2;
  }
  RigOptions rig_options = RigOptionsFrom(args.board);
  if (args.board.camera.empty() && args.board.fake_board) rig_options.camera = "sim";
  rig_options.seed = args.seed;
  rig_options.io.frame_wait_s = 0.0;  // never hold up the drive controller for a frame
  std::unique_ptr<Rig> rig;
  std::vector<std::unique_ptr<platform::RecordingWriter>> writers;
  std::unique_ptr<TeeWriter> tee;
  try {
    rig = std::make_unique<Rig>(rig_options, season, robot, start);
    platform::RecordingInfo info = platform::RecordingInfoFor(robot);
    info.source = args.board.fake_board ? "fake board" : "board";
    info.description = "slamo record: board " + rig->board_name() + ", camera " +
                       rig->camera_name() + ", script \"" + args.script + "\"";
    writers = OpenWriters(args, info);
    std::vector<platform::RecordingWriter*> raw;
    for (const auto& w : writers) raw.push_back(w.get());
    tee = std::make_unique<TeeWriter>(raw);
    rig->SetRecorder(tee.get());
    rig->Connect();
  } catch (const RigError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return e.exit_status;
  } catch (const platform::RecordingError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  std::unique_ptr<HardwareIo> io = rig->TakeIo();
  io->Start(season, robot, start);
  const double period_s = 1.0 / args.fps;
  double next_frame_s = 0.0;
  const auto grab = [&]() {
    if (io->clock().NowS() + 1e-9 < next_frame_s) return;
    io->Capture();
    next_frame_s += period_s;
  };
  platform::DriveBodyLink body = DriveLinkFor(*io, robot);
  body.advance = [&](double dt_s) {
    io->Advance(dt_s);
    grab();
  };
  std::vector<platform::DriveStepResult> results;
  try {
    grab();
    results =
        platform::RunDriveScript(steps, platform::DriveControllerOptionsFor(robot.drive), body);
    io->drive().Stop();
    io->Advance(0.1);
    tee->Close();
  } catch (const platform::RecordingError& e) {
    io->drive().Stop();
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const platform::CameraError& e) {
    io->drive().Stop();
    std::cerr << "error: the camera failed: " << e.what() << "\n";
    return 3;
  }
  int timed_out = 0;
  for (const auto& r : results) timed_out += r.status != platform::DriveStepStatus::kDone;
  const std::map<std::string, double> status = io->Status();
  std::printf(
      "recorded %.2f s of %s driving \"%s\" on %s: %d frames, %d encoder readings, %d "
      "ground-truth poses; link losses %.0f%s\n",
      io->clock().NowS(), rig->board_name().c_str(), args.script.c_str(), robot.name.c_str(),
      tee->frames, tee->encoder_readings, tee->ground_truth_poses, status.at("link_losses"),
      timed_out > 0 ? " (a step timed out)" : "");
  PrintWritten(args, tee->ground_truth_poses > 0, true);
  return 0;
}

}  // namespace

void RegisterRecordCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<RecordArgs>();
  CLI::App* record = app.add_subcommand(
      "record",
      "Record a run (colour, depth, encoders, truth) as a TUM RGB-D folder and an MRPT rawlog.   "
      "e.g. slamo record --sim --script \"forward 0.3; turn 90\" --out DIR");
  record->add_flag("--sim", args->sim,
                   "record the simulator driving --script (without it: the board with --port or "
                   "--fake-board, else a real OpenNI2 camera alone)");
  AddSeasonRobotOptions(record, &args->season, &args->robot);
  record->add_option("--seed", args->seed, "random seed (--sim: layout, slip, lighting, noise)")
      ->capture_default_str();
  record->add_option("--pose", args->pose,
                     "start pose X,Y,THETA in m, m, deg (--sim; default: first red start tile)");
  record
      ->add_option("--script", args->script,
                   "drive script (--sim): forward M; back M; turn DEG; wait S")
      ->capture_default_str();
  record->add_option("--fps", args->fps, "camera frames per second")->capture_default_str();
  record->add_option("--duration", args->duration_s, "seconds to record (real camera)")
      ->capture_default_str();
  record->add_option("--out,-o", args->out, "output folder")->required();
  record
      ->add_option("--format", args->format,
                   "tum: the TUM RGB-D folder; rawlog: OUT/recording.rawlog; both")
      ->check(CLI::IsMember({"tum", "rawlog", "both"}))
      ->capture_default_str();
  record->add_flag("--overwrite", args->overwrite,
                   "replace a recording already in the output folder");
  AddBoardOptions(record, &args->board,
                  {"the motor-controller board's serial device: it drives --script and its "
                   "encoder ticks are recorded with the camera",
                   "the fake board on a pseudo-terminal in this process, on simulated time "
                   "(camera: the simulated field seen from its motors)",
                   "with --port or --fake-board: openni2 | sim (fake board only)"});
  record->callback([action, args] {
    *action = [args] {
      if (args->sim) return RecordSim(*args);
      if (!args->board.port.empty() || args->board.fake_board) return RecordBoard(*args);
      return RecordCamera(*args);
    };
  });
}

}  // namespace slamo::autonomy
