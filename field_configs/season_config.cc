#include "field_configs/season_config.h"

#include "field_configs/config_error.h"

namespace slamo::field {

ConfigError::ConfigError(std::string file, int line, int column, std::string key_path,
                         std::string expected)
    : std::runtime_error(
          file +
          (line > 0 ? ":" + std::to_string(line) + ":" + std::to_string(column) : std::string()) +
          ": " + key_path + ": " + expected),
      file_(std::move(file)),
      line_(line),
      column_(column),
      key_path_(std::move(key_path)),
      expected_(std::move(expected)) {}

const ObjectType* SeasonConfig::FindObjectType(const std::string& type_name) const {
  for (const ObjectType& type : object_types) {
    if (type.name == type_name) return &type;
  }
  return nullptr;
}

int SeasonConfig::ObjectCount() const {
  int total = 0;
  for (const ObjectPlacement& placement : objects) total += placement.count;
  return total;
}

const char* ToString(Alliance alliance) {
  switch (alliance) {
    case Alliance::kRed:
      return "red";
    case Alliance::kBlue:
      return "blue";
    case Alliance::kNone:
      break;
  }
  return "none";
}

const char* ToString(ObjectShape shape) {
  switch (shape) {
    case ObjectShape::kSphere:
      return "sphere";
    case ObjectShape::kCube:
      return "cube";
    case ObjectShape::kStar:
      return "star";
    case ObjectShape::kTorus:
      return "torus";
    case ObjectShape::kTriball:
      return "triball";
    case ObjectShape::kHollowBlock:
      return "hollow_block";
    case ObjectShape::kCylinder:
      return "cylinder";
  }
  return "?";
}

const char* ToString(Material material) {
  return material == Material::kSolid ? "solid" : "semi_transparent";
}

}  // namespace slamo::field
