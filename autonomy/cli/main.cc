// `slamo`: one program, one subcommand per file under autonomy/commands/. This file only
// builds the command line and dispatches; bad configuration exits with status 2.
#include <iostream>

#include <CLI/CLI.hpp>

#include "autonomy/cli/commands.h"
#include "field_configs/config_error.h"

int main(int argc, char** argv) {
  CLI::App app{"slamo: SLAM-O autonomy for VEX Robotics Competition robots"};
  app.require_subcommand(1);
  app.footer(
      "Examples:\n"
      "  slamo field list                          the shipped seasons\n"
      "  slamo field check toss_up                 validate a season and summarise it\n"
      "  slamo field show toss_up --out f.png      draw the field from above\n"
      "  slamo sim render --seed 1 --out DIR       an RGB-D frame of the simulated field\n"
      "  slamo sim drive --script \"forward 0.3; turn 90\"   encoder drift against the truth\n"
      "  slamo calibrate plane --depth DIR/depth.png   camera-to-wall distance (RANSAC plane)\n"
      "  slamo detect --color DIR/colour.png --depth DIR/depth.png --out seen.png\n"
      "  slamo eval vision --frames 50             detection methods against ground truth\n"
      "  slamo replay --log run.log --truth t.tum --out DIR   EKF SLAM over a log; ATE\n"
      "  slamo map build --out DIR                 the OctoMap: map.bt, map.ot, grid.png\n"
      "  slamo dry-run                             a simulated autonomous period: report, map, "
      "replay\n"
      "  slamo tune --matches 50 --param strategy=planner,greedy --jobs 2   ranked over seeds\n"
      "  slamo plan --no-objects --from -0.8955,1.40,0 --to 0.3,-1.2,90 --out plan.png   a path\n"
      "  slamo record --sim --script \"forward 0.3; turn 90\" --out run   TUM folder + rawlog\n"
      "  slamo match --port /dev/ttyACM0           the match-day run on the robot\n"
      "  slamo match --fake-board --camera sim     the same on the fake board, no robot");

  slamo::autonomy::CommandAction action;
  slamo::autonomy::RegisterFieldCommand(app, &action);
  slamo::autonomy::RegisterSimCommand(app, &action);
  slamo::autonomy::RegisterCalibrateCommand(app, &action);
  slamo::autonomy::RegisterDetectCommand(app, &action);
  slamo::autonomy::RegisterEvalCommand(app, &action);
  slamo::autonomy::RegisterReplayCommand(app, &action);
  slamo::autonomy::RegisterExperimentCommand(app, &action);
  slamo::autonomy::RegisterMapCommand(app, &action);
  slamo::autonomy::RegisterPlanCommand(app, &action);
  slamo::autonomy::RegisterBoardCommand(app, &action);
  slamo::autonomy::RegisterDryRunCommand(app, &action);
  slamo::autonomy::RegisterTuneCommand(app, &action);
  slamo::autonomy::RegisterMatchCommand(app, &action);
  slamo::autonomy::RegisterRecordCommand(app, &action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  try {
    return action ? action() : 0;
  } catch (const slamo::field::ConfigError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}
