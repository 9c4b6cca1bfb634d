// What the `slamo` subcommands share: the pose parser, the start pose, and the option blocks
// several commands offer (--season/--robot, the board and camera of a rig).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "autonomy/io/robot_rig.h"
#include "field_configs/season_config.h"
#include "platform/drive_base.h"

namespace slamo::autonomy {

// "X,Y,THETA" in metres, metres and degrees; field::ConfigError naming `option` otherwise (the
// program exits 2 with it).
platform::Pose2D ParsePose(const std::string& text, const std::string& option = "--pose");
// `text` as a pose (ParsePose), or the season's first starting tile when it is empty.
platform::Pose2D PoseOrFirstStart(const field::SeasonConfig& season, const std::string& text,
                                  const std::string& option = "--pose");

// --season and --robot: a shipped name or a YAML file each.
void AddSeasonRobotOptions(CLI::App* cmd, std::string* season, std::string* robot);

// The motor-controller board and the camera of a rig (autonomy/io/robot_rig.h).
struct BoardArgs {
  std::string port;
  int baud = 115200;
  bool fake_board = false;
  std::string camera;
};
// --port, --baud, --fake-board and --camera, each with its command's own help.
struct BoardHelp {
  std::string port;
  std::string fake_board;
  std::string camera;
};
void AddBoardOptions(CLI::App* cmd, BoardArgs* args, const BoardHelp& help);
// The rig's options from them (the rest at their defaults).
RigOptions RigOptionsFrom(const BoardArgs& args);

}  // namespace slamo::autonomy
