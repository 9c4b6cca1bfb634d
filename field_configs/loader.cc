#include "field_configs/loader.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "field_configs/config_error.h"
#include "field_configs/internal/yaml_reader.h"

namespace slamo::field {
namespace {

namespace fs = std::filesystem;
using internal::YamlReader;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path, 0, 0, "(file)", "a readable file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string Stem(const std::string& path) { return fs::path(path).stem().string(); }

std::string FormatMetres(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

Rgb ParseHexColour(const YamlReader& node) {
  const std::string expected = "a colour '#rrggbb' in quotes ('#' starts a YAML comment)";
  std::string text;
  try {
    text = node.String();
  } catch (const ConfigError&) {
    node.Fail(expected);
  }
  const bool hex = text.size() == 7 && text[0] == '#' &&
                   std::all_of(text.begin() + 1, text.end(),
                               [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
  if (!hex) node.Fail(expected);
  const auto channel = [&](int i) {
    return static_cast<std::uint8_t>(std::stoi(text.substr(1 + 2 * i, 2), nullptr, 16));
  };
  return Rgb{channel(0), channel(1), channel(2)};
}

// Context for the checks that relate one part of the file to another.
class SeasonParser {
 public:
  explicit SeasonParser(SeasonConfig* config) : config_(config) {}

  void Parse(const YamlReader& root) {
    root.AllowKeys({"name", "years", "colours", "field", "rules", "structures", "landmarks",
                    "object_types", "objects", "goals", "starts", "opponents"});
    config_->name = root.Required("name").String();
    config_->years = root.Required("years").String();
    ParseColours(root.Required("colours"));
    ParseField(root.Required("field"));
    ParseRules(root.Required("rules"));
    for (const YamlReader& item : root.Required("structures").Items()) ParseStructure(item);
    for (const YamlReader& item : root.Required("landmarks").Items()) ParseLandmark(item);
    if (config_->landmarks.empty()) root.Required("landmarks").Fail("at least one landmark");
    for (const YamlReader& item : root.Required("object_types").Items()) ParseObjectType(item);
    for (const YamlReader& item : root.Required("objects").Items()) ParseObject(item);
    for (const YamlReader& item : root.Required("goals").Items()) ParseGoal(item);
    for (const YamlReader& item : root.Required("starts").Items()) ParseStart(item);
    if (config_->starts.empty()) root.Required("starts").Fail("at least one starting tile");
    if (auto opponents = root.Optional("opponents")) {
      for (const YamlReader& item : opponents->Items()) ParseOpponent(item);
    }
  }

 private:
  std::string ColourName(const YamlReader& node) const {
    const std::string name = node.String();
    if (config_->colours.count(name) == 0) {
      std::string known;
      for (const auto& [k, v] : config_->colours) known += (known.empty() ? "" : ", ") + k;
      node.Fail("a colour name from 'colours' {" + known + "}");
    }
    return name;
  }

  // A point inside the field, `margin_m` from the perimeter (negative: outside allowed).
  Vec2 FieldPoint(const YamlReader& node, double margin_m = 0.0) const {
    const Vec2 p = node.Point();
    const double limit = config_->HalfSize() - margin_m;
    if (std::abs(p.x) > limit + 1e-9 || std::abs(p.y) > limit + 1e-9) {
      node.Fail("a point with |x| and |y| <= " + FormatMetres(limit) +
                " m (inside the field, origin at its centre)");
    }
    return p;
  }

  Vec2 PositiveSize(const YamlReader& node) const {
    const Vec2 s = node.Point();
    if (s.x <= 0.0 || s.y <= 0.0) node.Fail("a size [length, width] of positive metres");
    return s;
  }

  Alliance ParseAlliance(const YamlReader& node, bool allow_none) const {
    const int index =
        allow_none ? node.OneOf({"red", "blue", "none"}) : node.OneOf({"red", "blue"});
    return index == 0 ? Alliance::kRed : index == 1 ? Alliance::kBlue : Alliance::kNone;
  }

  void ParseColours(const YamlReader& node) {
    for (const auto& [name, value] : node.Entries()) config_->colours[name] = ParseHexColour(value);
    if (config_->colours.empty()) node.Fail("at least one colour");
  }

  void ParseField(const YamlReader& node) {
    node.AllowKeys(
        {"size_m", "tile_m", "tile_colour", "wall_height_m", "wall_thickness_m", "wall_colour"});
    FieldGeometry& f = config_->field;
    f.size_m = node.Required("size_m").Positive();
    const YamlReader tile = node.Required("tile_m");
    f.tile_m = tile.Positive();
    if (f.tile_m > f.size_m)
      tile.Fail("a tile no larger than the field (" + FormatMetres(f.size_m) + " m)");
    f.tile_colour = ColourName(node.Required("tile_colour"));
    f.wall_height_m = node.Required("wall_height_m").Positive();
    f.wall_thickness_m = node.Required("wall_thickness_m").Positive();
    f.wall_colour = ColourName(node.Required("wall_colour"));
  }

  void ParseRules(const YamlReader& node) {
    node.AllowKeys({"autonomous_s", "match_s", "autonomous_bonus", "own_colour_only"});
    Rules& r = config_->rules;
    r.autonomous_s = node.Required("autonomous_s").Positive();
    const YamlReader match = node.Required("match_s");
    r.match_s = match.Positive();
    if (r.match_s < r.autonomous_s) match.Fail("a match at least as long as autonomous_s");
    r.autonomous_bonus = node.Required("autonomous_bonus").IntInRange(0, 1000);
    r.own_colour_only = node.Required("own_colour_only").Bool();
  }

  void ParseStructure(const YamlReader& node) {
    node.AllowKeys({"name", "shape", "center_m", "size_m", "radius_m", "z_min_m", "height_m",
                    "yaw_deg", "colour", "blocks_robot"});
    Structure s;
    s.name = node.Required("name").String();
    s.shape = node.Required("shape").OneOf({"box", "cylinder"}) == 0 ? SolidShape::kBox
                                                                     : SolidShape::kCylinder;
    s.center_m = FieldPoint(node.Required("center_m"));
    if (s.shape == SolidShape::kBox) {
      s.size_m = PositiveSize(node.Required("size_m"));
      if (node.Has("radius_m"))
        node.Required("radius_m").FailRule("radius_m is for cylinders; a box takes size_m");
    } else {
      s.radius_m = node.Required("radius_m").Positive();
      if (node.Has("size_m"))
        node.Required("size_m").FailRule("size_m is for boxes; a cylinder takes radius_m");
    }
    if (auto z = node.Optional("z_min_m")) s.z_min_m = z->NonNegative();
    const YamlReader height = node.Required("height_m");
    s.height_m = height.Positive();
    if (s.height_m <= s.z_min_m)
      height.Fail("a top height above z_min_m (" + FormatMetres(s.z_min_m) + " m)");
    if (auto yaw = node.Optional("yaw_deg")) s.yaw_deg = yaw->InRange(-360.0, 360.0);
    s.colour = ColourName(node.Required("colour"));
    if (auto blocks = node.Optional("blocks_robot")) s.blocks_robot = blocks->Bool();
    config_->structures.push_back(s);
  }

  void ParseLandmark(const YamlReader& node) {
    node.AllowKeys({"id", "position_m", "height_m", "size_m", "shape", "colour"});
    Landmark l;
    if (auto id = node.Optional("id")) {
      l.id = id->String();
      for (const Landmark& other : config_->landmarks) {
        if (other.id == l.id) id->Fail("an id not used by another landmark");
      }
    }
    // Markers sit on or just outside the perimeter wall.
    l.position_m =
        FieldPoint(node.Required("position_m"), -(config_->field.wall_thickness_m + 0.1));
    l.height_m = node.Required("height_m").NonNegative();
    l.size_m = node.Required("size_m").Positive();
    const int shape = node.Required("shape").OneOf({"disc", "square", "cylinder", "sphere"});
    l.shape = static_cast<LandmarkShape>(shape);
    l.colour = ColourName(node.Required("colour"));
    config_->landmarks.push_back(l);
  }

  void ParseObjectType(const YamlReader& node) {
    node.AllowKeys({"name", "shape", "size_m", "height_m", "material", "opacity", "colours"});
    ObjectType t;
    const YamlReader name = node.Required("name");
    t.name = name.String();
    if (config_->FindObjectType(t.name)) name.Fail("a name not used by another object type");
    t.shape = static_cast<ObjectShape>(node.Required("shape").OneOf(
        {"sphere", "cube", "star", "torus", "triball", "hollow_block", "cylinder"}));
    t.size_m = node.Required("size_m").Positive();
    t.height_m = t.size_m;
    if (auto h = node.Optional("height_m")) t.height_m = h->Positive();
    const YamlReader material = node.Required("material");
    t.material = material.OneOf({"solid", "semi_transparent"}) == 0 ? Material::kSolid
                                                                    : Material::kSemiTransparent;
    if (t.material == Material::kSemiTransparent) {
      t.opacity = node.Required("opacity").InRange(0.05, 0.95);
    } else if (auto opacity = node.Optional("opacity")) {
      if (opacity->InRange(0.0, 1.0) != 1.0) opacity->Fail("opacity 1 for a solid material");
    }
    const YamlReader colours = node.Required("colours");
    for (const YamlReader& c : colours.Items()) t.colours.push_back(ColourName(c));
    if (t.colours.empty()) colours.Fail("at least one colour");
    config_->object_types.push_back(t);
  }

  std::string KnownTypes() const {
    std::string known;
    for (const ObjectType& t : config_->object_types) known += (known.empty() ? "" : ", ") + t.name;
    return "an object type from 'object_types' {" + known + "}";
  }

  const ObjectType& ObjectTypeNamed(const YamlReader& node) const {
    const ObjectType* type = config_->FindObjectType(node.String());
    if (!type) node.Fail(KnownTypes());
    return *type;
  }

  std::string TypeColour(const YamlReader& node, const ObjectType& type) const {
    const std::string colour = ColourName(node);
    if (std::find(type.colours.begin(), type.colours.end(), colour) == type.colours.end()) {
      node.Fail("one of the colours of object type '" + type.name + "'");
    }
    return colour;
  }

  void ParseObject(const YamlReader& node) {
    node.AllowKeys({"type", "colour", "stack", "position_m", "region", "count", "z_m"});
    ObjectPlacement p;
    const ObjectType& type = ObjectTypeNamed(node.Required("type"));
    p.type = type.name;
    // A stack: objects of one type resting on each other, colours listed top first.
    std::vector<std::string> stack_colours;
    if (node.Has("colour") == node.Has("stack"))
      node.FailRule("give exactly one of 'colour' or 'stack' (a list of colours, top first)");
    if (node.Has("stack")) {
      const YamlReader stack = node.Required("stack");
      for (const YamlReader& c : stack.Items())
        stack_colours.insert(stack_colours.begin(), TypeColour(c, type));
      if (stack_colours.size() < 2 || stack_colours.size() > 20)
        stack.Fail("a stack of 2 to 20 colours, top first (one object: use 'colour')");
      if (!node.Has("position_m"))
        stack.FailRule("'stack' goes with 'position_m' (a stack stands at one place)");
      p.colour = stack_colours.front();
    } else {
      p.colour = TypeColour(node.Required("colour"), type);
    }
    const double radius = type.size_m / 2.0;
    const bool has_position = node.Has("position_m");
    const bool has_region = node.Has("region");
    if (has_position == has_region) node.FailRule("give exactly one of 'position_m' or 'region'");
    if (has_position) {
      const YamlReader position = node.Required("position_m");
      p.position_m = FieldPoint(position, radius);
      if (node.Has("count"))
        node.Required("count").FailRule(
            "'count' goes with 'region'; a fixed position places one object");
      // Objects overlap when their footprints overlap and their heights [z, z + height] do
      // (a stack's objects rest on each other, so they touch without overlapping).
      const double z = node.Has("z_m") ? node.Required("z_m").Number() : 0.0;
      const double top =
          z + type.height_m * static_cast<double>(std::max<size_t>(1, stack_colours.size()));
      for (const ObjectPlacement& other : config_->objects) {
        if (!other.position_m) continue;
        const ObjectType& other_type = *config_->FindObjectType(other.type);
        const double other_radius = other_type.size_m / 2.0;
        const double d = std::hypot(other.position_m->x - p.position_m->x,
                                    other.position_m->y - p.position_m->y);
        const bool z_overlap = z < other.z_m + other_type.height_m - 1e-3 && other.z_m < top - 1e-3;
        if (d < radius + other_radius - 1e-3 && z_overlap) {
          position.Fail("a position not overlapping another object (one at [" +
                        FormatMetres(other.position_m->x) + ", " +
                        FormatMetres(other.position_m->y) + "])");
        }
      }
    } else {
      const YamlReader region = node.Required("region");
      region.AllowKeys({"min_m", "max_m"});
      Region r{FieldPoint(region.Required("min_m"), radius),
               FieldPoint(region.Required("max_m"), radius)};
      if (r.max_m.x <= r.min_m.x || r.max_m.y <= r.min_m.y)
        region.Fail("min_m below max_m in x and y");
      p.region = r;
      p.count = node.Required("count").IntInRange(1, 500);
    }
    if (auto z = node.Optional("z_m")) p.z_m = z->InRange(0.0, 3.0);
    if (stack_colours.empty()) {
      config_->objects.push_back(p);
      return;
    }
    // One placement per object of the stack, bottom first, each on the one below.
    const double bottom = p.z_m;
    p.stack_size = static_cast<int>(stack_colours.size());
    for (size_t k = 0; k < stack_colours.size(); ++k) {
      p.colour = stack_colours[k];
      p.stack_level = static_cast<int>(k);
      p.z_m = bottom + type.height_m * static_cast<double>(k);
      config_->objects.push_back(p);
    }
  }

  // A triangle zone: three corners inside the field, not all on one line; its centroid and
  // bounding box fill center_m and size_m.
  void ParseTriangle(const YamlReader& node, Goal* g) const {
    for (const char* key : {"center_m", "size_m", "radius_m", "yaw_deg"}) {
      if (node.Has(key))
        node.Required(key).FailRule(std::string(key) +
                                    " is not for a triangle; its three vertices_m define it");
    }
    const YamlReader vertices = node.Required("vertices_m");
    for (const YamlReader& v : vertices.Items()) g->vertices_m.push_back(FieldPoint(v));
    if (g->vertices_m.size() != 3) vertices.Fail("three vertices [[x, y], [x, y], [x, y]]");
    const Vec2 &a = g->vertices_m[0], &b = g->vertices_m[1], &c = g->vertices_m[2];
    const double area2 = std::abs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
    if (area2 < 1e-4) vertices.Fail("three vertices that enclose an area (not on one line)");
    g->center_m = {(a.x + b.x + c.x) / 3.0, (a.y + b.y + c.y) / 3.0};
    const double min_x = std::min({a.x, b.x, c.x}), max_x = std::max({a.x, b.x, c.x});
    const double min_y = std::min({a.y, b.y, c.y}), max_y = std::max({a.y, b.y, c.y});
    g->size_m = {max_x - min_x, max_y - min_y};
  }

  void ParseGoal(const YamlReader& node) {
    node.AllowKeys({"name", "kind", "alliance", "shape", "center_m", "size_m", "radius_m",
                    "vertices_m", "height_m", "yaw_deg", "points", "entry", "on_object"});
    Goal g;
    g.name = node.Required("name").String();
    g.kind = node.Required("kind").OneOf({"zone", "goal"}) == 0 ? GoalKind::kZone : GoalKind::kGoal;
    g.alliance = ParseAlliance(node.Required("alliance"), true);
    const YamlReader shape = node.Required("shape");
    const int shape_index = shape.OneOf({"box", "cylinder", "triangle"});
    g.shape = shape_index == 0   ? SolidShape::kBox
              : shape_index == 1 ? SolidShape::kCylinder
                                 : SolidShape::kTriangle;
    if (g.shape == SolidShape::kTriangle) {
      if (g.kind != GoalKind::kZone)
        shape.FailRule("a triangle is a floor zone (kind: zone); a goal is a box or a cylinder");
      ParseTriangle(node, &g);
    } else {
      if (node.Has("vertices_m"))
        node.Required("vertices_m").FailRule("vertices_m is for triangles (shape: triangle)");
      g.center_m = FieldPoint(node.Required("center_m"));
    }
    if (g.shape == SolidShape::kBox) {
      g.size_m = PositiveSize(node.Required("size_m"));
    } else if (g.shape == SolidShape::kCylinder) {
      g.radius_m = node.Required("radius_m").Positive();
    }
    if (g.kind == GoalKind::kGoal) {
      g.height_m = node.Required("height_m").Positive();
    } else if (auto h = node.Optional("height_m")) {
      g.height_m = h->NonNegative();
    }
    if (auto yaw = node.Optional("yaw_deg")) g.yaw_deg = yaw->InRange(-360.0, 360.0);
    if (auto entry = node.Optional("entry")) {
      g.entry = entry->OneOf({"any", "ends"}) == 0 ? Goal::Entry::kAny : Goal::Entry::kEnds;
      if (g.entry == Goal::Entry::kEnds &&
          (g.kind != GoalKind::kGoal || g.shape != SolidShape::kBox)) {
        entry->FailRule("entry: ends is for a box goal (kind: goal, shape: box)");
      }
    }
    if (auto carrier = node.Optional("on_object")) {
      g.on_object = carrier->String();
      if (!config_->FindObjectType(g.on_object)) {
        carrier->FailRule("unknown object type '" + g.on_object + "': expected " + KnownTypes());
      }
      if (g.kind != GoalKind::kGoal || g.shape != SolidShape::kCylinder) {
        carrier->FailRule("on_object is for a cylinder goal (kind: goal, shape: cylinder)");
      }
    }
    const YamlReader points = node.Required("points");
    for (const auto& [type_name, value] : points.Entries()) {
      if (!config_->FindObjectType(type_name)) {
        value.FailRule("unknown object type '" + type_name + "': expected " + KnownTypes());
      }
      g.points[type_name] = value.IntInRange(0, 1000);
    }
    config_->goals.push_back(g);
  }

  void ParseStart(const YamlReader& node) {
    node.AllowKeys({"alliance", "center_m", "heading_deg"});
    StartTile s;
    s.alliance = ParseAlliance(node.Required("alliance"), false);
    const YamlReader center = node.Required("center_m");
    s.center_m = FieldPoint(center, config_->field.tile_m / 2.0);
    s.heading_deg = node.Required("heading_deg").InRange(-360.0, 360.0);
    const double tile = config_->field.tile_m;
    for (const StartTile& other : config_->starts) {
      if (std::abs(other.center_m.x - s.center_m.x) < tile - 1e-6 &&
          std::abs(other.center_m.y - s.center_m.y) < tile - 1e-6) {
        center.Fail("a starting tile not overlapping another (one at [" +
                    FormatMetres(other.center_m.x) + ", " + FormatMetres(other.center_m.y) + "])");
      }
    }
    config_->starts.push_back(s);
  }

  void ParseOpponent(const YamlReader& node) {
    node.AllowKeys({"alliance", "size_m", "speed_mps", "path_m", "loop"});
    OpponentRobot o;
    o.alliance = ParseAlliance(node.Required("alliance"), false);
    o.size_m = PositiveSize(node.Required("size_m"));
    o.speed_mps = node.Required("speed_mps").InRange(0.01, 5.0);
    const YamlReader path = node.Required("path_m");
    for (const YamlReader& p : path.Items()) o.path_m.push_back(FieldPoint(p));
    if (o.path_m.size() < 2) path.Fail("a path of at least two points");
    if (auto loop = node.Optional("loop")) o.loop = loop->Bool();
    config_->opponents.push_back(o);
  }

  SeasonConfig* config_;
};

}  // namespace

namespace {

void ParseRobot(const YamlReader& root, RobotConfig* robot) {
  root.AllowKeys(
      {"name", "footprint", "mass_kg", "drive", "intake", "camera", "imu", "odometry_noise"});
  robot->name = root.Required("name").String();
  const YamlReader footprint = root.Required("footprint");
  footprint.AllowKeys({"length_m", "width_m", "height_m"});
  robot->length_m = footprint.Required("length_m").InRange(0.05, 1.0);
  robot->width_m = footprint.Required("width_m").InRange(0.05, 1.0);
  robot->height_m = footprint.Required("height_m").InRange(0.05, 2.0);
  robot->mass_kg = root.Required("mass_kg").Positive();

  const YamlReader drive = root.Required("drive");
  drive.AllowKeys({"wheel_diameter_m", "track_width_m", "max_speed_mps", "cruise_speed_mps",
                   "match_speed_mps", "turn_rate_dps", "accel_mps2", "encoder_ticks_per_rev", "pwm",
                   "pid", "motor", "slip"});
  DriveConfig& d = robot->drive;
  d.wheel_diameter_m = drive.Required("wheel_diameter_m").InRange(0.01, 0.5);
  const YamlReader track = drive.Required("track_width_m");
  d.track_width_m = track.Positive();
  if (d.track_width_m > robot->width_m) track.Fail("a track no wider than footprint.width_m");
  d.max_speed_mps = drive.Required("max_speed_mps").InRange(0.01, 5.0);
  const YamlReader cruise = drive.Required("cruise_speed_mps");
  d.cruise_speed_mps = cruise.Positive();
  if (d.cruise_speed_mps > d.max_speed_mps) cruise.Fail("a speed no faster than max_speed_mps");
  d.match_speed_mps = d.cruise_speed_mps;
  if (auto match = drive.Optional("match_speed_mps")) {
    d.match_speed_mps = match->Positive();
    if (d.match_speed_mps > d.max_speed_mps) match->Fail("a speed no faster than max_speed_mps");
  }
  d.turn_rate_dps = drive.Required("turn_rate_dps").InRange(1.0, 1080.0);
  d.accel_mps2 = drive.Required("accel_mps2").Positive();
  d.encoder_ticks_per_rev = drive.Required("encoder_ticks_per_rev").InRange(1.0, 100000.0);

  const YamlReader pwm = drive.Required("pwm");
  pwm.AllowKeys({"full_forward", "stop", "full_reverse", "deadband", "curve_exponent"});
  // Servo PWM (0 / 90 / 180) or a signed command (V5: 127 / 0 / -127).
  d.pwm.full_forward = pwm.Required("full_forward").IntInRange(-255, 255);
  d.pwm.stop = pwm.Required("stop").IntInRange(-255, 255);
  const YamlReader reverse = pwm.Required("full_reverse");
  d.pwm.full_reverse = reverse.IntInRange(-255, 255);
  const bool stop_between = (d.pwm.full_forward < d.pwm.stop && d.pwm.stop < d.pwm.full_reverse) ||
                            (d.pwm.full_forward > d.pwm.stop && d.pwm.stop > d.pwm.full_reverse);
  if (!stop_between)
    reverse.FailRule("pwm.stop must lie strictly between full_forward and full_reverse");
  const int half_range = std::min(std::abs(d.pwm.stop - d.pwm.full_forward),
                                  std::abs(d.pwm.full_reverse - d.pwm.stop));
  d.pwm.deadband = pwm.Required("deadband").IntInRange(0, half_range - 1);
  d.pwm.curve_exponent = pwm.Required("curve_exponent").InRange(0.2, 5.0);

  const YamlReader pid = drive.Required("pid");
  pid.AllowKeys({"kp", "ki", "kd", "rate_hz", "integral_limit"});
  d.pid.kp = pid.Required("kp").NonNegative();
  d.pid.ki = pid.Required("ki").NonNegative();
  d.pid.kd = pid.Required("kd").NonNegative();
  d.pid.rate_hz = pid.Required("rate_hz").InRange(1.0, 10000.0);
  d.pid.integral_limit = pid.Required("integral_limit").NonNegative();

  if (auto motor = drive.Optional("motor")) {
    motor->AllowKeys({"type", "cartridge_rpm", "gear_ratio", "count"});
    MotorConfig m;
    m.type = motor->Required("type").String();
    m.cartridge_rpm = motor->Required("cartridge_rpm").InRange(1.0, 20000.0);
    m.gear_ratio = motor->Required("gear_ratio").InRange(0.01, 100.0);
    m.count = motor->Required("count").IntInRange(1, 16);
    if (m.type == "v5_smart_motor" && m.cartridge_rpm != 100.0 && m.cartridge_rpm != 200.0 &&
        m.cartridge_rpm != 600.0) {
      motor->Required("cartridge_rpm")
          .Fail("a V5 cartridge's free speed: 100 (red), 200 (green) or 600 (blue) rpm");
    }
    const double free_mps = m.FreeSpeedMps(d.wheel_diameter_m);
    if (d.max_speed_mps > free_mps * 1.01) {
      drive.Required("max_speed_mps")
          .Fail("a top speed no faster than the motors' free speed (" + FormatMetres(free_mps) +
                " m/s from cartridge_rpm x gear_ratio x pi x wheel_diameter_m / 60)");
    }
    d.motor = m;
  }
  if (auto slip = drive.Optional("slip")) {
    slip->AllowKeys({"straight_mean", "straight_stddev", "side_stddev", "turn_mean", "turn_stddev",
                     "pivot_offset_m", "pivot_stddev_m", "motor_time_constant_s"});
    SlipConfig sc;
    sc.straight_mean = slip->Required("straight_mean").InRange(-0.5, 0.95);
    sc.straight_stddev = slip->Required("straight_stddev").InRange(0.0, 0.5);
    sc.side_stddev = slip->Required("side_stddev").InRange(0.0, 0.5);
    sc.turn_mean = slip->Required("turn_mean").InRange(-0.5, 0.95);
    sc.turn_stddev = slip->Required("turn_stddev").InRange(0.0, 0.5);
    sc.pivot_offset_m = slip->Required("pivot_offset_m").InRange(-0.5, 0.5);
    sc.pivot_stddev_m = slip->Required("pivot_stddev_m").InRange(0.0, 0.2);
    sc.motor_time_constant_s = slip->Required("motor_time_constant_s").InRange(0.001, 2.0);
    d.slip = sc;
  }

  const YamlReader intake = root.Required("intake");
  intake.AllowKeys({"reach_m", "capacity", "pick_s", "release_s"});
  robot->intake.reach_m = intake.Required("reach_m").InRange(0.0, 1.0);
  robot->intake.capacity = intake.Required("capacity").IntInRange(0, 100);
  if (const std::optional<YamlReader> v = intake.Optional("pick_s"))
    robot->intake.pick_s = v->InRange(0.0, 10.0);
  if (const std::optional<YamlReader> v = intake.Optional("release_s"))
    robot->intake.release_s = v->InRange(0.0, 10.0);

  const YamlReader camera = root.Required("camera");
  camera.AllowKeys({"model", "width_px", "height_px", "cx", "cy", "fx", "fy", "min_range_m",
                    "max_range_m", "frame_rate_hz", "colour_depth_baseline_m", "mount", "noise",
                    "depth_correction", "stop_bias", "latency_s"});
  CameraConfig& c = robot->camera;
  c.model = camera.Required("model").String();
  c.width_px = camera.Required("width_px").IntInRange(16, 8192);
  c.height_px = camera.Required("height_px").IntInRange(16, 8192);
  c.cx = camera.Required("cx").InRange(0.0, c.width_px);
  c.cy = camera.Required("cy").InRange(0.0, c.height_px);
  c.fx = camera.Required("fx").Positive();
  c.fy = camera.Required("fy").Positive();
  c.min_range_m = camera.Required("min_range_m").Positive();
  const YamlReader max_range = camera.Required("max_range_m");
  c.max_range_m = max_range.Positive();
  if (c.max_range_m <= c.min_range_m) max_range.Fail("a range above min_range_m");
  c.frame_rate_hz = camera.Required("frame_rate_hz").InRange(0.1, 1000.0);
  c.colour_depth_baseline_m = camera.Required("colour_depth_baseline_m").InRange(-0.5, 0.5);
  if (const std::optional<YamlReader> v = camera.Optional("latency_s")) {
    c.latency_s = v->InRange(0.0, 0.5);
  }

  const YamlReader mount = camera.Required("mount");
  mount.AllowKeys({"x_m", "y_m", "height_m", "pitch_deg", "yaw_deg"});
  c.mount.x_m = mount.Required("x_m").InRange(-1.0, 1.0);
  c.mount.y_m = mount.Required("y_m").InRange(-1.0, 1.0);
  c.mount.height_m = mount.Required("height_m").InRange(0.01, 3.0);
  c.mount.pitch_deg = mount.Required("pitch_deg").InRange(-90.0, 90.0);
  c.mount.yaw_deg = mount.Required("yaw_deg").InRange(-180.0, 180.0);

  const YamlReader noise = camera.Required("noise");
  noise.AllowKeys({"distance_m", "sigma_m"});
  const YamlReader distances = noise.Required("distance_m");
  c.noise.distance_m = distances.Numbers();
  const YamlReader sigmas = noise.Required("sigma_m");
  c.noise.sigma_m = sigmas.Numbers();
  if (c.noise.distance_m.size() < 2) distances.Fail("at least two distances");
  for (size_t i = 1; i < c.noise.distance_m.size(); ++i) {
    if (c.noise.distance_m[i] <= c.noise.distance_m[i - 1])
      distances.Fail("distances in increasing order");
  }
  if (c.noise.sigma_m.size() != c.noise.distance_m.size()) {
    sigmas.Fail("one sigma per distance (" + std::to_string(c.noise.distance_m.size()) +
                " values)");
  }
  for (double s : c.noise.sigma_m) {
    if (s < 0.0) sigmas.Fail("standard deviations >= 0");
  }

  const YamlReader correction = camera.Required("depth_correction");
  correction.AllowKeys({"a", "b_mm"});
  c.depth_correction.a = correction.Required("a").InRange(0.5, 2.0);
  c.depth_correction.b_mm = correction.Required("b_mm").InRange(-500.0, 500.0);

  const YamlReader stop_bias = camera.Required("stop_bias");
  stop_bias.AllowKeys({"range_sigma_m", "bearing_sigma_deg"});
  c.stop_bias_range_sigma_m = stop_bias.Required("range_sigma_m").InRange(0.0, 1.0);
  c.stop_bias_bearing_sigma_deg = stop_bias.Required("bearing_sigma_deg").InRange(0.0, 10.0);

  if (auto imu = root.Optional("imu")) {
    imu->AllowKeys({"model", "noise_deg", "drift_deg_per_sqrt_s"});
    ImuConfig i;
    i.model = imu->Required("model").String();
    i.noise_deg = imu->Required("noise_deg").InRange(0.0, 10.0);
    i.drift_deg_per_sqrt_s = imu->Required("drift_deg_per_sqrt_s").InRange(0.0, 10.0);
    robot->imu = i;
  }

  const YamlReader odometry = root.Required("odometry_noise");
  odometry.AllowKeys({"forward_sigma_per_m", "lateral_sigma_per_m", "forward_sigma_per_rad",
                      "lateral_sigma_per_rad", "heading_sigma_per_rad", "heading_sigma_per_m"});
  OdometryNoiseConfig& n = robot->odometry_noise;
  n.forward_sigma_per_m = odometry.Required("forward_sigma_per_m").InRange(0.0, 5.0);
  n.lateral_sigma_per_m = odometry.Required("lateral_sigma_per_m").InRange(0.0, 5.0);
  n.forward_sigma_per_rad = odometry.Required("forward_sigma_per_rad").InRange(0.0, 5.0);
  n.lateral_sigma_per_rad = odometry.Required("lateral_sigma_per_rad").InRange(0.0, 5.0);
  n.heading_sigma_per_rad = odometry.Required("heading_sigma_per_rad").InRange(0.0, 5.0);
  n.heading_sigma_per_m = odometry.Required("heading_sigma_per_m").InRange(0.0, 5.0);
}

std::vector<std::string> ListYamlStems(const fs::path& dir) {
  std::vector<std::string> out;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    if (entry.is_regular_file() && entry.path().extension() == ".yaml") {
      out.push_back(entry.path().stem().string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string Resolve(const std::string& name_or_path, const fs::path& dir,
                    const std::vector<std::string>& known, const char* what) {
  const bool looks_like_path =
      name_or_path.find('/') != std::string::npos || fs::path(name_or_path).extension() == ".yaml";
  if (looks_like_path) return name_or_path;
  const fs::path candidate = dir / (name_or_path + ".yaml");
  if (fs::exists(candidate)) return candidate.string();
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  throw ConfigError(
      name_or_path, 0, 0, what,
      std::string("a shipped ") + what + " name {" + list + "} or a path to a .yaml file");
}

}  // namespace

std::string ConfigDir() {
  if (const char* env = std::getenv("SLAMO_FIELD_CONFIG_DIR"); env && *env) return env;
  return SLAMO_FIELD_CONFIG_DIR;
}

std::vector<std::string> ListSeasons() { return ListYamlStems(ConfigDir()); }
std::vector<std::string> ListRobots() { return ListYamlStems(fs::path(ConfigDir()) / "robots"); }

std::string ResolveSeasonPath(const std::string& season_or_path) {
  return Resolve(season_or_path, ConfigDir(), ListSeasons(), "season");
}

std::string ResolveRobotPath(const std::string& robot_or_path) {
  return Resolve(robot_or_path, fs::path(ConfigDir()) / "robots", ListRobots(), "robot");
}

namespace {

// yaml-cpp's own exceptions (e.g. a bad conversion when a map key is itself a sequence or a
// map, `[1, 2]: 3`, found by tests/fuzz/field_config_fuzzer) as a ConfigError, so a bad file
// exits with status 2 and a message instead of terminating the program.
ConfigError YamlShapeError(const YAML::Exception& e, const std::string& file) {
  const bool known = !e.mark.is_null();
  return ConfigError(file, known ? e.mark.line + 1 : 0, known ? e.mark.column + 1 : 0, "(document)",
                     "YAML of the expected shape (" + e.msg + ")");
}

}  // namespace

SeasonConfig ParseSeasonConfig(const std::string& yaml_text, const std::string& file) {
  SeasonConfig config;
  config.source_file = file;
  config.season = Stem(file);
  try {
    SeasonParser(&config).Parse(YamlReader::FromText(yaml_text, file));
  } catch (const YAML::Exception& e) {
    throw YamlShapeError(e, file);
  }
  return config;
}

RobotConfig ParseRobotConfig(const std::string& yaml_text, const std::string& file) {
  RobotConfig robot;
  robot.source_file = file;
  try {
    ParseRobot(YamlReader::FromText(yaml_text, file), &robot);
  } catch (const YAML::Exception& e) {
    throw YamlShapeError(e, file);
  }
  return robot;
}

SeasonConfig LoadSeasonConfig(const std::string& season_or_path) {
  const std::string path = ResolveSeasonPath(season_or_path);
  return ParseSeasonConfig(ReadFile(path), path);
}

RobotConfig LoadRobotConfig(const std::string& robot_or_path) {
  const std::string path = ResolveRobotPath(robot_or_path);
  return ParseRobotConfig(ReadFile(path), path);
}

}  // namespace slamo::field
