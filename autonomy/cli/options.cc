#include "autonomy/cli/options.h"

#include <sstream>

#include "field_configs/config_error.h"

namespace slamo::autonomy {

using platform::kPi;
using platform::Pose2D;

Pose2D ParsePose(const std::string& text, const std::string& option) {
  std::stringstream in(text);
  double v[3];
  char comma = 0;
  if (!(in >> v[0] >> comma) || comma != ',' || !(in >> v[1] >> comma) || comma != ',' ||
      !(in >> v[2]) || !in.eof()) {
    throw field::ConfigError(option, 0, 0, "pose",
                             "X,Y,THETA (metres, metres, degrees), got '" + text + "'");
  }
  return Pose2D{v[0], v[1], v[2] * kPi / 180.0};
}

Pose2D PoseOrFirstStart(const field::SeasonConfig& season, const std::string& text,
                        const std::string& option) {
  if (!text.empty()) return ParsePose(text, option);
  const field::StartTile& tile = season.starts.front();
  return Pose2D{tile.center_m.x, tile.center_m.y, tile.heading_deg * kPi / 180.0};
}

void AddSeasonRobotOptions(CLI::App* cmd, std::string* season, std::string* robot) {
  cmd->add_option("--season", *season, "season name or .yaml file")->capture_default_str();
  cmd->add_option("--robot", *robot, "robot name or .yaml file")->capture_default_str();
}

void AddBoardOptions(CLI::App* cmd, BoardArgs* args, const BoardHelp& help) {
  cmd->add_option("--port", args->port, help.port);
  cmd->add_option("--baud", args->baud, "serial speed")->capture_default_str();
  cmd->add_flag("--fake-board", args->fake_board, help.fake_board);
  cmd->add_option("--camera", args->camera, help.camera);
}

RigOptions RigOptionsFrom(const BoardArgs& args) {
  RigOptions options;
  options.port = args.port;
  options.baud = args.baud;
  options.fake_board = args.fake_board;
  options.camera = args.camera;
  return options;
}

}  // namespace slamo::autonomy
