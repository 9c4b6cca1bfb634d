// `slamo dry-run`: one simulated autonomous period, end to end, with the report files. With no
// arguments it runs the default season from its first red starting tile. Exit status: 0 after
// a run (whatever it scored), 1 when an output file cannot be written, 2 on bad input.
// `--from-recording DIR` runs SLAM-O on a recorded run instead (autonomy/recording_run.h).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "autonomy/cli/commands.h"
#include "autonomy/cli/options.h"
#include "autonomy/experiments/calibration.h"
#include "autonomy/experiments/recording_run.h"
#include "autonomy/experiments/tuning.h"
#include "autonomy/io/sim_io.h"
#include "autonomy/loop/executive.h"
#include "autonomy/reports/match_report.h"
#include "field_configs/loader.h"
#include "mapping/frame_selection.h"
#include "platform/recording.h"
#include "strategy/strategy.h"

namespace slamo::autonomy {
namespace {

struct DryRunArgs {
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  uint64_t seed = 1;
  std::string strategy = "planner";
  std::string frames = "covariance";
  std::string out = "dry-run";
  double jitter_m = 0.15;
  std::string scenario = "nominal";
  std::string calibration;  // a `slamo tune calibrate` file: learned P(success)
  double speed_mps = 0.0;
  bool video = true;
  bool quiet = false;
  bool frames_png = false;
  std::string recording;  // --from-recording: a TUM folder or rawlog instead of the simulator
  std::vector<std::string> params;  // name=value, as one combination of `slamo tune --param`
};

// SLAM-O on a recording: report.json, map.png, trajectory.tum (+ groundtruth.tum when the
// recording has ground truth) and objects.bt; no replay.
int DryRunRecording(const DryRunArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  if (!CreateOutputDir(args.out)) return 1;
  std::cout << "dry run: " << season.name << " (" << season.season << ") on the recording "
            << args.recording << "\n";
  MatchResult result;
  try {
    result = RunRecording(season, robot, args.recording, RecordingRunOptions{}, args.out);
  } catch (const platform::RecordingError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  PrintSummary(result, std::cout);
  if (std::isnan(result.pose_ate_m))
    std::cout << "  (the recording has no ground truth: pose ATE is not available and the "
                 "truth columns repeat the estimate)\n";
  try {
    const std::vector<std::string> written = WriteMatchFiles(result, args.out, false);
    std::cout << "wrote " << args.out << "/{" << Join(written) << ", objects.bt}\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

int DryRun(const DryRunArgs& args) {
  if (!args.recording.empty()) return DryRunRecording(args);
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  MatchSetup setup;
  setup.strategy = args.strategy;
  setup.placement_jitter_m = args.jitter_m;
  setup.drive_speed_mps = args.speed_mps;
  try {
    mapping::ParseFrameRule(args.frames, &setup.frames);
    strategy::MakeStrategy(args.strategy, setup.strategy_options);
    setup.scenario = ParseScenario(args.scenario);
    for (const std::string& param : args.params) {
      const size_t eq = param.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == param.size() ||
          param.find(',') != std::string::npos) {
        throw std::invalid_argument("--param " + param + ": expected name=value (one value)");
      }
      ApplyParam(param.substr(0, eq), param.substr(eq + 1), &setup);
    }
    if (!args.calibration.empty()) {
      setup.strategy_options.learned_success =
          LearnedSuccess(LoadCalibration(args.calibration, season.season, robot.name));
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (!CreateOutputDir(args.out)) return 1;
  std::cout << "dry run: " << season.name << " (" << season.season << "), seed " << args.seed
            << ", strategy " << setup.strategy << ", " << season.rules.autonomous_s
            << " s autonomous, " << ScenarioName(setup.scenario) << " layout\n";
  const MatchResult result =
      RunMatch(season, robot, setup, args.seed, args.out, [&](const TimelineEntry& e) {
        if (!args.quiet)
          std::cout << "  [" << e.t_s << " s] " << e.action << " " << e.detail << std::endl;
      });
  PrintSummary(result, std::cout);

  const std::string dir = args.out + "/";
  try {
    const std::vector<std::string> written = WriteMatchFiles(result, args.out, args.video);
    if (args.frames_png) {
      std::filesystem::create_directories(dir + "replay");
      for (size_t k = 0; k < result.snapshots.size(); ++k) {
        char name[32];
        std::snprintf(name, sizeof(name), "replay/%04zu.png", k);
        cv::imwrite(dir + name, DrawSnapshot(result, k));
      }
    }
    std::cout << "wrote " << args.out << "/{" << Join(written) << ", objects.bt}\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

void RegisterDryRunCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<DryRunArgs>();
  CLI::App* cmd =
      app.add_subcommand("dry-run",
                         "one simulated autonomous period: SLAM-O, strategy, planning and driving "
                         "against the simulated field, with a report");
  AddSeasonRobotOptions(cmd, &args->season, &args->robot);
  cmd->add_option("--seed", args->seed, "seed of the field, camera and wheels")
      ->capture_default_str();
  cmd->add_option("--strategy", args->strategy, "planner | greedy | scripted | thesis")
      ->capture_default_str();
  cmd->add_option("--frames", args->frames,
                  "frame rule at every observation: fixed:N | covariance | gmm")
      ->capture_default_str();
  cmd->add_option("--out", args->out,
                  "directory for report.json, map.png, trajectory.tum, objects.bt, replay.avi")
      ->capture_default_str();
  cmd->add_option("--jitter", args->jitter_m,
                  "fixed object positions moved up to this far per seed (m)")
      ->capture_default_str();
  cmd->add_option("--scenario", args->scenario,
                  "nominal: objects jittered up to --jitter; disturbed: objects moved 0.3-0.8 m "
                  "from their spots, as after contact with an opponent (the robot is told the "
                  "season file either way)")
      ->capture_default_str();
  cmd->add_option("--calibration", args->calibration,
                  "pick and release success models from `slamo tune calibrate` for this season "
                  "and robot (default: the tolerance model)");
  cmd->add_option("--speed", args->speed_mps, "driving speed (m/s); 0: the robot's match_speed_mps")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 5.0));
  cmd->add_option("--param", args->params,
                  "name=value: one of `slamo tune`'s parameters (see `slamo tune --help`), to "
                  "run one of its combinations as a single match; repeatable, applied after the "
                  "options above");
  cmd->add_flag("!--no-video", args->video, "skip replay.avi");
  cmd->add_flag("--quiet", args->quiet, "no line per action");
  cmd->add_option("--from-recording", args->recording,
                  "run SLAM-O on a recording (TUM folder or rawlog, see `slamo record`) instead "
                  "of the simulator");
  cmd->add_flag("--replay-png", args->frames_png,
                "also write every replay frame as DIR/replay/NNNN.png");
  cmd->callback([args, action]() { *action = [args]() { return DryRun(*args); }; });
}

}  // namespace slamo::autonomy
