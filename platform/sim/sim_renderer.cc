#include "platform/sim/sim_renderer.h"

#include "platform/camera_geometry.h"
#include "platform/field_geometry.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include <emmintrin.h>

#include <opencv2/imgproc.hpp>

namespace slamo::platform {

using Eigen::Vector3d;
using Eigen::Vector3f;

enum class PrimitiveKind { kSphere, kBox, kCylinder, kRing, kPlate, kPrism };

struct SimRenderer::Primitive {
  PrimitiveKind kind = PrimitiveKind::kSphere;
  Vector3d center =
      Vector3d::Zero();               // sphere centre; box/cylinder/ring/plate: (x, y) and unused z
  double radius = 0.0;                // sphere, cylinder, ring outer, plate disc radius
  double inner_radius = 0.0;          // ring
  double half_x = 0.0, half_y = 0.0;  // box (local axes), plate half width
  double z0 = 0.0, z1 = 0.0;          // vertical extent (box, cylinder, ring, plate)
  double cos_yaw = 1.0, sin_yaw = 0.0;
  Vector3d plate_normal = Vector3d::UnitX();  // plate: horizontal normal facing the viewer
  bool plate_disc = true;
  std::vector<Eigen::Vector2d> polygon;       // prism: outline around (x, y), counter-clockwise
  Vector3d albedo = Vector3d::Constant(0.5);  // RGB in [0, 1]
  double opacity = 1.0;
  bool glossy = false;
  int id = 0;
  Vector3d aabb_min = Vector3d::Zero(), aabb_max = Vector3d::Zero();
};

namespace {

using Primitive = SimRenderer::Primitive;

constexpr float kInf = std::numeric_limits<float>::infinity();

Vector3d Albedo(const field::SeasonConfig& season, const std::string& colour) {
  const field::Rgb& c = season.colours.at(colour);
  return Vector3d(c.r, c.g, c.b) / 255.0;
}

// x^n by squaring (n >= 0): the highlight exponents, without std::pow per pixel.
float PowInt(float x, int n) {
  float result = 1.0f;
  while (n > 0) {
    if (n & 1) result *= x;
    x *= x;
    n >>= 1;
  }
  return result;
}

double Luminance(const Vector3d& rgb) {
  return 0.299 * rgb.x() + 0.587 * rgb.y() + 0.114 * rgb.z();
}

void SetAabb(Primitive* p) {
  switch (p->kind) {
    case PrimitiveKind::kSphere:
      p->aabb_min = p->center - Vector3d::Constant(p->radius);
      p->aabb_max = p->center + Vector3d::Constant(p->radius);
      return;
    case PrimitiveKind::kBox: {
      const double ex = std::abs(p->cos_yaw) * p->half_x + std::abs(p->sin_yaw) * p->half_y;
      const double ey = std::abs(p->sin_yaw) * p->half_x + std::abs(p->cos_yaw) * p->half_y;
      p->aabb_min = Vector3d(p->center.x() - ex, p->center.y() - ey, p->z0);
      p->aabb_max = Vector3d(p->center.x() + ex, p->center.y() + ey, p->z1);
      return;
    }
    case PrimitiveKind::kCylinder:
    case PrimitiveKind::kRing:
    case PrimitiveKind::kPrism:
      p->aabb_min = Vector3d(p->center.x() - p->radius, p->center.y() - p->radius, p->z0);
      p->aabb_max = Vector3d(p->center.x() + p->radius, p->center.y() + p->radius, p->z1);
      return;
    case PrimitiveKind::kPlate: {
      const double e = std::max(p->radius, p->half_x) + 0.01;
      p->aabb_min = Vector3d(p->center.x() - e, p->center.y() - e, p->z0);
      p->aabb_max = Vector3d(p->center.x() + e, p->center.y() + e, p->z1);
      return;
    }
  }
}

// Ray o + t d against a vertical cylinder side (radius r, axis through c) within [z0, z1].
// `inside` selects the far (inner-surface) hit.
bool HitCylinderSide(const Vector3d& o, const Vector3d& d, const Vector3d& c, double r, double z0,
                     double z1, bool inside, double* t, Vector3d* n) {
  const double ox = o.x() - c.x(), oy = o.y() - c.y();
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a < 1e-12) return false;
  const double b = 2.0 * (ox * d.x() + oy * d.y());
  const double cc = ox * ox + oy * oy - r * r;
  const double disc = b * b - 4.0 * a * cc;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  const double candidates[2] = {(-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a)};
  for (int k = inside ? 1 : 0; k < 2; ++k) {
    const double tk = candidates[k];
    if (tk <= 1e-6) continue;
    const double z = o.z() + tk * d.z();
    if (z < z0 || z > z1) continue;
    *t = tk;
    const Vector3d hit = o + tk * d;
    *n = Vector3d(hit.x() - c.x(), hit.y() - c.y(), 0.0).normalized();
    if (inside) *n = -*n;
    return true;
  }
  return false;
}

// Nearest intersection of a ray with a primitive.
bool Intersect(const Primitive& p, const Vector3d& o, const Vector3d& d, double* t, Vector3d* n) {
  switch (p.kind) {
    case PrimitiveKind::kSphere: {
      const Vector3d oc = o - p.center;
      const double b = oc.dot(d);
      const double c = oc.squaredNorm() - p.radius * p.radius;
      const double a = d.squaredNorm();
      const double disc = b * b - a * c;
      if (disc < 0.0) return false;
      const double tt = (-b - std::sqrt(disc)) / a;
      if (tt <= 1e-6) return false;
      *t = tt;
      *n = (o + tt * d - p.center) / p.radius;
      return true;
    }
    case PrimitiveKind::kBox: {
      // Into the box's local frame (yaw about z).
      const double rx = o.x() - p.center.x(), ry = o.y() - p.center.y();
      const Vector3d lo(p.cos_yaw * rx + p.sin_yaw * ry, -p.sin_yaw * rx + p.cos_yaw * ry, o.z());
      const Vector3d ld(p.cos_yaw * d.x() + p.sin_yaw * d.y(),
                        -p.sin_yaw * d.x() + p.cos_yaw * d.y(), d.z());
      const double lo_b[3] = {-p.half_x, -p.half_y, p.z0};
      const double hi_b[3] = {p.half_x, p.half_y, p.z1};
      double t_near = -std::numeric_limits<double>::infinity();
      double t_far = std::numeric_limits<double>::infinity();
      int axis = -1;
      double sign = 1.0;
      for (int i = 0; i < 3; ++i) {
        if (std::abs(ld[i]) < 1e-12) {
          if (lo[i] < lo_b[i] || lo[i] > hi_b[i]) return false;
          continue;
        }
        double t0 = (lo_b[i] - lo[i]) / ld[i];
        double t1 = (hi_b[i] - lo[i]) / ld[i];
        double s = -1.0;
        if (t0 > t1) std::swap(t0, t1), s = 1.0;
        if (t0 > t_near) t_near = t0, axis = i, sign = s;
        t_far = std::min(t_far, t1);
        if (t_near > t_far) return false;
      }
      if (t_near <= 1e-6 || axis < 0) return false;
      *t = t_near;
      Vector3d ln = Vector3d::Zero();
      ln[axis] = sign;
      *n = Vector3d(p.cos_yaw * ln.x() - p.sin_yaw * ln.y(),
                    p.sin_yaw * ln.x() + p.cos_yaw * ln.y(), ln.z());
      return true;
    }
    case PrimitiveKind::kCylinder:
    case PrimitiveKind::kRing: {
      double best = std::numeric_limits<double>::infinity();
      Vector3d best_n = Vector3d::Zero();
      double tt = 0.0;
      Vector3d nn = Vector3d::Zero();
      if (HitCylinderSide(o, d, p.center, p.radius, p.z0, p.z1, false, &tt, &nn) && tt < best)
        best = tt, best_n = nn;
      if (p.kind == PrimitiveKind::kRing &&
          HitCylinderSide(o, d, p.center, p.inner_radius, p.z0, p.z1, true, &tt, &nn) &&
          tt < best) {
        best = tt, best_n = nn;
      }
      // Caps.
      if (std::abs(d.z()) > 1e-12) {
        for (const double zc : {p.z1, p.z0}) {
          tt = (zc - o.z()) / d.z();
          if (tt <= 1e-6 || tt >= best) continue;
          const double dx = o.x() + tt * d.x() - p.center.x();
          const double dy = o.y() + tt * d.y() - p.center.y();
          const double r2 = dx * dx + dy * dy;
          if (r2 > p.radius * p.radius) continue;
          if (p.kind == PrimitiveKind::kRing && r2 < p.inner_radius * p.inner_radius) continue;
          best = tt, best_n = Vector3d(0, 0, zc == p.z1 ? 1.0 : -1.0);
        }
      }
      if (!std::isfinite(best)) return false;
      *t = best;
      *n = best_n;
      return true;
    }
    case PrimitiveKind::kPrism: {
      // A vertical prism over a polygon: the caps where the hit lies inside the outline,
      // the side walls where the ray crosses an edge between z0 and z1.
      const Eigen::Vector2d o2(o.x() - p.center.x(), o.y() - p.center.y());
      const Eigen::Vector2d d2(d.x(), d.y());
      double best = std::numeric_limits<double>::infinity();
      Vector3d best_n = Vector3d::Zero();
      const size_t k = p.polygon.size();
      for (size_t e = 0; e < k; ++e) {
        const Eigen::Vector2d a = p.polygon[e];
        const Eigen::Vector2d edge = p.polygon[(e + 1) % k] - a;
        const double denom = d2.x() * edge.y() - d2.y() * edge.x();
        if (std::abs(denom) < 1e-12) continue;
        const Eigen::Vector2d ao = a - o2;
        const double tt = (ao.x() * edge.y() - ao.y() * edge.x()) / denom;
        const double s = (ao.x() * d2.y() - ao.y() * d2.x()) / denom;
        if (tt <= 1e-6 || tt >= best || s < 0.0 || s > 1.0) continue;
        const double z = o.z() + tt * d.z();
        if (z < p.z0 || z > p.z1) continue;
        best = tt;
        best_n = Vector3d(edge.y(), -edge.x(), 0.0).normalized();  // outward (CCW outline)
      }
      if (std::abs(d.z()) > 1e-12) {
        for (const double zc : {p.z1, p.z0}) {
          const double tt = (zc - o.z()) / d.z();
          if (tt <= 1e-6 || tt >= best) continue;
          const Eigen::Vector2d q = o2 + tt * d2;
          bool inside = false;  // crossing number
          for (size_t e = 0, f = k - 1; e < k; f = e++) {
            const Eigen::Vector2d& a = p.polygon[e];
            const Eigen::Vector2d& b = p.polygon[f];
            if ((a.y() > q.y()) != (b.y() > q.y()) &&
                q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x()) {
              inside = !inside;
            }
          }
          if (inside) best = tt, best_n = Vector3d(0, 0, zc == p.z1 ? 1.0 : -1.0);
        }
      }
      if (!std::isfinite(best)) return false;
      *t = best;
      *n = best_n;
      return true;
    }
    case PrimitiveKind::kPlate: {
      const double denom = p.plate_normal.dot(d);
      if (std::abs(denom) < 1e-9) return false;
      const double tt = p.plate_normal.dot(p.center - o) / denom;
      if (tt <= 1e-6) return false;
      const Vector3d hit = o + tt * d;
      const Vector3d rel = hit - p.center;
      if (p.plate_disc) {
        if (rel.squaredNorm() > p.radius * p.radius) return false;
      } else {
        const Vector3d side = Vector3d::UnitZ().cross(p.plate_normal);
        if (std::abs(rel.dot(side)) > p.half_x || std::abs(rel.z()) > p.half_x) return false;
      }
      *t = tt;
      *n = denom < 0 ? p.plate_normal : -p.plate_normal;
      return true;
    }
  }
  return false;
}

Primitive ObjectPrimitive(const field::SeasonConfig& season, const SimObject& object) {
  const field::ObjectType& type = *object.type;
  Primitive p;
  p.id = object.id;
  p.albedo = Albedo(season, object.colour);
  p.opacity = type.material == field::Material::kSemiTransparent ? type.opacity : 1.0;
  p.center = object.center_m;
  const double half_h = type.height_m / 2.0;
  p.z0 = object.center_m.z() - half_h;
  p.z1 = object.center_m.z() + half_h;
  switch (type.shape) {
    case field::ObjectShape::kSphere:
    case field::ObjectShape::kTriball:  // rendered as its bounding sphere
      p.kind = PrimitiveKind::kSphere;
      p.radius = type.size_m / 2.0;
      p.glossy = true;
      break;
    case field::ObjectShape::kCube:
    case field::ObjectShape::kHollowBlock:
      p.kind = PrimitiveKind::kBox;
      p.half_x = p.half_y = type.size_m / 2.0;
      break;
    case field::ObjectShape::kTorus:  // a flat ring: outer diameter size_m, tube = height
      p.kind = PrimitiveKind::kRing;
      p.radius = type.size_m / 2.0;
      p.inner_radius = std::max(0.0, p.radius - std::max(type.height_m, type.size_m * 0.2));
      break;
    case field::ObjectShape::kStar:  // a five-pointed star prism, lying flat
      p.kind = PrimitiveKind::kPrism;
      p.radius = type.size_m / 2.0;
      for (int k = 0; k < 10; ++k) {
        const double angle = kPi / 2.0 + k * kPi / 5.0;
        const double r = k % 2 == 0 ? p.radius : 0.45 * p.radius;
        p.polygon.emplace_back(r * std::cos(angle), r * std::sin(angle));
      }
      break;
    case field::ObjectShape::kCylinder:
      p.kind = PrimitiveKind::kCylinder;
      p.radius = type.size_m / 2.0;
      break;
  }
  SetAabb(&p);
  return p;
}

// An opponent in arena mode, from its footprint box `body`: a dark metal chassis, bumpers in
// the alliance's colour all round its foot, and an alliance-coloured flag plate on top.
void AddArenaRobot(const field::SeasonConfig& season, const Primitive& body, const char* alliance,
                   std::vector<Primitive>* out) {
  const Vector3d team =
      season.colours.count(alliance) ? Albedo(season, alliance) : Vector3d(Vector3d::Constant(0.5));
  Primitive chassis = body;
  chassis.albedo = Vector3d(0.22, 0.22, 0.24);
  chassis.glossy = true;
  SetAabb(&chassis);
  out->push_back(chassis);
  constexpr double kBumper = 0.06;  // thickness (m)
  for (int side = 0; side < 4; ++side) {
    Primitive bumper = body;
    const bool along_x = side < 2;
    const double sign = side % 2 ? -1.0 : 1.0;
    const double offset = (along_x ? body.half_y : body.half_x) + kBumper / 2.0;
    const Vector3d local = along_x ? Vector3d(0, sign * offset, 0) : Vector3d(sign * offset, 0, 0);
    bumper.center = body.center + Vector3d(body.cos_yaw * local.x() - body.sin_yaw * local.y(),
                                           body.sin_yaw * local.x() + body.cos_yaw * local.y(), 0);
    bumper.half_x = along_x ? body.half_x + kBumper : kBumper / 2.0;
    bumper.half_y = along_x ? kBumper / 2.0 : body.half_y;
    bumper.z0 = 0.02;
    bumper.z1 = 0.14;
    bumper.albedo = team;
    SetAabb(&bumper);
    out->push_back(bumper);
  }
  Primitive flag = body;
  flag.half_x = 0.01;
  flag.half_y = std::min(0.12, body.half_y);
  flag.z0 = body.z1;
  flag.z1 = body.z1 + 0.15;
  flag.albedo = team;
  SetAabb(&flag);
  out->push_back(flag);
}

}  // namespace

struct SimRenderer::Buffers {
  int width = 0, height = 0;
  std::vector<float> t;          // depth along the optical axis (m), inf = nothing
  std::vector<Vector3f> colour;  // linear RGB in [0, 1]
  std::vector<uint16_t> id;
  std::vector<uint8_t> no_depth;   // 1: the camera reads nothing here (black, specular, sky)
  std::vector<Vector3f> row_rays;  // per row, the world ray of its first pixel (camera z = 1)

  void Reset(int w, int h) {
    width = w, height = h;
    const size_t n = static_cast<size_t>(w) * h;
    // Kept between frames: resizing is a no-op after the first, so no fresh pages per frame.
    t.resize(n), colour.resize(n), id.resize(n), no_depth.resize(n), row_rays.resize(h);
    // t, colour and no_depth are written for every pixel by the floor pass.
    std::fill(id.begin(), id.end(), uint16_t{0});
  }
};

SimRenderer::SimRenderer(const field::SeasonConfig& season, const field::CameraConfig& camera,
                         RenderOptions options, uint64_t seed)
    : season_(season),
      camera_(camera),
      options_(options),
      seed_(seed),
      rng_(seed),
      depth_buffers_(std::make_unique<Buffers>()),
      colour_buffers_(std::make_unique<Buffers>()) {
  rays_cam_.reserve(static_cast<size_t>(camera.width_px) * camera.height_px);
  ray_length2_.reserve(rays_cam_.capacity());
  for (int v = 0; v < camera.height_px; ++v) {
    for (int u = 0; u < camera.width_px; ++u) {
      rays_cam_.emplace_back(static_cast<float>((u + 0.5 - camera.cx) / camera.fx),
                             static_cast<float>((v + 0.5 - camera.cy) / camera.fy), 1.0f);
      ray_length2_.push_back(rays_cam_.back().squaredNorm());
    }
  }
  // A pool of standard normal draws, read from a random offset each frame: per-pixel noise
  // without a normal draw per pixel per frame. The pool holds four frames' worth of pixels
  // (at least 2^20), so a frame's colour noise (3 per pixel) always fits after an offset.
  std::normal_distribution<float> normal(0.0f, 1.0f);
  normal_pool_.resize(std::max<size_t>(size_t{1} << 20, 4 * rays_cam_.size()));
  for (float& x : normal_pool_) x = normal(rng_);
  BuildStaticPrimitives();
  // sigma(d) per millimetre of depth, so the per-pixel noise needs no table search.
  sigma_mm_by_mm_.resize(static_cast<size_t>(camera.max_range_m * 1000.0) + 2);
  for (size_t mm = 0; mm < sigma_mm_by_mm_.size(); ++mm) {
    sigma_mm_by_mm_[mm] = static_cast<float>(1000.0 * DepthSigmaM((mm + 0.5) / 1000.0));
  }
}

SimRenderer::~SimRenderer() = default;

void SimRenderer::BuildStaticPrimitives() {
  for (const field::Structure& s : season_.structures) {
    Primitive p;
    p.center = Vector3d(s.center_m.x, s.center_m.y, 0.0);
    p.z0 = s.z_min_m;
    p.z1 = s.height_m;
    p.albedo = Albedo(season_, s.colour);
    if (s.shape == field::SolidShape::kBox) {
      p.kind = PrimitiveKind::kBox;
      p.half_x = s.size_m.x / 2.0;
      p.half_y = s.size_m.y / 2.0;
      p.cos_yaw = std::cos(s.yaw_deg * kPi / 180.0);
      p.sin_yaw = std::sin(s.yaw_deg * kPi / 180.0);
    } else {
      p.kind = PrimitiveKind::kCylinder;
      p.radius = s.radius_m;
    }
    SetAabb(&p);
    static_primitives_.push_back(p);
  }
  // Landmarks: discs and squares are plates on the inner face of the nearest wall, facing the
  // field; cylinders and spheres stand where they are.
  for (size_t i = 0; i < season_.landmarks.size(); ++i) {
    const field::Landmark& l = season_.landmarks[i];
    Primitive p;
    p.id = kLandmarkIdBase + static_cast<int>(i);
    p.albedo = Albedo(season_, l.colour);
    const double r = l.size_m / 2.0;
    p.z0 = l.height_m - r;
    p.z1 = l.height_m + r;
    if (l.shape == field::LandmarkShape::kDisc || l.shape == field::LandmarkShape::kSquare) {
      p.kind = PrimitiveKind::kPlate;
      p.plate_disc = l.shape == field::LandmarkShape::kDisc;
      p.radius = r;
      p.half_x = r;
      const bool on_x_wall = std::abs(l.position_m.x) >= std::abs(l.position_m.y);
      p.center = LandmarkCentre(season_, l);
      p.plate_normal = on_x_wall ? Vector3d(p.center.x() > 0 ? -1.0 : 1.0, 0.0, 0.0)
                                 : Vector3d(0.0, p.center.y() > 0 ? -1.0 : 1.0, 0.0);
    } else if (l.shape == field::LandmarkShape::kCylinder) {
      p.kind = PrimitiveKind::kCylinder;
      p.radius = r;
      p.center = LandmarkCentre(season_, l);
    } else {
      p.kind = PrimitiveKind::kSphere;
      p.radius = r;
      p.center = LandmarkCentre(season_, l);
    }
    SetAabb(&p);
    landmark_centres_.push_back(p.center);
    static_primitives_.push_back(p);
  }
}

Eigen::Isometry3d SimRenderer::CameraPose(const Pose2D& robot) const {
  return WorldFromRobot(robot) * RobotFromCamera(camera_.mount);
}

double SimRenderer::DepthSigmaM(double depth_m) const {
  return platform::DepthSigmaM(camera_, depth_m);
}

void SimRenderer::RenderPass(const SimWorld& world, const Eigen::Isometry3d& world_from_camera,
                             const ArenaBackdrop* arena, Buffers* out) const {
  const int w = camera_.width_px;
  const int h = camera_.height_px;
  out->Reset(w, h);
  const Eigen::Matrix3f rotation = world_from_camera.linear().cast<float>();
  const Vector3d origin = world_from_camera.translation();
  const Lighting& light = world.lighting;
  const double half = season_.HalfSize();
  const double wall_h = season_.field.wall_height_m;
  const Vector3d tile_albedo = Albedo(season_, season_.field.tile_colour);
  const Vector3d wall_albedo = Albedo(season_, season_.field.wall_colour);
  const double tile = season_.field.tile_m;

  const Vector3f to_light_f = light.to_light.cast<float>();
  const Vector3f tint_f = light.tint.cast<float>();
  const float ambient_f = static_cast<float>(light.ambient);
  const float diffuse_f = static_cast<float>(light.diffuse);
  // Lambert: albedo * (ambient + diffuse * max(0, n . l)) * tint.
  const auto shade_f = [&](const Vector3f& albedo, const Vector3f& n) -> Vector3f {
    const float lambert = ambient_f + diffuse_f * std::max(0.0f, n.dot(to_light_f));
    return albedo.cwiseProduct(tint_f) * lambert;
  };
  const auto shade = [&](const Vector3d& albedo, const Vector3d& n) -> Vector3f {
    return shade_f(albedo.cast<float>(), n.cast<float>());
  };

  // 1. Floor, walls and the venue beyond them, for every pixel; the world rays are kept for
  // the passes below. Single precision and per-frame constants: this loop touches every pixel.
  std::vector<Vector3f>& row_rays = out->row_rays;
  const Vector3f o = origin.cast<float>();
  const float half_f = static_cast<float>(half);
  const float tile_f = static_cast<float>(tile);
  const float wall_h_f = static_cast<float>(wall_h);
  const Vector3f floor_colour = shade(tile_albedo, Vector3d::UnitZ());
  const Vector3f wall_colour[4] = {
      shade(wall_albedo, -Vector3d::UnitX()), shade(wall_albedo, Vector3d::UnitX()),
      shade(wall_albedo, -Vector3d::UnitY()), shade(wall_albedo, Vector3d::UnitY())};
  const bool floor_black = Luminance(tile_albedo) < options_.black_albedo;
  const bool wall_black = Luminance(wall_albedo) < options_.black_albedo;
  constexpr float kSeamM = 0.004f;
  // Each tile's shade factor by its hash's low byte: the same float as computed per pixel,
  // without a division per floor pixel.
  float tile_variation[256];
  for (int k = 0; k < 256; ++k) tile_variation[k] = 0.96f + 0.08f * (k / 255.0f);
  // The world ray is linear in u along a row: start of row plus u steps.
  const Vector3f ray_step = rotation.col(0) / static_cast<float>(camera_.fx);
  // The floor test runs four pixels at a time in SSE2: the same single-precision operations
  // in the same order as one pixel at a time (no FMA), so the same bits, with the three
  // divisions per pixel done four at once. The row's rays are accumulated first, as before.
  const int w4 = (w + 3) / 4 * 4;
  std::vector<float> row_x(w4, 0.0f), row_y(w4, 0.0f), row_z(w4, 0.0f);
  const __m128 neg_oz4 = _mm_set1_ps(-o.z());
  const __m128 ox4 = _mm_set1_ps(o.x()), oy4 = _mm_set1_ps(o.y());
  const __m128 half4 = _mm_set1_ps(half_f), field4 = _mm_set1_ps(2.0f * half_f);
  const __m128 tile4 = _mm_set1_ps(tile_f), zero4 = _mm_setzero_ps();
  const __m128 seam_lo4 = _mm_set1_ps(kSeamM), seam_hi4 = _mm_set1_ps(tile_f - kSeamM);
  const __m128 down4 = _mm_set1_ps(-1e-9f);
  for (int v = 0; v < h; ++v) {
    Vector3f d = rotation * rays_cam_[static_cast<size_t>(v) * w];
    row_rays[v] = d;
    for (int u = 0; u < w; ++u, d += ray_step) row_x[u] = d.x(), row_y[u] = d.y(), row_z[u] = d.z();
    for (int u0 = 0; u0 < w; u0 += 4) {
      const __m128 dx = _mm_loadu_ps(&row_x[u0]), dy = _mm_loadu_ps(&row_y[u0]);
      const __m128 dz = _mm_loadu_ps(&row_z[u0]);
      const __m128 t_floor = _mm_div_ps(neg_oz4, dz);
      const __m128 px = _mm_add_ps(_mm_add_ps(ox4, _mm_mul_ps(t_floor, dx)), half4);
      const __m128 py = _mm_add_ps(_mm_add_ps(oy4, _mm_mul_ps(t_floor, dy)), half4);
      const __m128 on_floor =
          _mm_and_ps(_mm_and_ps(_mm_cmplt_ps(dz, down4),
                                _mm_and_ps(_mm_cmpge_ps(px, zero4), _mm_cmpge_ps(py, zero4))),
                     _mm_and_ps(_mm_cmple_ps(px, field4), _mm_cmple_ps(py, field4)));
      const int floor_lanes = _mm_movemask_ps(on_floor);
      // Tiles: seams 4 mm wide, each tile's shade varied a little.
      const __m128 fx = _mm_div_ps(px, tile4), fy = _mm_div_ps(py, tile4);
      const __m128i ix4 = _mm_cvttps_epi32(fx), iy4 = _mm_cvttps_epi32(fy);
      const __m128 sx = _mm_mul_ps(_mm_sub_ps(fx, _mm_cvtepi32_ps(ix4)), tile4);
      const __m128 sy = _mm_mul_ps(_mm_sub_ps(fy, _mm_cvtepi32_ps(iy4)), tile4);
      const __m128 seam4 =
          _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(sx, seam_lo4), _mm_cmplt_ps(sy, seam_lo4)),
                    _mm_or_ps(_mm_cmpgt_ps(sx, seam_hi4), _mm_cmpgt_ps(sy, seam_hi4)));
      const int seam_lanes = _mm_movemask_ps(seam4);
      alignas(16) float t_lane[4];
      alignas(16) int32_t ix_lane[4], iy_lane[4];
      _mm_store_ps(t_lane, t_floor);
      _mm_store_si128(reinterpret_cast<__m128i*>(ix_lane), ix4);
      _mm_store_si128(reinterpret_cast<__m128i*>(iy_lane), iy4);
      for (int lane = 0; lane < 4 && u0 + lane < w; ++lane) {
        const int u = u0 + lane;
        const size_t i = static_cast<size_t>(v) * w + u;
        // A floor point inside the perimeter is reached before any wall (the camera is inside
        // the field), so the walls are only tested for rays that miss the field's floor.
        if (floor_lanes >> lane & 1) {
          const int tile_hash = (ix_lane[lane] * 73856093) ^ (iy_lane[lane] * 19349663);
          out->colour[i] =
              floor_colour * ((seam_lanes >> lane & 1) ? 0.7f : tile_variation[tile_hash & 0xff]);
          out->t[i] = t_lane[lane];
          out->no_depth[i] = floor_black;
          continue;
        }
        const Vector3f d(row_x[u], row_y[u], row_z[u]);
        // Nearest perimeter wall along the ray.
        float t_wall = kInf;
        int wall = 0;
        if (d.x() > 1e-9f) t_wall = (half_f - o.x()) / d.x(), wall = 0;
        if (d.x() < -1e-9f) t_wall = (-half_f - o.x()) / d.x(), wall = 1;
        if (d.y() > 1e-9f) {
          const float t = (half_f - o.y()) / d.y();
          if (t < t_wall) t_wall = t, wall = 2;
        }
        if (d.y() < -1e-9f) {
          const float t = (-half_f - o.y()) / d.y();
          if (t < t_wall) t_wall = t, wall = 3;
        }
        if (t_wall < kInf && o.z() + t_wall * d.z() <= wall_h_f) {
          out->colour[i] = wall_colour[wall];
          out->t[i] = t_wall;
          out->no_depth[i] = wall_black;
        } else if (arena) {
          ShadeArena(*arena, o, d, &out->colour[i], &out->t[i], &out->no_depth[i]);
        } else {
          // The venue: dim, no depth within the camera's range.
          const float g = 0.25f + 0.1f * std::max(0.0f, d.z() / d.norm());
          out->colour[i] = Vector3f(g, g, g * 1.1f);
          out->t[i] = kInf;
          out->no_depth[i] = 1;
        }
      }
    }
  }

  // 2. Solid primitives, each over its projected bounding box only.
  std::vector<Primitive> primitives = static_primitives_;
  std::vector<Primitive> transparent;
  for (size_t k = 0; k < world.opponents.size(); ++k) {
    const SimOpponent& o = world.opponents[k];
    Primitive p;
    p.kind = PrimitiveKind::kBox;
    p.id = kOpponentIdBase + static_cast<int>(k);
    p.center = Vector3d(o.pose.x_m, o.pose.y_m, 0.0);
    p.half_x = o.config.size_m.x / 2.0;
    p.half_y = o.config.size_m.y / 2.0;
    p.z0 = 0.0;
    p.z1 = o.height_m;
    p.cos_yaw = std::cos(o.pose.theta_rad);
    p.sin_yaw = std::sin(o.pose.theta_rad);
    const char* alliance = field::ToString(o.config.alliance);
    if (arena) {
      AddArenaRobot(season_, p, alliance, &primitives);
      continue;
    }
    p.albedo = season_.colours.count(alliance) ? Vector3d(0.6 * Albedo(season_, alliance))
                                               : Vector3d(Vector3d::Constant(0.3));
    SetAabb(&p);
    primitives.push_back(p);
  }
  for (const SimObject& object : world.objects) {
    if (object.held) continue;
    Primitive p = ObjectPrimitive(season_, object);
    (p.opacity < 1.0 ? transparent : primitives).push_back(p);
  }
  const Eigen::Isometry3d camera_from_world = world_from_camera.inverse();
  // A primitive's pixels lie inside the projection of its bounding box. The box's corners are
  // taken into the camera frame and their camera-space bounds clipped at the near plane, so a
  // box that straddles the camera plane still gets a tight screen box.
  const auto screen_box = [&](const Primitive& p) {
    constexpr double kNear = 0.02;
    Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity());
    Vector3d hi = -lo;
    for (int k = 0; k < 8; ++k) {
      const Vector3d corner((k & 1) ? p.aabb_max.x() : p.aabb_min.x(),
                            (k & 2) ? p.aabb_max.y() : p.aabb_min.y(),
                            (k & 4) ? p.aabb_max.z() : p.aabb_min.z());
      const Vector3d c = camera_from_world * corner;
      lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
    }
    if (hi.z() < kNear) return cv::Rect();  // wholly behind the camera
    const double z_near = std::max(lo.z(), kNear);
    // x / z over the clipped box is extreme at its corners.
    const auto range = [&](double a, double b, double f, double centre, double* out_lo,
                           double* out_hi) {
      const double values[4] = {a / z_near, a / hi.z(), b / z_near, b / hi.z()};
      *out_lo = f * *std::min_element(values, values + 4) + centre;
      *out_hi = f * *std::max_element(values, values + 4) + centre;
    };
    double u0, u1, v0, v1;
    range(lo.x(), hi.x(), camera_.fx, camera_.cx, &u0, &u1);
    range(lo.y(), hi.y(), camera_.fy, camera_.cy, &v0, &v1);
    const int iu0 = static_cast<int>(std::max(0.0, std::floor(u0)));
    const int iv0 = static_cast<int>(std::max(0.0, std::floor(v0)));
    const int iu1 = static_cast<int>(std::min(w - 1.0, std::ceil(u1)));
    const int iv1 = static_cast<int>(std::min(h - 1.0, std::ceil(v1)));
    if (iu1 < iu0 || iv1 < iv0) return cv::Rect();
    return cv::Rect(iu0, iv0, iu1 - iu0 + 1, iv1 - iv0 + 1);
  };
  // Calls on_hit(pixel, ray, t, normal) for each pixel where `p` is the nearest surface so far.
  const auto for_each_hit = [&](const Primitive& p, auto&& on_hit) {
    const cv::Rect box = screen_box(p);
    if (p.kind == PrimitiveKind::kSphere) {
      // Spheres, the most common object, in single precision: |d|^2 is the camera ray's
      // (rotation keeps lengths), so a hit costs a dot product and a square root.
      const Vector3f oc = (origin - p.center).cast<float>();
      const float c = oc.squaredNorm() - static_cast<float>(p.radius * p.radius);
      const float inv_r = static_cast<float>(1.0 / p.radius);
      for (int v = box.y; v < box.y + box.height; ++v) {
        for (int u = box.x; u < box.x + box.width; ++u) {
          const size_t i = static_cast<size_t>(v) * w + u;
          const Vector3f d = row_rays[v] + static_cast<float>(u) * ray_step;
          const float b = oc.dot(d);
          const float a = ray_length2_[i];
          const float disc = b * b - a * c;
          if (disc < 0.0f) continue;
          const float t = (-b - std::sqrt(disc)) / a;
          if (t <= 1e-6f || t >= out->t[i]) continue;
          on_hit(i, d, t, Vector3f((oc + t * d) * inv_r));
        }
      }
      return;
    }
    if (p.kind == PrimitiveKind::kBox) {
      // Boxes (structures, cubes, opponents) in single precision, in the box's own frame.
      const float cy = static_cast<float>(p.cos_yaw), sy = static_cast<float>(p.sin_yaw);
      const float rx = static_cast<float>(origin.x() - p.center.x());
      const float ry = static_cast<float>(origin.y() - p.center.y());
      const float lo_o[3] = {cy * rx + sy * ry, -sy * rx + cy * ry, static_cast<float>(origin.z())};
      const float lo_b[3] = {static_cast<float>(-p.half_x), static_cast<float>(-p.half_y),
                             static_cast<float>(p.z0)};
      const float hi_b[3] = {static_cast<float>(p.half_x), static_cast<float>(p.half_y),
                             static_cast<float>(p.z1)};
      for (int v = box.y; v < box.y + box.height; ++v) {
        for (int u = box.x; u < box.x + box.width; ++u) {
          const size_t i = static_cast<size_t>(v) * w + u;
          const Vector3f d = row_rays[v] + static_cast<float>(u) * ray_step;
          const float ld[3] = {cy * d.x() + sy * d.y(), -sy * d.x() + cy * d.y(), d.z()};
          float t_near = -kInf, t_far = kInf;
          int axis = -1;
          float sign = 1.0f;
          bool miss = false;
          for (int k = 0; k < 3 && !miss; ++k) {
            if (std::abs(ld[k]) < 1e-12f) {
              miss = lo_o[k] < lo_b[k] || lo_o[k] > hi_b[k];
              continue;
            }
            const float inv = 1.0f / ld[k];
            float t0 = (lo_b[k] - lo_o[k]) * inv, t1 = (hi_b[k] - lo_o[k]) * inv;
            float sg = -1.0f;
            if (t0 > t1) std::swap(t0, t1), sg = 1.0f;
            if (t0 > t_near) t_near = t0, axis = k, sign = sg;
            t_far = std::min(t_far, t1);
            miss = t_near > t_far;
          }
          if (miss || axis < 0 || t_near <= 1e-6f || t_near >= out->t[i]) continue;
          Vector3f n = Vector3f::Zero();
          if (axis == 2) {
            n.z() = sign;
          } else {
            const float lx = axis == 0 ? sign : 0.0f, ly = axis == 1 ? sign : 0.0f;
            n = Vector3f(cy * lx - sy * ly, sy * lx + cy * ly, 0.0f);
          }
          on_hit(i, d, t_near, n);
        }
      }
      return;
    }
    for (int v = box.y; v < box.y + box.height; ++v) {
      for (int u = box.x; u < box.x + box.width; ++u) {
        const size_t i = static_cast<size_t>(v) * w + u;
        const Vector3d d = (row_rays[v] + static_cast<float>(u) * ray_step).cast<double>();
        double t = 0.0;
        Vector3d n = Vector3d::Zero();
        if (Intersect(p, origin, d, &t, &n) && t < out->t[i]) {
          on_hit(i, d.cast<float>(), static_cast<float>(t), n.cast<float>());
        }
      }
    }
  };
  for (const Primitive& p : primitives) {
    const Vector3f albedo = p.albedo.cast<float>();
    const uint8_t black = Luminance(p.albedo) < options_.black_albedo ? 1 : 0;
    for_each_hit(p, [&](size_t i, const Vector3f& d, float t, const Vector3f& n) {
      out->t[i] = t;
      out->id[i] = static_cast<uint16_t>(p.id);
      Vector3f c = shade_f(albedo, n);
      if (p.glossy) {
        // Facing away from the half vector (n . h <= 0 before normalising), n . h / |h| is at
        // most a few 1e-7 and its 40th power is 0 in float: no highlight, as computed in full.
        const Vector3f h = to_light_f - d.normalized();
        if (n.dot(h) > 0.0f) {
          c += Vector3f::Constant(0.25f * PowInt(std::max(0.0f, n.dot(h.normalized())), 40));
        }
      }
      out->colour[i] = c;
      out->no_depth[i] = black;
    });
  }

  // 3. Semi-transparent objects, far to near, blended over what is behind them.
  std::sort(transparent.begin(), transparent.end(), [&](const Primitive& a, const Primitive& b) {
    return (a.center - origin).squaredNorm() > (b.center - origin).squaredNorm();
  });

  for (const Primitive& p : transparent) {
    const Vector3f tint = p.albedo.cast<float>();
    const float opacity = static_cast<float>(p.opacity);
    const Vector3f albedo = p.albedo.cast<float>();
    for_each_hit(p, [&](size_t i, const Vector3f& d, float t, const Vector3f& n) {
      const Vector3f view = -d.normalized();
      // Thin tinted plastic: the background shows through, filtered by the tint.
      const Vector3f behind = out->colour[i].cwiseProduct(Vector3f::Constant(0.35f) + 0.65f * tint);
      Vector3f c = opacity * shade_f(albedo, n) + (1.0f - opacity) * behind;
      // Reflections: the ceiling lights as bright low-saturation patches, stronger at
      // grazing angles (Fresnel), plus the light's specular highlight.
      const float n_dot_view = n.dot(view);
      const Vector3f reflected = 2.0f * n_dot_view * n - view;
      const float grazing = 1.0f - std::max(0.0f, n_dot_view);
      const float fresnel = 0.1f + 0.9f * (grazing * grazing) * (grazing * grazing);
      // Six ceiling light bands around the azimuth: sin(6 phi) from (x + iy)^6, no trig.
      float ceiling = std::clamp((reflected.z() - 0.45f) / 0.25f, 0.0f, 1.0f);
      if (ceiling > 0.0f) {
        const float r2 = reflected.x() * reflected.x() + reflected.y() * reflected.y();
        const std::complex<float> c1(reflected.x(), reflected.y());
        const std::complex<float> c2 = c1 * c1;
        ceiling *= 0.5f + 0.5f * (c2 * c2 * c2).imag() / (r2 * r2 * r2);
      }
      const float patch = std::min(1.0f, fresnel * 0.6f + 0.7f * ceiling);
      // As for glossy solids: n . h <= 0 before normalising means a highlight of exactly 0.
      const Vector3f h = view + to_light_f;
      const float spec =
          n.dot(h) > 0.0f ? 0.9f * PowInt(std::max(0.0f, n.dot(h.normalized())), 60) : 0.0f;
      c = (1.0f - patch) * c + patch * Vector3f::Constant(0.85f);
      c += Vector3f::Constant(spec);
      out->colour[i] = c;
      out->t[i] = t;
      out->id[i] = static_cast<uint16_t>(p.id);
      out->no_depth[i] = spec > options_.specular_dropout ? 1 : 0;
    });
  }
}

RgbdFrame SimRenderer::Render(const SimWorld& world, const Pose2D& robot, double t_s,
                              FrameTruth* truth) {
  const int w = camera_.width_px;
  const int h = camera_.height_px;
  const Eigen::Isometry3d world_from_camera = CameraPose(robot);
  Buffers& depth_pass = *depth_buffers_;
  if (options_.arena) {
    // A new hall for every frame, from the seed and the frame's index.
    arena_ = MakeArenaBackdrop(season_, options_.arena_options,
                               seed_ * 0x9E3779B97F4A7C15ULL + static_cast<uint64_t>(frame_index_));
  }
  const ArenaBackdrop* arena = options_.arena ? &arena_ : nullptr;
  RenderPass(world, world_from_camera, arena, &depth_pass);
  Buffers& colour_pass_storage = *colour_buffers_;
  const Buffers* colour_pass = &depth_pass;
  if (options_.colour_depth_baseline && camera_.colour_depth_baseline_m != 0.0) {
    Eigen::Isometry3d colour_pose = world_from_camera;
    colour_pose.translation() +=
        world_from_camera.linear() * Vector3d(camera_.colour_depth_baseline_m, 0, 0);
    RenderPass(world, colour_pose, arena, &colour_pass_storage);
    colour_pass = &colour_pass_storage;
  }

  RgbdFrame frame;
  frame.t_s = t_s;
  frame.index = frame_index_++;
  frame.colour.create(h, w, CV_8UC3);
  frame.depth_mm.create(h, w, CV_16UC1);
  // Noise comes from the pool, from a random offset each frame (contiguous: SIMD-friendly).
  const size_t n = static_cast<size_t>(w) * h;
  std::uniform_int_distribution<size_t> offset(0, normal_pool_.size() - 3 * n);
  const float* colour_noise = normal_pool_.data() + offset(rng_);
  const float* depth_noise = normal_pool_.data() + offset(rng_);

  // Colour: 255 * linear RGB + sigma * N(0, 1), to 8-bit BGR, with OpenCV's vector code.
  const cv::Mat colour_f(h, w, CV_32FC3, const_cast<Vector3f*>(colour_pass->colour.data()));
  cv::Mat scaled;
  if (options_.colour_noise) {
    const cv::Mat noise(h, w, CV_32FC3, const_cast<float*>(colour_noise));
    cv::scaleAdd(noise, options_.colour_noise_sigma / 255.0, colour_f, scaled);
  } else {
    scaled = colour_f;
  }
  cv::Mat rgb8;
  scaled.convertTo(rgb8, CV_8UC3, 255.0);
  cv::cvtColor(rgb8, frame.colour, cv::COLOR_RGB2BGR);

  // Depth: the camera's linear error, then sigma(d) noise, in whole millimetres.
  const float a = static_cast<float>(options_.depth_bias ? camera_.depth_correction.a : 1.0);
  const float b_mm = static_cast<float>(options_.depth_bias ? camera_.depth_correction.b_mm : 0.0);
  const float min_range = static_cast<float>(camera_.min_range_m);
  const float max_range = static_cast<float>(camera_.max_range_m);
  const size_t sigma_last = sigma_mm_by_mm_.size() - 1;
  uint16_t* depth_out = frame.depth_mm.ptr<uint16_t>(0);
  for (size_t i = 0; i < n; ++i) {
    const float z = depth_pass.t[i];
    uint16_t depth = 0;
    if (!depth_pass.no_depth[i] && z >= min_range && z <= max_range) {  // false for inf
      float measured_mm = a * z * 1000.0f + b_mm;
      if (options_.depth_noise) {
        measured_mm += sigma_mm_by_mm_[std::min(sigma_last, static_cast<size_t>(z * 1000.0f))] *
                       depth_noise[i];
      }
      depth = static_cast<uint16_t>(std::clamp(measured_mm + 0.5f, 0.0f, 65535.0f));
    }
    depth_out[i] = depth;
  }

  if (truth) {
    truth->robot = robot;
    truth->world_from_camera = world_from_camera;
    truth->objects.clear();
    truth->landmarks.clear();
    truth->ids = cv::Mat(h, w, CV_16UC1, const_cast<uint16_t*>(depth_pass.id.data())).clone();
    // Pixel counts and boxes per id: the extreme columns and rows of each id's pixels (the
    // same boxes as the union of one-pixel rectangles, without a rectangle union per pixel).
    struct Extent {
      int count = 0;
      int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
    };
    std::vector<Extent> extents(kLandmarkIdBase + season_.landmarks.size());
    for (int v = 0; v < h; ++v) {
      const uint16_t* row = depth_pass.id.data() + static_cast<size_t>(v) * w;
      for (int u = 0; u < w; ++u) {
        const uint16_t id = row[u];
        if (id == 0 || id >= extents.size()) continue;
        Extent& e = extents[id];
        if (e.count++ == 0) {
          e.u0 = e.u1 = u, e.v0 = e.v1 = v;
        } else {
          e.u0 = std::min(e.u0, u), e.u1 = std::max(e.u1, u), e.v1 = v;  // rows come in order
        }
      }
    }
    const auto box_of = [&](int id) {
      const Extent& e = extents[id];
      return cv::Rect(e.u0, e.v0, e.u1 - e.u0 + 1, e.v1 - e.v0 + 1);
    };
    const Eigen::Isometry3d camera_from_world = world_from_camera.inverse();
    for (const SimObject& object : world.objects) {
      if (object.id >= static_cast<int>(extents.size()) || extents[object.id].count == 0) continue;
      truth->objects.push_back({object.id, object.type->name, object.colour, object.center_m,
                                camera_from_world * object.center_m, extents[object.id].count,
                                box_of(object.id)});
    }
    for (size_t l = 0; l < season_.landmarks.size(); ++l) {
      const int id = kLandmarkIdBase + static_cast<int>(l);
      if (extents[id].count == 0) continue;
      const Vector3d& position = landmark_centres_[l];
      truth->landmarks.push_back({static_cast<int>(l), position, camera_from_world * position,
                                  extents[id].count, box_of(id)});
    }
  }
  return frame;
}

}  // namespace slamo::platform
