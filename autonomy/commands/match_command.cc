// `slamo match`: the match-day run on the robot. The executive (autonomy/executive.cc) runs on
// MatchWorld, which is built on the simulated field; the hardware pieces exist on their own
// (SerialDriveBase for the motor-controller board, the OpenNI2 camera, recordings), but the
// world that puts them behind the executive is not written yet. Until it is, this command
// checks what it can (the season, the robot, the camera model, the board's port) and says
// plainly what is missing, with exit status 3: it never pretends to run a match.
#include <iostream>
#include <memory>
#include <string>

#include "autonomy/commands/commands.h"
#include "field_configs/loader.h"
#include "platform/openni2_camera.h"

namespace slamo::autonomy {
namespace {

struct MatchArgs {
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  std::string port;
};

int Match(const MatchArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  std::cout << "match: " << season.name << ", " << season.rules.autonomous_s
            << " s autonomous, robot " << robot.name << "\n";
  const bool openni2 = platform::IsOpenNI2CameraModel(robot.camera.model);
  std::cout << "  camera  " << robot.camera.model
            << (openni2
                    ? ": an OpenNI2 model (platform/openni2_camera.h)"
                    : ": no driver here (OpenNI2 drives PrimeSense, Kinect V1 and Xtion models)")
            << "\n";
  std::cout << "  board   " << (args.port.empty() ? "no --port given" : args.port)
            << " (platform/serial_drive_base.h; try `slamo board ping --port "
            << (args.port.empty() ? "DEV" : args.port) << "`)\n";
  std::cerr
      << "error: slamo match cannot run a match yet: the executive runs on the simulated field "
         "only. "
         "Missing: a hardware MatchWorld that reads the camera and the board's encoders and drives "
         "through SerialDriveBase (see issue notes). Use `slamo dry-run` for a simulated match.\n";
  return 3;
}

}  // namespace

void RegisterMatchCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<MatchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "match",
      "the match-day autonomous run on the robot (not available yet: says what is missing)");
  cmd->add_option("--season", args->season, "season name or YAML file")->capture_default_str();
  cmd->add_option("--robot", args->robot, "robot YAML file")->capture_default_str();
  cmd->add_option("--port", args->port, "the motor-controller board's serial device");
  cmd->callback([args, action]() { *action = [args]() { return Match(*args); }; });
}

}  // namespace slamo::autonomy
