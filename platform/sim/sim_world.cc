#include "platform/sim/sim_world.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "platform/field_geometry.h"

namespace slamo::platform {
namespace {

using field::SeasonConfig;

double ObjectHeight(const field::ObjectType& type) { return type.height_m; }

}  // namespace

SimWorld CreateWorld(const SeasonConfig& season, uint64_t seed) {
  SimWorld world;
  world.season = &season;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);

  // Lighting: light direction and strength, and a slight colour temperature, per seed.
  const double azimuth = 2.0 * kPi * unit(rng);
  const double elevation = (50.0 + 35.0 * unit(rng)) * kPi / 180.0;
  world.lighting.to_light =
      Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                      std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  world.lighting.ambient = 0.35 + 0.2 * unit(rng);
  world.lighting.diffuse = 0.5 + 0.25 * unit(rng);
  const double warm = 0.06 * (unit(rng) - 0.5);
  world.lighting.tint = Eigen::Vector3d(1.0 + warm, 1.0, 1.0 - warm);

  const auto clear_of_everything = [&](const Eigen::Vector3d& c, double radius, double height) {
    for (const SimObject& o : world.objects) {
      const double other = o.type->size_m / 2.0;
      if ((o.center_m.head<2>() - c.head<2>()).norm() < radius + other &&
          std::abs(o.center_m.z() - c.z()) < radius + other) {
        return false;
      }
    }
    // Not inside a structure nor under a raised one it does not fit under.
    return !PointBlocksObject(season, c.head<2>(), radius, height);
  };

  int next_id = 1;
  for (const field::ObjectPlacement& p : season.objects) {
    const field::ObjectType* type = season.FindObjectType(p.type);
    const double radius = type->size_m / 2.0;
    const double z = p.z_m + ObjectHeight(*type) / 2.0;
    for (int i = 0; i < p.count; ++i) {
      SimObject object;
      object.id = next_id++;
      object.type = type;
      object.colour = p.colour;
      if (p.position_m) {
        object.center_m = Eigen::Vector3d(p.position_m->x, p.position_m->y, z);
      } else {
        // Rejection sampling; after many tries accept an overlap rather than lose an object.
        Eigen::Vector3d c;
        for (int attempt = 0; attempt < 200; ++attempt) {
          c = Eigen::Vector3d(
              p.region->min_m.x + unit(rng) * (p.region->max_m.x - p.region->min_m.x),
              p.region->min_m.y + unit(rng) * (p.region->max_m.y - p.region->min_m.y), z);
          if (clear_of_everything(c, radius, ObjectHeight(*type))) break;
        }
        object.center_m = c;
      }
      world.objects.push_back(object);
    }
  }

  for (const field::OpponentRobot& o : season.opponents) {
    SimOpponent opponent;
    opponent.config = o;
    const auto& a = o.path_m[0];
    const auto& b = o.path_m[1];
    opponent.pose = Pose2D{a.x, a.y, std::atan2(b.y - a.y, b.x - a.x)};
    world.opponents.push_back(opponent);
  }
  return world;
}

namespace {

// Removes the world's objects within `radius_m` (plus their own radius) of `centre_m` and
// returns the next free id.
int ClearAround(const Eigen::Vector2d& centre_m, double radius_m, SimWorld* world) {
  std::vector<SimObject>& objects = world->objects;
  objects.erase(std::remove_if(objects.begin(), objects.end(),
                               [&](const SimObject& o) {
                                 return (o.center_m.head<2>() - centre_m).norm() <
                                        radius_m + o.type->size_m / 2.0;
                               }),
                objects.end());
  int next_id = 1;
  for (const SimObject& o : objects) next_id = std::max(next_id, o.id + 1);
  return next_id;
}

}  // namespace

std::vector<int> AddPile(const field::ObjectType& type, const std::string& colour,
                         const Eigen::Vector2d& centre_m, int count, SimWorld* world) {
  // Hexagonal packing, spacing one size (touching), the `count` places nearest the centre.
  const double spacing = type.size_m * 1.001;
  std::vector<Eigen::Vector2d> places;
  const int rings = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count)))) + 2;
  for (int row = -rings; row <= rings; ++row) {
    for (int column = -rings; column <= rings; ++column) {
      places.emplace_back((column + 0.5 * (row & 1)) * spacing,
                          row * spacing * std::sqrt(3.0) / 2.0);
    }
  }
  std::stable_sort(places.begin(), places.end(),
                   [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
                     return a.squaredNorm() < b.squaredNorm();
                   });
  places.resize(std::min<size_t>(places.size(), count));
  double reach = 0.0;
  for (const Eigen::Vector2d& p : places) reach = std::max(reach, p.norm() + type.size_m / 2.0);
  int next_id = ClearAround(centre_m, reach, world);
  std::vector<int> ids;
  for (const Eigen::Vector2d& p : places) {
    SimObject o;
    o.id = next_id++;
    o.type = &type;
    o.colour = colour;
    o.center_m = Eigen::Vector3d(centre_m.x() + p.x(), centre_m.y() + p.y(), type.height_m / 2.0);
    world->objects.push_back(o);
    ids.push_back(o.id);
  }
  return ids;
}

std::vector<int> AddStack(const field::ObjectType& type, const std::string& colour,
                          const Eigen::Vector2d& centre_m, int count, SimWorld* world) {
  int next_id = ClearAround(centre_m, type.size_m / 2.0, world);
  std::vector<int> ids;
  for (int level = 0; level < count; ++level) {
    SimObject o;
    o.id = next_id++;
    o.type = &type;
    o.colour = colour;
    o.center_m = Eigen::Vector3d(centre_m.x(), centre_m.y(), (level + 0.5) * type.height_m);
    world->objects.push_back(o);
    ids.push_back(o.id);
  }
  return ids;
}

}  // namespace slamo::platform
