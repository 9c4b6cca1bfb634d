// The description of one VRC season's field: geometry, landmarks, scoring objects, goals,
// rules and starting tiles. Loaded and validated from field_configs/<season>.yaml by
// LoadSeasonConfig(); plain data afterwards, shared read-only by every module.
//
// Frame: origin at the field centre, x towards the blue alliance wall, y to the left of x,
// z up, metres; headings in degrees counter-clockwise from +x.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace slamo::field {

struct Vec2 {
  double x = 0.0;
  double y = 0.0;
};

struct Rgb {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
};

enum class Alliance { kNone, kRed, kBlue };

// Fixed field elements as simple solids (goals, posts, barriers, troughs, ladders...). A
// triangle is a floor zone only (a corner cut off by a bar or a tape diagonal).
enum class SolidShape { kBox, kCylinder, kTriangle };

struct Structure {
  std::string name;
  SolidShape shape = SolidShape::kBox;
  Vec2 center_m;
  Vec2 size_m;            // box: extent along its own x and y (before yaw)
  double radius_m = 0.0;  // cylinder
  double z_min_m = 0.0;   // bottom above the floor (an elevated bar has z_min_m > 0)
  double height_m = 0.0;  // top above the floor
  double yaw_deg = 0.0;
  std::string colour;        // a name from SeasonConfig::colours
  bool blocks_robot = true;  // false: the robot drives over or under it (a bump, a tape line)

  // Robots lower than z_min_m pass under it (blocks_robot false and raised off the floor): a
  // barrier or bar they drive beneath (see platform::BlocksRobot). Objects taller than z_min_m
  // cannot pass either (see PointBlocksObject).
  bool PassUnder() const { return !blocks_robot && z_min_m > 0.0; }
};

enum class LandmarkShape { kDisc, kSquare, kCylinder, kSphere };

// A coloured marker for SLAM (the thesis put eight on the field border).
struct Landmark {
  std::optional<std::string> id;  // set when the marker is uniquely identifiable
  Vec2 position_m;
  double height_m = 0.0;  // centre above the floor
  double size_m = 0.0;    // diameter or edge
  LandmarkShape shape = LandmarkShape::kDisc;
  std::string colour;  // a name from SeasonConfig::colours
};

enum class ObjectShape { kSphere, kCube, kStar, kTorus, kTriball, kHollowBlock, kCylinder };
enum class Material { kSolid, kSemiTransparent };

struct ObjectType {
  std::string name;
  ObjectShape shape = ObjectShape::kSphere;
  double size_m = 0.0;    // diameter (sphere, torus, triball, star), edge (cube, block)
  double height_m = 0.0;  // vertical extent when resting on the floor
  Material material = Material::kSolid;
  double opacity = 1.0;              // 1 for solid; < 1 for semi-transparent
  std::vector<std::string> colours;  // names from SeasonConfig::colours
};

struct Region {
  Vec2 min_m;
  Vec2 max_m;
};

// Where objects start: either one fixed position, or `count` objects drawn uniformly in a
// region from the run's seed.
struct ObjectPlacement {
  std::string type;    // an ObjectType name
  std::string colour;  // one of that type's colours
  std::optional<Vec2> position_m;
  std::optional<Region> region;
  int count = 1;
  double z_m = 0.0;  // height of the object's bottom (0: on the floor)
  // Position in a stack (`stack:` in the file): 0 for the bottom object (or one not stacked),
  // k for the k-th object resting on the one below it; stack_size objects in the stack.
  int stack_level = 0;
  int stack_size = 1;
};

enum class GoalKind { kZone, kGoal };  // zone: floor area; goal: a structure objects go into

struct Goal {
  std::string name;
  GoalKind kind = GoalKind::kZone;
  Alliance alliance = Alliance::kNone;  // kNone: scores for the object's colour / either side
  SolidShape shape = SolidShape::kBox;
  Vec2 center_m;  // a triangle's centroid
  Vec2 size_m;    // a triangle's bounding box (axis-aligned)
  double radius_m = 0.0;
  std::vector<Vec2> vertices_m;  // triangle zones only: the three corners
  double height_m = 0.0;         // opening height for a goal; 0 for a floor zone
  double yaw_deg = 0.0;
  std::map<std::string, int> points;  // object type -> points for one object scored here
  // kEnds: a tube objects enter only through the two ends of its long axis (a box goal; the
  // Push Back goals); kAny: from any side the robot reaches.
  enum class Entry { kAny, kEnds } entry = Entry::kAny;
  // Non-empty: the goal stands on an object of this type (a High Stakes mobile goal's stake on
  // its base), placed at the goal's centre, and moves with it; a robot releases into it with
  // its bumper just short of that object's edge (platform::CarrierRadius).
  std::string on_object;
};

struct StartTile {
  Alliance alliance = Alliance::kRed;
  Vec2 center_m;
  double heading_deg = 0.0;
};

// An opponent robot that follows a scripted path and pushes what it meets.
struct OpponentRobot {
  Alliance alliance = Alliance::kBlue;
  Vec2 size_m;  // footprint length x width
  double speed_mps = 0.0;
  std::vector<Vec2> path_m;
  bool loop = false;
};

struct FieldGeometry {
  double size_m = 3.658;  // square side, inside the perimeter
  double tile_m = 0.6096;
  std::string tile_colour;
  double wall_height_m = 0.0;
  double wall_thickness_m = 0.0;
  std::string wall_colour;
};

struct Rules {
  double autonomous_s = 15.0;  // autonomous period length
  double match_s = 120.0;
  int autonomous_bonus = 0;      // points to the alliance ahead at the end of autonomous
  bool own_colour_only = false;  // objects score only for the alliance of their colour
};

struct SeasonConfig {
  std::string source_file;             // where it was loaded from, for messages
  std::string season;                  // file stem, e.g. "toss_up"
  std::string name;                    // e.g. "Toss Up"
  std::string years;                   // e.g. "2013-14"
  std::map<std::string, Rgb> colours;  // the palette every colour name refers to
  FieldGeometry field;
  Rules rules;
  std::vector<Structure> structures;
  std::vector<Landmark> landmarks;
  std::vector<ObjectType> object_types;
  std::vector<ObjectPlacement> objects;
  std::vector<Goal> goals;
  std::vector<StartTile> starts;
  std::vector<OpponentRobot> opponents;

  double HalfSize() const { return field.size_m / 2.0; }
  const ObjectType* FindObjectType(const std::string& name) const;
  // Total objects the placements create.
  int ObjectCount() const;
};

const char* ToString(Alliance alliance);
const char* ToString(ObjectShape shape);
const char* ToString(Material material);

}  // namespace slamo::field
