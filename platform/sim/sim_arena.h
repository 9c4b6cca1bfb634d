// The arena beyond the perimeter, for the renderer's arena mode: a square hall around the
// field whose walls carry a crowd (clothing in the alliance colours among others), posters
// and banners with round logos, and bright lights near the ceiling, drawn anew from a seed
// for every frame; between the perimeter and the stands, the hall's floor. The renderer asks
// it what a ray leaving the field sees. Clean mode never builds one.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "field_configs/season_config.h"

namespace slamo::platform {

struct ArenaOptions {
  double stands_gap_m = 1.5;     // from the perimeter's inner face to the stands' wall
  double stands_height_m = 5.0;  // the wall's height; the ceiling above it is dark
  double texel_m = 0.015;        // texture resolution on the stands' wall
};

// One frame's arena: the stands' four walls unrolled into one texture (linear RGB, 8-bit),
// side after side (+x, -x, +y, -y), each 2 * half_m wide, top row at height_m.
struct ArenaBackdrop {
  double half_m = 0.0;    // the stands' walls at x, y = +-half_m
  double height_m = 0.0;  // texture top
  double texel_m = 0.0;
  cv::Mat texture;  // CV_8UC3, RGB
  cv::Mat bright;   // CV_8UC1, non-zero where a lamp shines (no depth reading there)
};

ArenaBackdrop MakeArenaBackdrop(const field::SeasonConfig& season, const ArenaOptions& options,
                                uint64_t seed);

// What the ray origin + t * direction (t: depth along the camera's axis) sees beyond the
// perimeter: the hall's floor, the stands or the ceiling. Sets the linear RGB colour, t (inf
// for the ceiling) and whether the camera reads no depth there.
void ShadeArena(const ArenaBackdrop& arena, const Eigen::Vector3f& origin,
                const Eigen::Vector3f& direction, Eigen::Vector3f* colour, float* t,
                uint8_t* no_depth);

}  // namespace slamo::platform
