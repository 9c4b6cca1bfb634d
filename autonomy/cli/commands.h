// Each subcommand of `slamo` lives in its own file and registers itself on the app here;
// autonomy/main.cc only dispatches.
#pragma once

#include <CLI/CLI.hpp>

#include <filesystem>
#include <functional>
#include <iostream>
#include <string>

namespace slamo::autonomy {

// Creates an output folder (and its parents); false, with the reason on stderr, when it
// cannot (the command then exits 1).
inline bool CreateOutputDir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) std::cerr << "error: " << dir << ": " << ec.message() << "\n";
  return !ec;
}

// A registered subcommand runs this after parsing; it returns the process exit status.
using CommandAction = std::function<int()>;

// `slamo field list|check|show`.
void RegisterFieldCommand(CLI::App& app, CommandAction* action);

// `slamo sim render|drive`.
void RegisterSimCommand(CLI::App& app, CommandAction* action);

// `slamo calibrate plane|depth`.
void RegisterCalibrateCommand(CLI::App& app, CommandAction* action);

// `slamo detect`.
void RegisterDetectCommand(CLI::App& app, CommandAction* action);

// `slamo eval vision`.
void RegisterEvalCommand(CLI::App& app, CommandAction* action);

// `slamo replay`: EKF SLAM over a recorded run, scored against ground truth.
void RegisterReplayCommand(CLI::App& app, CommandAction* action);

// `slamo experiment waypoints|nees`.
void RegisterExperimentCommand(CLI::App& app, CommandAction* action);

// `slamo map build`.
void RegisterMapCommand(CLI::App& app, CommandAction* action);

// `slamo plan`: an OMPL path across the field, its stops and travel time.
void RegisterPlanCommand(CLI::App& app, CommandAction* action);

// `slamo record`: a run saved as a TUM RGB-D folder and an MRPT rawlog (--sim: the simulator).
void RegisterRecordCommand(CLI::App& app, CommandAction* action);

// `slamo dry-run`: one simulated autonomous period with its report.
void RegisterDryRunCommand(CLI::App& app, CommandAction* action);

// `slamo match`: the match-day run on the robot (says what is missing until it exists).
void RegisterMatchCommand(CLI::App& app, CommandAction* action);

// `slamo tune`: many seeded matches per parameter combination, ranked (and `tune merge`).
void RegisterTuneCommand(CLI::App& app, CommandAction* action);

// `slamo board fake|ping`: the motor-controller board link (fake board on a pty, ping).
void RegisterBoardCommand(CLI::App& app, CommandAction* action);

}  // namespace slamo::autonomy
