#include "platform/sim/sim_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include <opencv2/imgproc.hpp>

#include "field_configs/loader.h"
#include "platform/sim/sim_world.h"

namespace slamo::platform {
namespace {

class SimRendererTest : public ::testing::Test {
 protected:
  SimRendererTest()
      : season_(field::LoadSeasonConfig("toss_up")),
        robot_(field::LoadRobotConfig("thesis_robot")) {}

  // A world with only the given objects (the structures and landmarks stay).
  SimWorld WorldWith(std::vector<SimObject> objects) {
    SimWorld world = CreateWorld(season_, 1);
    world.objects = std::move(objects);
    return world;
  }

  SimObject Ball(int id, const std::string& type, const std::string& colour, double x, double y) {
    SimObject o;
    o.id = id;
    o.type = season_.FindObjectType(type);
    o.colour = colour;
    o.center_m = Eigen::Vector3d(x, y, o.type->size_m / 2.0);
    return o;
  }

  static RenderOptions Clean() {
    RenderOptions o;
    o.depth_noise = o.depth_bias = o.colour_noise = false;
    return o;
  }

  field::SeasonConfig season_;
  field::RobotConfig robot_;
  const Pose2D pose_{-1.5, 0.3, 0.0};
};

// The ball's centre projects where the pinhole model says, and the depth at that pixel is
// the sphere's front surface along the ray.
TEST_F(SimRendererTest, BallLandsAtTheExpectedPixelAndDepth) {
  SimRenderer renderer(season_, robot_.camera, Clean(), 7);
  const SimWorld world = WorldWith({Ball(1, "buckyball", "red", -0.4, 0.45)});
  FrameTruth truth;
  const RgbdFrame frame = renderer.Render(world, pose_, 0.0, &truth);
  ASSERT_EQ(truth.objects.size(), 1u);
  const Eigen::Vector3d c = truth.objects[0].position_cam_m;
  const double u = robot_.camera.fx * c.x() / c.z() + robot_.camera.cx;
  const double v = robot_.camera.fy * c.y() / c.z() + robot_.camera.cy;
  const cv::Rect box = truth.objects[0].box;
  EXPECT_NEAR(box.x + box.width / 2.0, u, 1.5);
  EXPECT_NEAR(box.y + box.height / 2.0, v, 1.5);
  // Apparent radius: r * f / Z within a pixel or two.
  EXPECT_NEAR(box.width / 2.0, 0.0635 * robot_.camera.fx / c.z(), 2.0);

  // Depth at the centre pixel: intersect the pixel's ray with the sphere.
  const int iu = static_cast<int>(u), iv = static_cast<int>(v);
  const Eigen::Vector3d ray((iu + 0.5 - robot_.camera.cx) / robot_.camera.fx,
                            (iv + 0.5 - robot_.camera.cy) / robot_.camera.fy, 1.0);
  const double b = -ray.dot(c), cc = c.squaredNorm() - 0.0635 * 0.0635, a = ray.squaredNorm();
  const double t = (-b - std::sqrt(b * b - a * cc)) / a;  // Z of the front surface (ray z = 1)
  EXPECT_NEAR(frame.depth_mm.at<uint16_t>(iv, iu), t * 1000.0, 1.0);
  EXPECT_EQ(truth.ids.at<uint16_t>(iv, iu), 1);
}

// With noise and bias on, the same pixel reads a * d + b within 4 sigma(d).
TEST_F(SimRendererTest, NoisyDepthStaysWithinTheNoiseModel) {
  SimRenderer clean(season_, robot_.camera, Clean(), 7);
  SimRenderer noisy(season_, robot_.camera, RenderOptions{}, 7);
  const SimWorld world = WorldWith({Ball(1, "buckyball", "red", -0.4, 0.45)});
  const RgbdFrame truth_frame = clean.Render(world, pose_, 0.0, nullptr);
  const RgbdFrame frame = noisy.Render(world, pose_, 0.0, nullptr);
  const double a = robot_.camera.depth_correction.a, b = robot_.camera.depth_correction.b_mm;
  int checked = 0;
  for (int v = 0; v < frame.depth_mm.rows; v += 7) {
    for (int u = 0; u < frame.depth_mm.cols; u += 7) {
      const double d_mm = truth_frame.depth_mm.at<uint16_t>(v, u);
      if (d_mm == 0) continue;
      const double sigma_mm = 1000.0 * noisy.DepthSigmaM(d_mm / 1000.0);
      ASSERT_NEAR(frame.depth_mm.at<uint16_t>(v, u), a * d_mm + b, 4.0 * sigma_mm + 1.0)
          << u << "," << v;
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

// Per distance band, the spread of (measured - (a d + b)) matches sigma(d) of the table and
// the mean is unbiased.
TEST_F(SimRendererTest, DepthNoiseStatisticsByDistance) {
  SimRenderer clean(season_, robot_.camera, Clean(), 3);
  SimRenderer noisy(season_, robot_.camera, RenderOptions{}, 3);
  const SimWorld world = WorldWith({});
  const double a = robot_.camera.depth_correction.a, b = robot_.camera.depth_correction.b_mm;
  struct Band {
    double sum = 0, sum2 = 0, sigma_sum = 0;
    int n = 0;
  };
  std::map<int, Band> bands;  // by half-metre of true depth
  for (const Pose2D& pose :
       {Pose2D{-1.5, 0.3, 0.0}, Pose2D{-1.0, -0.5, 0.6}, Pose2D{1.2, 1.2, -2.4}}) {
    const RgbdFrame truth_frame = clean.Render(world, pose, 0.0, nullptr);
    for (int k = 0; k < 3; ++k) {
      const RgbdFrame frame = noisy.Render(world, pose, 0.0, nullptr);
      for (int v = 0; v < frame.depth_mm.rows; v += 2) {
        for (int u = 0; u < frame.depth_mm.cols; u += 2) {
          const double d_mm = truth_frame.depth_mm.at<uint16_t>(v, u);
          if (d_mm == 0 || frame.depth_mm.at<uint16_t>(v, u) == 0) continue;
          const double e = frame.depth_mm.at<uint16_t>(v, u) - (a * d_mm + b);
          Band& band = bands[static_cast<int>(d_mm / 500.0)];
          band.sum += e, band.sum2 += e * e,
              band.sigma_sum += 1000.0 * noisy.DepthSigmaM(d_mm / 1000.0), ++band.n;
        }
      }
    }
  }
  int bands_checked = 0;
  for (const auto& [index, band] : bands) {
    if (band.n < 2000) continue;
    const double mean = band.sum / band.n;
    const double sd = std::sqrt(band.sum2 / band.n - mean * mean);
    const double expected = band.sigma_sum / band.n;
    // Rounding to whole millimetres adds 1/12 mm^2 of variance.
    const double expected_sd = std::sqrt(expected * expected + 1.0 / 12.0);
    SCOPED_TRACE("band " + std::to_string(index * 0.5) + " m, n " + std::to_string(band.n));
    EXPECT_NEAR(mean, 0.0, 0.15);
    EXPECT_NEAR(sd, expected_sd, 0.1 * expected_sd);
    ++bands_checked;
  }
  EXPECT_GE(bands_checked, 4);
}

TEST_F(SimRendererTest, SameSeedSameFramesOtherSeedOtherNoise) {
  const SimWorld world = CreateWorld(season_, 5);
  SimRenderer a(season_, robot_.camera, RenderOptions{}, 5);
  SimRenderer b(season_, robot_.camera, RenderOptions{}, 5);
  SimRenderer c(season_, robot_.camera, RenderOptions{}, 6);
  for (int k = 0; k < 3; ++k) {
    const RgbdFrame fa = a.Render(world, pose_, 0.1 * k, nullptr);
    const RgbdFrame fb = b.Render(world, pose_, 0.1 * k, nullptr);
    const RgbdFrame fc = c.Render(world, pose_, 0.1 * k, nullptr);
    EXPECT_EQ(cv::norm(fa.colour, fb.colour, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(fa.depth_mm, fb.depth_mm, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(fa.depth_mm, fc.depth_mm, cv::NORM_L1), 0.0);
  }
  // The same seed also places region objects the same way.
  const SimWorld again = CreateWorld(season_, 5);
  ASSERT_EQ(again.objects.size(), world.objects.size());
  for (size_t i = 0; i < world.objects.size(); ++i)
    EXPECT_EQ(again.objects[i].center_m, world.objects[i].center_m);
}

TEST_F(SimRendererTest, NoDepthOutOfRangeOrOnBlack) {
  SimRenderer renderer(season_, robot_.camera, Clean(), 2);
  // A ball 0.4 m from the camera is inside the minimum range (0.5 m): no depth on it.
  SimObject near_ball = Ball(1, "buckyball", "blue", -1.0, 0.3);
  near_ball.center_m.z() = 0.3;  // raised into view, 0.4 m ahead of the camera
  const SimWorld near_world = WorldWith({near_ball});
  FrameTruth truth;
  RgbdFrame frame = renderer.Render(near_world, pose_, 0.0, &truth);
  int near_pixels = 0;
  for (int v = 0; v < frame.depth_mm.rows; ++v) {
    for (int u = 0; u < frame.depth_mm.cols; ++u) {
      if (truth.ids.at<uint16_t>(v, u) != 1) continue;
      ++near_pixels;
      EXPECT_EQ(frame.depth_mm.at<uint16_t>(v, u), 0);
    }
  }
  EXPECT_GT(near_pixels, 100);
  // Every reading lies within the camera's range.
  for (int v = 0; v < frame.depth_mm.rows; ++v) {
    for (int u = 0; u < frame.depth_mm.cols; ++u) {
      const uint16_t d = frame.depth_mm.at<uint16_t>(v, u);
      if (d == 0) continue;
      EXPECT_GE(d, 1000 * robot_.camera.min_range_m - 1);
      EXPECT_LE(d, 1000 * robot_.camera.max_range_m + 1);
    }
  }
  // A black ball reads no depth.
  field::SeasonConfig dark = season_;
  dark.colours["red"] = field::Rgb{10, 10, 10};
  SimRenderer dark_renderer(dark, robot_.camera, Clean(), 2);
  SimWorld dark_world = CreateWorld(dark, 1);
  SimObject ball = Ball(1, "buckyball", "red", -0.4, 0.45);
  ball.type = dark.FindObjectType("buckyball");
  dark_world.objects = {ball};
  frame = dark_renderer.Render(dark_world, pose_, 0.0, &truth);
  ASSERT_EQ(truth.objects.size(), 1u);
  const cv::Rect box = truth.objects[0].box;
  EXPECT_GT(cv::countNonZero(truth.ids(box) == 1), 100);
  EXPECT_EQ(cv::countNonZero((frame.depth_mm(box) != 0) & (truth.ids(box) == 1)), 0);
}

// The semi-transparent ball shows the background through it and low-saturation patches:
// a hue threshold tuned on the solid ball misses much of it.
TEST_F(SimRendererTest, SemiTransparentBallDefeatsAHueThreshold) {
  SimRenderer renderer(season_, robot_.camera, RenderOptions{}, 4);
  const SimWorld world =
      WorldWith({Ball(1, "buckyball", "blue", -0.5, 0.0), Ball(2, "large_ball", "blue", 0.0, 0.6)});
  FrameTruth truth;
  const RgbdFrame frame = renderer.Render(world, Pose2D{-1.5, 0.3, -0.1}, 0.0, &truth);
  ASSERT_EQ(truth.objects.size(), 2u);
  cv::Mat hsv;
  cv::cvtColor(frame.colour, hsv, cv::COLOR_BGR2HSV);
  const auto fraction_blue = [&](int id) {
    int in = 0, total = 0;
    for (int v = 0; v < hsv.rows; ++v) {
      for (int u = 0; u < hsv.cols; ++u) {
        if (truth.ids.at<uint16_t>(v, u) != id) continue;
        const cv::Vec3b p = hsv.at<cv::Vec3b>(v, u);
        ++total;
        in += (p[0] >= 100 && p[0] <= 130 && p[1] >= 120 && p[2] >= 40);
      }
    }
    return static_cast<double>(in) / std::max(total, 1);
  };
  EXPECT_GT(fraction_blue(1), 0.9);  // solid: the threshold finds nearly all of it
  EXPECT_LT(fraction_blue(2), 0.7);  // semi-transparent: much of the body is missed
}

}  // namespace
}  // namespace slamo::platform

namespace slamo::platform {
namespace {

// Stars render as five-pointed prisms: seen from the robot they cover clearly less than the
// cylinder around them, and far more than nothing.
TEST(SimRendererShapesTest, StarIsAStarPrismNotADisc) {
  field::SeasonConfig season = field::LoadSeasonConfig("starstruck");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  season.objects.clear();
  field::ObjectType disc = *season.FindObjectType("star");
  disc.name = "disc";
  disc.shape = field::ObjectShape::kCylinder;
  season.object_types.push_back(disc);
  const auto pixels_of = [&](const char* type) {
    SimWorld world = CreateWorld(season, 1);
    SimObject o;
    o.id = 1;
    o.type = season.FindObjectType(type);
    o.colour = o.type->colours.front();
    o.center_m = Eigen::Vector3d(-0.4, 0.0, o.type->height_m / 2.0);
    world.objects = {o};
    SimRenderer renderer(season, robot.camera, RenderOptions{}, 1);
    FrameTruth truth;
    renderer.Render(world, Pose2D{-1.5, 0.0, 0.0}, 0.0, &truth);
    return truth.objects.empty() ? 0 : truth.objects[0].pixels;
  };
  const int star = pixels_of("star");
  const int cylinder = pixels_of("disc");
  EXPECT_GT(star, 200);
  EXPECT_LT(star, 0.8 * cylinder);
  EXPECT_GT(star, 0.3 * cylinder);
}

}  // namespace
}  // namespace slamo::platform

namespace slamo::platform {
namespace {

// A camera at the Kinect V2 colour resolution renders too (the noise pool grows with it).
TEST(SimRendererSizesTest, RendersAt1920x1080) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  field::CameraConfig camera = field::LoadRobotConfig("thesis_robot").camera;
  const double sx = 1920.0 / camera.width_px, sy = 1080.0 / camera.height_px;
  camera.width_px = 1920, camera.height_px = 1080;
  camera.fx *= sx, camera.cx *= sx, camera.fy *= sy, camera.cy *= sy;
  SimRenderer renderer(season, camera, RenderOptions{}, 1);
  const RgbdFrame frame =
      renderer.Render(CreateWorld(season, 1), Pose2D{-1.2, -0.5, 0.5}, 0.0, nullptr);
  EXPECT_EQ(frame.colour.cols, 1920);
  EXPECT_EQ(frame.depth_mm.rows, 1080);
  EXPECT_GT(cv::countNonZero(frame.depth_mm), 1920 * 1080 / 4);
}

// Arena mode: the same seed draws the same hall, another seed (or the next frame) another;
// everything on the field side of the perimeter is exactly the clean render, and the hall
// beyond it has colour where the clean venue is dim grey, and depth where it is in range.
TEST_F(SimRendererTest, ArenaIsSeededPerFrameAndOnlyChangesWhatLiesBeyondThePerimeter) {
  const SimWorld world = WorldWith({Ball(1, "buckyball", "red", -0.6, 0.35)});
  RenderOptions arena_options = Clean();
  arena_options.arena = true;
  SimRenderer clean(season_, robot_.camera, Clean(), 5);
  SimRenderer a(season_, robot_.camera, arena_options, 5);
  SimRenderer b(season_, robot_.camera, arena_options, 5);
  SimRenderer c(season_, robot_.camera, arena_options, 6);
  const Pose2D pose{0.8, 0.2, 0.3};  // near the +x wall: the hall in range of the depth camera
  FrameTruth truth;
  const RgbdFrame fclean = clean.Render(world, pose, 0.0, &truth);
  const RgbdFrame fa = a.Render(world, pose, 0.0, nullptr);
  const RgbdFrame fb = b.Render(world, pose, 0.0, nullptr);
  const RgbdFrame fc = c.Render(world, pose, 0.0, nullptr);
  const RgbdFrame fa_next = a.Render(world, pose, 0.1, nullptr);
  EXPECT_EQ(cv::norm(fa.colour, fb.colour, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(fa.depth_mm, fb.depth_mm, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(fa.colour, fc.colour, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(fa.colour, fa_next.colour, cv::NORM_L1), 0.0);

  int field_side = 0, field_side_same = 0, beyond = 0, beyond_changed = 0, beyond_depth = 0;
  for (int v = 0; v < fclean.colour.rows; ++v) {
    for (int u = 0; u < fclean.colour.cols; ++u) {
      const bool same = fclean.colour.at<cv::Vec3b>(v, u) == fa.colour.at<cv::Vec3b>(v, u) &&
                        fclean.depth_mm.at<uint16_t>(v, u) == fa.depth_mm.at<uint16_t>(v, u);
      if (truth.ids.at<uint16_t>(v, u) != 0 || fclean.depth_mm.at<uint16_t>(v, u) != 0) {
        ++field_side;  // floor, walls, markers, the ball: all in range here
        field_side_same += same;
      } else {
        ++beyond;
        beyond_changed += !same;
        beyond_depth += fa.depth_mm.at<uint16_t>(v, u) != 0;
      }
    }
  }
  EXPECT_GT(field_side, 20000);
  EXPECT_EQ(field_side_same, field_side);
  EXPECT_GT(beyond, 20000);
  EXPECT_GT(beyond_changed, beyond * 9 / 10);
  EXPECT_GT(beyond_depth, 1000);
}

// Arena mode draws an opponent as a dark chassis with bumpers and a flag in its alliance's
// colour; the clean mode as one dim box in that colour.
TEST_F(SimRendererTest, ArenaOpponentHasAllianceColouredBumpersOnADarkChassis) {
  SimWorld world = WorldWith({});
  SimOpponent opponent;
  opponent.config.alliance = field::Alliance::kRed;
  opponent.config.size_m = {0.45, 0.45};
  opponent.pose = Pose2D{0.2, 0.3, 0.5};
  world.opponents = {opponent};
  RenderOptions arena_options = Clean();
  arena_options.arena = true;
  for (const bool arena : {false, true}) {
    SimRenderer renderer(season_, robot_.camera, arena ? arena_options : Clean(), 3);
    FrameTruth truth;
    const RgbdFrame frame = renderer.Render(world, pose_, 0.0, &truth);
    int pixels = 0, red = 0, dark_grey = 0;
    for (int v = 0; v < frame.colour.rows; ++v) {
      for (int u = 0; u < frame.colour.cols; ++u) {
        if (truth.ids.at<uint16_t>(v, u) != kOpponentIdBase) continue;
        const cv::Vec3b bgr = frame.colour.at<cv::Vec3b>(v, u);
        ++pixels;
        red += bgr[2] > 2 * bgr[1] && bgr[2] > 2 * bgr[0];
        dark_grey += std::abs(bgr[2] - bgr[0]) < 20 && bgr[2] < 100;
      }
    }
    SCOPED_TRACE(arena ? "arena" : "clean");
    EXPECT_GT(pixels, 2000);
    EXPECT_GT(red, arena ? 300 : pixels * 9 / 10);
    EXPECT_EQ(dark_grey > pixels / 3, arena);
  }
}

}  // namespace
}  // namespace slamo::platform
