#include "platform/sim/sim_arena.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <opencv2/imgproc.hpp>

namespace slamo::platform {
namespace {

cv::Scalar Rgb8(const field::SeasonConfig& season, const std::string& name,
                const cv::Scalar& fallback) {
  const auto it = season.colours.find(name);
  if (it == season.colours.end()) return fallback;
  return cv::Scalar(it->second.r, it->second.g, it->second.b);
}

}  // namespace

ArenaBackdrop MakeArenaBackdrop(const field::SeasonConfig& season, const ArenaOptions& options,
                                uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };

  ArenaBackdrop arena;
  arena.half_m = season.HalfSize() + options.stands_gap_m;
  arena.height_m = options.stands_height_m;
  arena.texel_m = options.texel_m;
  const double texel = options.texel_m;
  const int width = static_cast<int>(std::ceil(8.0 * arena.half_m / texel));
  const int height = static_cast<int>(std::ceil(arena.height_m / texel));
  // Texture coordinates of a point (s along the unrolled walls, z up), in texels.
  const auto at = [&](double s_m, double z_m) {
    return cv::Point(static_cast<int>(s_m / texel),
                     static_cast<int>((arena.height_m - z_m) / texel));
  };
  const auto size = [&](double a_m, double b_m) {
    return cv::Size(std::max(1, static_cast<int>(a_m / texel)),
                    std::max(1, static_cast<int>(b_m / texel)));
  };
  const double length_m = width * texel;

  // The alliance colours exactly as the season paints its objects: the hardest clothing.
  const cv::Scalar red = Rgb8(season, "red", cv::Scalar(200, 30, 30));
  const cv::Scalar blue = Rgb8(season, "blue", cv::Scalar(30, 60, 200));
  const cv::Scalar others[] = {{20, 20, 24},    {235, 235, 235}, {90, 90, 95},  {30, 120, 40},
                               {230, 200, 30},  {120, 60, 30},   {60, 30, 110}, {240, 120, 20},
                               {200, 200, 160}, {10, 40, 90}};
  const cv::Scalar skins[] = {{230, 190, 160}, {200, 150, 110}, {150, 100, 70}, {90, 60, 40}};
  const auto clothing = [&]() {
    const double r = unit(rng);
    if (r < 0.25) return red;
    if (r < 0.5) return blue;
    return others[static_cast<size_t>(unit(rng) * std::size(others)) % std::size(others)];
  };
  const auto jitter = [&](const cv::Scalar& c, double amount) {
    cv::Scalar out;
    for (int k = 0; k < 3; ++k) out[k] = std::clamp(c[k] * uniform(1.0 - amount, 1.0), 0.0, 255.0);
    return out;
  };

  arena.texture = cv::Mat(height, width, CV_8UC3, cv::Scalar(28, 30, 40));
  arena.bright = cv::Mat(height, width, CV_8UC1, cv::Scalar(0));
  cv::Mat& tex = arena.texture;

  // Stands: tiers of seats, a person in most, some holding a foam finger or a balloon.
  for (double z = 1.2; z < arena.height_m - 1.2; z += 0.5) {
    cv::rectangle(tex, at(0.0, z), at(length_m, z - 0.06), cv::Scalar(45, 45, 55), cv::FILLED);
    for (double s = uniform(0.0, 0.4); s < length_m; s += uniform(0.42, 0.6)) {
      if (unit(rng) < 0.2) continue;  // an empty seat
      const double x = s + uniform(-0.05, 0.05);
      const double lean = uniform(-0.05, 0.05);
      cv::ellipse(tex, at(x, z + 0.28), size(uniform(0.16, 0.22), uniform(0.24, 0.3)), 0, 0, 360,
                  jitter(clothing(), 0.25), cv::FILLED, cv::LINE_AA);
      cv::circle(tex, at(x + lean, z + 0.62), static_cast<int>(uniform(0.08, 0.11) / texel),
                 jitter(skins[static_cast<size_t>(unit(rng) * 4) % 4], 0.15), cv::FILLED,
                 cv::LINE_AA);
      if (unit(rng) < 0.08) {
        const double r = uniform(0.08, 0.2);
        cv::circle(tex, at(x + uniform(-0.3, 0.3), z + uniform(0.8, 1.1)),
                   static_cast<int>(r / texel), unit(rng) < 0.5 ? red : blue, cv::FILLED,
                   cv::LINE_AA);
      }
    }
  }
  // Banners and posters along the barrier in front of the stands, with round logos.
  for (double s = uniform(0.0, 0.5); s < length_m;) {
    const double w = uniform(0.8, 2.5), h = uniform(0.5, 1.1), z0 = uniform(0.0, 0.2);
    const double pick = unit(rng);
    const cv::Scalar ground =
        pick < 0.3 ? red
        : pick < 0.6
            ? blue
            : others[static_cast<size_t>(unit(rng) * std::size(others)) % std::size(others)];
    cv::rectangle(tex, at(s, z0 + h), at(s + w, z0), jitter(ground, 0.1), cv::FILLED);
    const int logos = static_cast<int>(uniform(0.0, 3.0));
    for (int k = 0; k < logos; ++k) {
      const double r = uniform(0.06, std::min(0.35, h / 2.0));
      cv::circle(tex, at(s + uniform(r, w - r), z0 + uniform(r, h - r)),
                 static_cast<int>(r / texel), unit(rng) < 0.5 ? red : blue, cv::FILLED,
                 cv::LINE_AA);
    }
    for (int k = 0; k < 6; ++k) {  // lettering
      const double x = s + uniform(0.05, w - 0.3), y = z0 + uniform(0.05, h - 0.12);
      cv::rectangle(tex, at(x, y + uniform(0.04, 0.1)), at(x + uniform(0.1, 0.3), y),
                    unit(rng) < 0.5 ? cv::Scalar(250, 250, 250) : cv::Scalar(15, 15, 15),
                    cv::FILLED);
    }
    s += w + uniform(0.0, 0.6);
  }
  // Lights near the ceiling: a bright core (too bright for a depth reading) in a halo.
  for (double s = uniform(0.0, 2.0); s < length_m; s += uniform(1.5, 3.0)) {
    const cv::Point c = at(s, uniform(arena.height_m - 0.8, arena.height_m - 0.3));
    const int r = static_cast<int>(uniform(0.12, 0.3) / texel);
    cv::circle(tex, c, 2 * r, cv::Scalar(150, 145, 130), cv::FILLED, cv::LINE_AA);
    cv::circle(tex, c, r, cv::Scalar(255, 252, 240), cv::FILLED, cv::LINE_AA);
    cv::circle(arena.bright, c, r, cv::Scalar(255), cv::FILLED);
  }
  return arena;
}

void ShadeArena(const ArenaBackdrop& arena, const Eigen::Vector3f& origin,
                const Eigen::Vector3f& direction, Eigen::Vector3f* colour, float* t,
                uint8_t* no_depth) {
  const float half = static_cast<float>(arena.half_m);
  const Eigen::Vector3f& o = origin;
  const Eigen::Vector3f& d = direction;
  // The stands' wall the ray meets: sides +x, -x, +y, -y.
  float t_wall = std::numeric_limits<float>::infinity();
  int side = 0;
  if (d.x() > 1e-9f) t_wall = (half - o.x()) / d.x(), side = 0;
  if (d.x() < -1e-9f) t_wall = (-half - o.x()) / d.x(), side = 1;
  if (d.y() > 1e-9f && (half - o.y()) / d.y() < t_wall) t_wall = (half - o.y()) / d.y(), side = 2;
  if (d.y() < -1e-9f && (-half - o.y()) / d.y() < t_wall) {
    t_wall = (-half - o.y()) / d.y(), side = 3;
  }
  const float z = o.z() + t_wall * d.z();
  if (z < 0.0f && d.z() < 0.0f) {
    // The hall's floor between the perimeter and the stands.
    *t = -o.z() / d.z();
    const Eigen::Vector3f p = o + *t * d;
    const float stripe = (static_cast<int>(std::floor(p.x() + p.y())) & 1) ? 0.02f : 0.0f;
    *colour = Eigen::Vector3f(0.16f + stripe, 0.16f + stripe, 0.19f + stripe);
    *no_depth = 0;
    return;
  }
  if (!(z <= arena.height_m)) {
    // The ceiling: dark, too far for a reading.
    *colour = Eigen::Vector3f(0.05f, 0.05f, 0.06f);
    *t = std::numeric_limits<float>::infinity();
    *no_depth = 1;
    return;
  }
  const Eigen::Vector3f p = o + t_wall * d;
  const float along = side < 2 ? (side == 0 ? p.y() + half : half - p.y())
                               : (side == 2 ? half - p.x() : p.x() + half);
  const float texel = static_cast<float>(arena.texel_m);
  const int u =
      std::clamp(static_cast<int>((side * 2.0f * half + along) / texel), 0, arena.texture.cols - 1);
  const int v = std::clamp(static_cast<int>((static_cast<float>(arena.height_m) - z) / texel), 0,
                           arena.texture.rows - 1);
  const cv::Vec3b& c = arena.texture.at<cv::Vec3b>(v, u);
  *colour = Eigen::Vector3f(c[0], c[1], c[2]) / 255.0f;
  *t = t_wall;
  *no_depth = arena.bright.at<uint8_t>(v, u) ? 1 : 0;
}

}  // namespace slamo::platform
