// `slamo record`: save a run as a TUM RGB-D folder and / or an MRPT rawlog (formats in
// platform/RECORDING.md). With --sim the simulator drives a script on the whole field and
// renders the camera; without it a real OpenNI2 camera is recorded (frames only: the motor
// board's encoders are not wired into recording yet).
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/commands/commands.h"
#include "field_configs/config_error.h"
#include "field_configs/loader.h"
#include "platform/clock.h"
#include "platform/drive_script.h"
#include "platform/openni2_camera.h"
#include "platform/recording.h"
#include "platform/sim_world.h"

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
};

// "X,Y,THETA" in metres and degrees.
Pose2D ParsePose(const std::string& text) {
  std::stringstream in(text);
  double v[3];
  char comma = 0;
  if (!(in >> v[0] >> comma) || comma != ',' || !(in >> v[1] >> comma) || comma != ',' ||
      !(in >> v[2]) || !in.eof()) {
    throw field::ConfigError("--pose", 0, 0, "pose",
                             "X,Y,THETA (metres, metres, degrees), got '" + text + "'");
  }
  return Pose2D{v[0], v[1], v[2] * kPi / 180.0};
}

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

void PrintWritten(const RecordArgs& args) {
  if (WantTum(args)) {
    std::printf("  TUM RGB-D folder: %s (rgb/, depth/, rgb.txt, depth.txt, %srecording.json)\n",
                args.out.c_str(), args.sim ? "groundtruth.txt, encoders.txt, " : "");
  }
  if (WantRawlog(args)) {
    std::printf("  MRPT rawlog:      %s\n", (fs::path(args.out) / kRawlogName).string().c_str());
  }
}

int RecordSim(const RecordArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  Pose2D start;
  if (args.pose.empty()) {
    const field::StartTile& tile = season.starts.front();
    start = Pose2D{tile.center_m.x, tile.center_m.y, tile.heading_deg * kPi / 180.0};
  } else {
    start = ParsePose(args.pose);
  }
  if (!platform::FootprintIsFree(season, start, robot.length_m, robot.width_m)) {
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
  PrintWritten(args);
  return 0;
}

int RecordCamera(const RecordArgs& args) {
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  if (!platform::IsOpenNI2CameraModel(robot.camera.model)) {
    std::cerr << "error: without --sim, slamo record records the robot's real camera through the "
                 "OpenNI2 backend, and camera.model '"
              << robot.camera.model << "' in " << robot.source_file
              << " is not an OpenNI2 device (OpenNI2 drives " << platform::kOpenNI2Models
              << "; a Kinect V2 needs libfreenect2, which slamo does not use). Encoder ticks "
                 "also need the motor-controller board on its serial link. Use --sim to record "
                 "the simulator.\n";
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
  PrintWritten(args);
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
                   "record the simulator driving --script (without it: a real OpenNI2 camera)");
  record->add_option("--season", args->season, "season name or .yaml file (--sim)")
      ->capture_default_str();
  record->add_option("--robot", args->robot, "robot name or .yaml file")->capture_default_str();
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
  record->callback([action, args] {
    *action = [args] { return args->sim ? RecordSim(*args) : RecordCamera(*args); };
  });
}

}  // namespace slamo::autonomy
