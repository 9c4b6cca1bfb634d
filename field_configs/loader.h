// Finding, loading and validating season and robot files. Every function throws ConfigError
// on bad input; a typo never falls back to a default.
#pragma once

#include <string>
#include <vector>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"

namespace slamo::field {

inline constexpr const char* kDefaultSeason = "toss_up";
inline constexpr const char* kDefaultRobot = "thesis_robot";

// The directory holding the shipped configs: $SLAMO_FIELD_CONFIG_DIR if set, else the
// source tree's field_configs/.
std::string ConfigDir();

// The shipped season names (file stems of <ConfigDir()>/*.yaml), sorted.
std::vector<std::string> ListSeasons();
std::vector<std::string> ListRobots();

// A season name ("toss_up") or a path to a YAML file -> the file's path.
std::string ResolveSeasonPath(const std::string& season_or_path);
std::string ResolveRobotPath(const std::string& robot_or_path);

SeasonConfig LoadSeasonConfig(const std::string& season_or_path);
RobotConfig LoadRobotConfig(const std::string& robot_or_path);

// Parses YAML text; `file` is used in messages and for the season name.
SeasonConfig ParseSeasonConfig(const std::string& yaml_text, const std::string& file);
RobotConfig ParseRobotConfig(const std::string& yaml_text, const std::string& file);

}  // namespace slamo::field
