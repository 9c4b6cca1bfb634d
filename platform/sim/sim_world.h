// The simulated field's state: the season's fixed elements plus the objects (placed from the
// config, random regions drawn from the seed), opponent robots on their scripted paths, and
// the lighting of this run. Owned by the simulator; the renderer and physics read it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "field_configs/season_config.h"
#include "platform/drive_base.h"

namespace slamo::platform {

struct SimObject {
  int id = 0;  // 1-based, stable for the run
  const field::ObjectType* type = nullptr;
  std::string colour;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  // centre of the object's bounding box
  bool held = false;  // in a robot's intake: not on the field, not rendered
  int in_goal = -1;   // index into SeasonConfig::goals when released into a goal structure
};

struct SimOpponent {
  field::OpponentRobot config;
  double height_m = 0.45;  // a box this tall when rendered
  Pose2D pose;
  size_t next_waypoint = 1;
};

// Scene lighting, varied by the seed: a directional light plus ambient, with a colour tint.
struct Lighting {
  Eigen::Vector3d to_light = Eigen::Vector3d(0.3, 0.2, 0.93).normalized();
  double ambient = 0.45;
  double diffuse = 0.6;
  Eigen::Vector3d tint = Eigen::Vector3d::Ones();  // per channel, RGB
};

struct SimWorld {
  const field::SeasonConfig* season = nullptr;
  std::vector<SimObject> objects;
  std::vector<SimOpponent> opponents;
  Lighting lighting;
};

// Places every object of the season (region placements drawn uniformly from `seed`, kept off
// other objects and blocking structures) and picks the lighting from `seed`.
SimWorld CreateWorld(const field::SeasonConfig& season, uint64_t seed);

// Test scenes for counting (issue 16): objects of one type and colour added to the world,
// after removing those already where they go; new ids after the world's largest. Returns the
// new objects' ids.
// A heap: `count` objects on the floor, touching, packed hexagonally (each the nearest free
// place to `centre_m`), one layer.
std::vector<int> AddPile(const field::ObjectType& type, const std::string& colour,
                         const Eigen::Vector2d& centre_m, int count, SimWorld* world);
// A stack: `count` objects one on top of the other at `centre_m` (rings on a stake).
std::vector<int> AddStack(const field::ObjectType& type, const std::string& colour,
                          const Eigen::Vector2d& centre_m, int count, SimWorld* world);

}  // namespace slamo::platform
