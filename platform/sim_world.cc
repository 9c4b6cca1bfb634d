#include "platform/sim_world.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

namespace slamo::platform {
namespace {

using field::SeasonConfig;
using field::SolidShape;
using field::Structure;

// Distance from point p to a structure's footprint in the plane (0 inside).
double DistanceToStructure(const Structure& s, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = p - Eigen::Vector2d(s.center_m.x, s.center_m.y);
  if (s.shape == SolidShape::kCylinder) return std::max(0.0, d.norm() - s.radius_m);
  const double yaw = s.yaw_deg * kPi / 180.0;
  const double lx = std::cos(yaw) * d.x() + std::sin(yaw) * d.y();
  const double ly = -std::sin(yaw) * d.x() + std::cos(yaw) * d.y();
  const double ex = std::max(0.0, std::abs(lx) - s.size_m.x / 2.0);
  const double ey = std::max(0.0, std::abs(ly) - s.size_m.y / 2.0);
  return std::hypot(ex, ey);
}

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

  const auto clear_of_everything = [&](const Eigen::Vector3d& c, double radius) {
    for (const SimObject& o : world.objects) {
      const double other = o.type->size_m / 2.0;
      if ((o.center_m.head<2>() - c.head<2>()).norm() < radius + other &&
          std::abs(o.center_m.z() - c.z()) < radius + other) {
        return false;
      }
    }
    for (const Structure& s : season.structures) {
      if (!s.blocks_robot) continue;
      if (DistanceToStructure(s, c.head<2>()) < radius) return false;
    }
    return true;
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
          if (clear_of_everything(c, radius)) break;
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

bool PointInBlockingStructure(const SeasonConfig& season, const Eigen::Vector2d& p,
                              double clearance_m) {
  for (const Structure& s : season.structures) {
    if (s.blocks_robot && DistanceToStructure(s, p) <= clearance_m) return true;
  }
  return false;
}

bool GoalContains(const field::Goal& goal, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = p - Eigen::Vector2d(goal.center_m.x, goal.center_m.y);
  if (goal.shape == SolidShape::kCylinder) return d.norm() <= goal.radius_m;
  const double yaw = goal.yaw_deg * kPi / 180.0;
  const double lx = std::cos(yaw) * d.x() + std::sin(yaw) * d.y();
  const double ly = -std::sin(yaw) * d.x() + std::cos(yaw) * d.y();
  return std::abs(lx) <= goal.size_m.x / 2.0 && std::abs(ly) <= goal.size_m.y / 2.0;
}

bool FootprintIsFree(const SeasonConfig& season, const Pose2D& pose, double length_m,
                     double width_m) {
  const double c = std::cos(pose.theta_rad);
  const double s = std::sin(pose.theta_rad);
  // Sample the footprint's outline and centre line densely enough for the thinnest posts.
  const double step = 0.02;
  const double half = season.HalfSize();
  const int nx = static_cast<int>(std::ceil(length_m / step));
  const int ny = static_cast<int>(std::ceil(width_m / step));
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      if (i != 0 && i != nx && j != 0 && j != ny && j != ny / 2) continue;
      const double lx = -length_m / 2.0 + length_m * i / nx;
      const double ly = -width_m / 2.0 + width_m * j / ny;
      const Eigen::Vector2d p(pose.x_m + c * lx - s * ly, pose.y_m + s * lx + c * ly);
      if (std::abs(p.x()) > half || std::abs(p.y()) > half) return false;
      for (const Structure& st : season.structures) {
        if (st.blocks_robot && DistanceToStructure(st, p) <= 0.0) return false;
      }
    }
  }
  return true;
}

}  // namespace slamo::platform
