// Renders the simulated field as the robot's RGB-D camera sees it: ray casting against the
// floor tiles, perimeter walls, structures, landmarks and objects (solid and semi-transparent
// with highlights and low-saturation reflections), Lambert lighting from the world's
// Lighting, depth noise sigma(d) from the camera config, the camera's linear depth error, no
// depth out of range or on black / specular surfaces, and per-frame ground truth.
//
// The depth noise model: one Gaussian draw per pixel with sigma(d) interpolated linearly in
// the robot config's camera.noise table (thesis Table 3-7, Kinect V2), applied after the
// camera's linear error d_measured = a * d_true + b (the inverse of the thesis's correction).
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "platform/drive_base.h"
#include "platform/rgbd.h"
#include "platform/sim/sim_arena.h"
#include "platform/sim/sim_world.h"

namespace slamo::platform {

struct RenderOptions {
  bool depth_noise = true;  // Gaussian sigma(d) per pixel
  bool depth_bias = true;   // the camera's linear error a * d + b
  bool colour_noise = true;
  double colour_noise_sigma = 2.5;     // per channel, 8-bit levels
  bool colour_depth_baseline = false;  // render colour from the colour camera's own position
  double black_albedo = 0.08;          // luminance below which the camera reads no depth
  double specular_dropout = 0.55;      // highlight strength above which no depth (reflective)
  // Arena mode: beyond the perimeter a hall with a crowd, posters and lights drawn anew for
  // every frame from the seed (sim_arena.h), and opponent robots as dark chassis with bumpers
  // and a flag plate in their alliance's colour. Off: the clean field of the thesis.
  bool arena = false;
  ArenaOptions arena_options;
};

// Ids in FrameTruth::ids: 0 background / field, objects 1..N, landmarks kLandmarkIdBase + i,
// opponent robots kOpponentIdBase + i.
inline constexpr int kLandmarkIdBase = 10000;
inline constexpr int kOpponentIdBase = 20000;

struct ObjectTruth {
  int id = 0;
  std::string type;
  std::string colour;
  Eigen::Vector3d position_m;      // world frame, object centre
  Eigen::Vector3d position_cam_m;  // camera frame (x right, y down, z forward)
  int pixels = 0;                  // visible pixels in the depth camera's image
  cv::Rect box;                    // bounding box of those pixels
};

struct LandmarkTruth {
  int index = 0;               // into SeasonConfig::landmarks
  Eigen::Vector3d position_m;  // where it is drawn (see SimRenderer::landmark_centres)
  Eigen::Vector3d position_cam_m;
  int pixels = 0;
  cv::Rect box;
};

struct FrameTruth {
  Pose2D robot;
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
  std::vector<ObjectTruth> objects;      // those with at least one visible pixel
  std::vector<LandmarkTruth> landmarks;  // those with at least one visible pixel
  cv::Mat ids;                           // CV_16UC1 per pixel, see kLandmarkIdBase
};

class SimRenderer {
 public:
  SimRenderer(const field::SeasonConfig& season, const field::CameraConfig& camera,
              RenderOptions options, uint64_t seed);
  ~SimRenderer();

  // The depth camera's pose for a robot pose, OpenCV axes (x right, y down, z forward).
  Eigen::Isometry3d CameraPose(const Pose2D& robot) const;

  RgbdFrame Render(const SimWorld& world, const Pose2D& robot, double t_s, FrameTruth* truth);

  // sigma of one depth reading at `depth_m`, from the camera's noise table.
  double DepthSigmaM(double depth_m) const;

  // Where each season landmark is drawn (its centre): a disc or square marker sits on the
  // inner face of the nearest wall, whatever its configured offset behind it.
  const std::vector<Eigen::Vector3d>& landmark_centres() const { return landmark_centres_; }

  struct Primitive;  // internal geometry, public for the .cc's helpers

 private:
  struct Buffers;
  void RenderPass(const SimWorld& world, const Eigen::Isometry3d& world_from_camera,
                  const ArenaBackdrop* arena, Buffers* out) const;
  void BuildStaticPrimitives();
  void FillNormalPool();

  const field::SeasonConfig& season_;
  field::CameraConfig camera_;
  RenderOptions options_;
  uint64_t seed_;
  std::mt19937_64 rng_;
  std::vector<Eigen::Vector3f> rays_cam_;  // per pixel, z = 1
  std::vector<float> ray_length2_;         // per pixel, |ray|^2 (the same in every frame)
  // N(0, 1) draws, read from a random offset per frame; drawn at the first frame.
  std::vector<float> normal_pool_;
  std::vector<Primitive> static_primitives_;
  std::vector<Eigen::Vector3d> landmark_centres_;
  std::vector<float> sigma_mm_by_mm_;        // sigma(d) in mm, indexed by depth in whole mm
  std::unique_ptr<Buffers> depth_buffers_;   // reused every frame
  std::unique_ptr<Buffers> colour_buffers_;  // with the colour-depth baseline only
  int64_t frame_index_ = 0;
  ArenaBackdrop arena_;  // arena mode: this frame's
};

}  // namespace slamo::platform
