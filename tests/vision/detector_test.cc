#include "vision/detector.h"

#include <algorithm>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "field_configs/loader.h"
#include "platform/sim/sim_renderer.h"
#include "platform/sim/sim_world.h"

namespace slamo::vision {
namespace {

using platform::Pose2D;
using platform::SimObject;

// Renders Toss Up with only the objects a test places, and detects on the frame. The stash
// goals are left out of the ball tests: seen from the middle zone with the barrier's pipe
// across it, the red stash's top half passes for a red ball (a known detector weakness, see
// SameColouredStructureIsRejected), which is not what these tests are about.
class DetectorTest : public ::testing::Test {
 protected:
  DetectorTest()
      : season_(WithoutGoals(field::LoadSeasonConfig("toss_up"))),
        robot_(field::LoadRobotConfig("thesis_robot")),
        setup_(ObjectDetectorSetup(season_, &robot_.camera)) {}

  static field::SeasonConfig WithoutGoals(field::SeasonConfig season) {
    auto& s = season.structures;
    s.erase(std::remove_if(s.begin(), s.end(),
                           [](const field::Structure& st) {
                             return st.name == "red_goal" || st.name == "blue_goal";
                           }),
            s.end());
    return season;
  }

  SimObject Ball(const std::string& type, const std::string& colour, double x, double y) {
    SimObject o;
    o.id = static_cast<int>(objects_.size()) + 1;
    o.type = season_.FindObjectType(type);
    o.colour = colour;
    o.center_m = Eigen::Vector3d(x, y, o.type->size_m / 2.0);
    objects_.push_back(o);
    return o;
  }

  platform::RgbdFrame Render(const Pose2D& pose, platform::FrameTruth* truth = nullptr) {
    platform::SimWorld world = platform::CreateWorld(season_, 3);
    world.objects = objects_;
    platform::SimRenderer renderer(season_, robot_.camera, platform::RenderOptions{}, 3);
    return renderer.Render(world, pose, 0.0, truth);
  }

  std::vector<Detection> DetectColour(const platform::RgbdFrame& frame, const std::string& colour,
                                      const DetectOptions& options = {}) {
    std::vector<Detection> out;
    for (Detection& d : Detect(frame.colour, frame.depth_mm, setup_, options)) {
      if (d.colour == colour) out.push_back(std::move(d));
    }
    return out;
  }

  // Truth range and bearing of an object from a robot pose.
  static Eigen::Vector2d TruthRangeBearing(const SimObject& o, const Pose2D& pose) {
    const double dx = o.center_m.x() - pose.x_m, dy = o.center_m.y() - pose.y_m;
    return Eigen::Vector2d(std::hypot(dx, dy),
                           platform::WrapAngleRad(std::atan2(dy, dx) - pose.theta_rad));
  }

  field::SeasonConfig season_;
  field::RobotConfig robot_;
  DetectorSetup setup_;
  std::vector<SimObject> objects_;
  const Pose2D pose_{-1.5, 0.0, 0.0};
};

TEST_F(DetectorTest, SolidBallFoundWithRangeAndBearing) {
  const SimObject ball = Ball("buckyball", "red", -0.4, 0.2);
  const platform::RgbdFrame frame = Render(pose_);
  const std::vector<Detection> found = DetectColour(frame, "red");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].kind, "buckyball");
  ASSERT_TRUE(found[0].measurement.has_value());
  const Eigen::Vector2d truth = TruthRangeBearing(ball, pose_);
  EXPECT_NEAR(found[0].measurement->range_m, truth.x(), 0.02);
  EXPECT_NEAR(found[0].measurement->bearing_rad, truth.y(), 0.01);
  // The covariance is a covariance.
  const Eigen::Matrix2d& c = found[0].measurement->covariance;
  EXPECT_GT(c(0, 0), 0.0);
  EXPECT_GT(c(1, 1), 0.0);
  EXPECT_GT(c.determinant(), 0.0);
}

// The thesis's erosion erased every ball beyond 2 m; size-aware cleaning keeps them.
TEST_F(DetectorTest, FarBallAtThreeMetresIsFound) {
  // From a corner across the near half (the barrier would hide the far half's floor).
  const SimObject ball = Ball("buckyball", "blue", 0.3, 0.9);
  const Pose2D corner{-1.5, -1.5, std::atan2(2.4, 1.8)};
  ASSERT_NEAR(TruthRangeBearing(ball, corner).x(), 3.0, 0.01);
  const platform::RgbdFrame frame = Render(corner);
  const std::vector<Detection> found = DetectColour(frame, "blue");
  ASSERT_EQ(found.size(), 1u);
  ASSERT_TRUE(found[0].measurement.has_value());
  EXPECT_NEAR(found[0].measurement->range_m, TruthRangeBearing(ball, corner).x(), 0.05);
}

TEST_F(DetectorTest, SemiTransparentBallKMeansCoversMoreThanThreshold) {
  // On the whole field: the red stash stands behind the ball and shows through it.
  season_ = field::LoadSeasonConfig("toss_up");
  Ball("large_ball", "blue", -0.2, 0.3);
  platform::FrameTruth truth;
  const platform::RgbdFrame frame = Render(pose_, &truth);
  const cv::Mat body = truth.ids == 1;
  const auto coverage = [&](DetectMethod method) {
    DetectOptions options;
    options.method = method;
    const std::vector<cv::Mat> masks = ColourMasks(frame.colour, setup_, options);
    size_t blue = 0;
    while (setup_.colours[blue].name != "blue") ++blue;
    return static_cast<double>(cv::countNonZero(masks[blue] & body)) / cv::countNonZero(body);
  };
  const double threshold = coverage(DetectMethod::kThreshold);
  const double kmeans = coverage(DetectMethod::kKMeans);
  EXPECT_GT(kmeans, threshold + 0.15) << "threshold " << threshold << ", kmeans " << kmeans;
  DetectOptions options;
  options.method = DetectMethod::kKMeans;
  const std::vector<Detection> found = DetectColour(frame, "blue", options);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].kind, "large_ball");
}

TEST_F(DetectorTest, TwoTouchingBallsAreSplit) {
  Ball("buckyball", "red", -0.5, 0.0635);
  Ball("buckyball", "red", -0.5, -0.0635);
  const platform::RgbdFrame frame = Render(pose_);
  DetectOptions options;
  options.separation = SeparationMethod::kNone;
  options.split_spheres = false;
  // Unsplit, the pair is one blob that is not round: no detection at all.
  EXPECT_TRUE(DetectColour(frame, "red", options).empty());
  // Cut at its concave defects (the thesis), or found by the balls' centres whatever the cut.
  for (const bool by_centres : {false, true}) {
    options.separation = by_centres ? SeparationMethod::kNone : SeparationMethod::kConcaveDefects;
    options.split_spheres = by_centres;
    const std::vector<Detection> split = DetectColour(frame, "red", options);
    ASSERT_EQ(split.size(), 2u) << (by_centres ? "by centres" : "by defects");
    for (const Detection& d : split) {
      ASSERT_TRUE(d.measurement.has_value());
      EXPECT_NEAR(std::abs(d.measurement->position_robot_m.y()), 0.0635, 0.03);
    }
  }
}

TEST_F(DetectorTest, ThreeTouchingBallsAreSplit) {
  for (int k = -1; k <= 1; ++k) Ball("buckyball", "blue", -0.6, 0.127 * k);
  const platform::RgbdFrame frame = Render(pose_);
  EXPECT_EQ(DetectColour(frame, "blue").size(), 3u);
}

TEST_F(DetectorTest, PartlyOccludedBallIsStillFound) {
  Ball("buckyball", "red", -0.6, 0.0);     // in front
  Ball("buckyball", "blue", -0.35, 0.09);  // behind, partly hidden by the red one
  const platform::RgbdFrame frame = Render(pose_);
  EXPECT_EQ(DetectColour(frame, "red").size(), 1u);
  EXPECT_EQ(DetectColour(frame, "blue").size(), 1u);
}

// The red goal is red, tall and not round: it is not a ball.
TEST_F(DetectorTest, SameColouredStructureIsRejected) {
  // The red stash (0.78, 0.61) 0.92 m ahead, seen from the goal zone where nothing stands in
  // front of it. (From the middle zone the barrier's pipe crosses it and its top half is
  // taken for a ball: not yet handled.)
  season_ = field::LoadSeasonConfig("toss_up");
  const Pose2D facing_goal{1.70, 0.61, M_PI};
  const platform::RgbdFrame frame = Render(facing_goal);
  DetectStats stats;
  const std::vector<Detection> all = Detect(frame.colour, frame.depth_mm, setup_, {}, &stats);
  for (const Detection& d : all) EXPECT_NE(d.colour, "red") << d.centre_px;
  EXPECT_GT(stats.rejected_shape + stats.rejected_size, 0);
}

TEST_F(DetectorTest, NoDepthMeansNoMeasurementNeverNaN) {
  Ball("buckyball", "red", -0.4, 0.2);
  const platform::RgbdFrame frame = Render(pose_);
  const cv::Mat zero_depth(frame.depth_mm.size(), CV_16UC1, cv::Scalar(0));
  DetectStats stats;
  std::vector<Detection> found = Detect(frame.colour, zero_depth, setup_, {}, &stats);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_FALSE(found[0].measurement.has_value());
  EXPECT_EQ(found[0].kind, "buckyball");  // its size fits a buckyball on the floor
  EXPECT_EQ(stats.without_depth, 1);
  // Colour only, with the robot's camera: ranged on the ground plane, finite.
  found = Detect(frame.colour, cv::Mat(), setup_, {});
  ASSERT_EQ(found.size(), 1u);
  ASSERT_TRUE(found[0].measurement.has_value());
  EXPECT_EQ(found[0].measurement->depth_pixels, 0);
  EXPECT_TRUE(std::isfinite(found[0].measurement->range_m));
  EXPECT_TRUE(found[0].measurement->covariance.allFinite());
  // Colour only, no camera (a photo): found, no range.
  DetectorSetup photo = setup_;
  photo.camera.reset();
  found = Detect(frame.colour, cv::Mat(), photo, {});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_FALSE(found[0].measurement.has_value());
}

// A piece with readings on few of its pixels (an object nearer than the camera's least range,
// whose few readings are of something seen beside or through it) is not measured by them
// (MeasurementOptions::min_depth_fraction): it is kept by its size on the floor, unranged.
TEST_F(DetectorTest, APieceMostlyWithoutReadingsIsNotRangedByThem) {
  const SimObject ball = Ball("buckyball", "red", -0.4, 0.2);
  platform::FrameTruth truth;
  platform::RgbdFrame frame = Render(pose_, &truth);
  // One pixel in eight of the ball reads 3.5 m (something beyond it); the rest reads nothing.
  int k = 0;
  for (int v = 0; v < frame.depth_mm.rows; ++v) {
    for (int u = 0; u < frame.depth_mm.cols; ++u) {
      if (truth.ids.at<uint16_t>(v, u) != ball.id) continue;
      frame.depth_mm.at<uint16_t>(v, u) = k++ % 8 == 0 ? 3500 : 0;
    }
  }
  ASSERT_GT(k, 200);
  const double truth_range = TruthRangeBearing(ball, pose_).x();
  DetectStats stats;
  std::vector<Detection> found;
  for (Detection& d : Detect(frame.colour, frame.depth_mm, setup_, {}, &stats)) {
    if (d.colour == "red") found.push_back(std::move(d));
  }
  // Kept: it has a buckyball's size on the floor at the ground plane's range; not ranged.
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].kind, "buckyball");
  EXPECT_FALSE(found[0].measurement.has_value());
  EXPECT_EQ(stats.without_depth, 1);
  // Measured by those readings, it is dropped (too small for 3.5 m) or ranged far off.
  DetectOptions by_readings;
  by_readings.measurement.min_depth_fraction = 0.0;
  found = DetectColour(frame, "red", by_readings);
  EXPECT_TRUE(found.empty() || !found[0].measurement ||
              std::abs(found[0].measurement->range_m - truth_range) > 0.5);
}

TEST_F(DetectorTest, BadInputIsAClearError) {
  const platform::RgbdFrame frame = Render(pose_);
  EXPECT_THROW(Detect(cv::Mat(), cv::Mat(), setup_, {}), std::invalid_argument);
  cv::Mat grey;
  cv::extractChannel(frame.colour, grey, 0);
  EXPECT_THROW(Detect(grey, cv::Mat(), setup_, {}), std::invalid_argument);
  cv::Mat depth8;
  frame.depth_mm.convertTo(depth8, CV_8U, 1.0 / 16.0);
  EXPECT_THROW(Detect(frame.colour, depth8, setup_, {}), std::invalid_argument);
  const cv::Mat small_depth(100, 100, CV_16UC1, cv::Scalar(1000));
  EXPECT_THROW(Detect(frame.colour, small_depth, setup_, {}), std::invalid_argument);
}

// A semi-transparent ball's blob taken whole (DetectOptions::min_disc_fill,
// min_disc_outline), on drawn shapes of Toss Up's blue without depth: a ball notched from the
// top down to near its centre (a highlight seen through it) and from the bottom (a seam) is
// one ball, with its centre and radius; without the step the cut between the notches takes it
// apart. A notched square is not taken for a
// ball: the circle fitted to its outline (radius 66 px, between the inscribed 60 and the
// circumscribed 85) has the outline on it over 0.61 of the way round, under the 0.7 asked;
// with no share asked, it is taken for one.
TEST(SemiDiscTest, ANotchedBallIsOneBallAndANotchedSquareIsNone) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const DetectorSetup setup = ObjectDetectorSetup(season, nullptr);
  const cv::Scalar grey(128, 128, 128), blue(200, 40, 20);  // BGR
  cv::Mat image(424, 512, CV_8UC3, grey);
  const cv::Point ball(170, 250), square(400, 120);
  cv::circle(image, ball, 70, blue, cv::FILLED);
  const std::vector<cv::Point> notch = {{150, 170}, {190, 170}, {170, 240}};
  cv::fillConvexPoly(image, notch, grey);
  const std::vector<cv::Point> low_notch = {{160, 330}, {180, 330}, {170, 290}};
  cv::fillConvexPoly(image, low_notch, grey);
  cv::rectangle(image, square - cv::Point(60, 60), square + cv::Point(60, 60), blue, cv::FILLED);
  const std::vector<cv::Point> square_notch = {{385, 60}, {415, 60}, {400, 95}};
  cv::fillConvexPoly(image, square_notch, grey);
  const auto near = [&](const DetectOptions& options, cv::Point at, double radius) {
    const std::vector<Detection> found = Detect(image, cv::Mat(), setup, options);
    return std::count_if(found.begin(), found.end(), [&](const Detection& d) {
      return d.colour == "blue" && cv::norm(d.centre_px - cv::Point2d(at)) < 0.1 * radius &&
             std::abs(d.radius_px - radius) < 0.1 * radius;
    });
  };
  const DetectOptions options;
  EXPECT_EQ(near(options, ball, 70), 1);
  EXPECT_EQ(near(options, square, 60), 0);
  DetectOptions without = options;
  without.min_disc_fill = 0.0;
  EXPECT_EQ(near(without, ball, 70), 0);
  DetectOptions any_outline = options;
  any_outline.min_disc_outline = 0.0;
  EXPECT_EQ(near(any_outline, square, 60), 1);
}

// Shapes per type (issue #16 item 3): objects that are not round have concave outlines of
// their own (a star's points; a ring's hole and corners seen obliquely), which the
// concave-defect cut takes for touching objects. With depth, a blob no larger than one such
// object can look is that one object. Single Starstruck stars and High Stakes rings from 24
// views each: one detection, never split (rings typed right). These views keep them whole
// without the size rule too; its effect in the evaluation's views is in vision_eval_test.
struct SingleObjectCase {
  const char* season;
  const char* type;
  double x_m;          // where the object lies, at y = -0.2
  double max_range_m;  // views 0.8 m to this from the object (Starstruck's fence is at x = 0)
};

class SingleObjectTest : public ::testing::TestWithParam<SingleObjectCase> {};

TEST_P(SingleObjectTest, IsNeverCut) {
  const SingleObjectCase& c = GetParam();
  const field::SeasonConfig season = field::LoadSeasonConfig(c.season);
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  const DetectorSetup setup = ObjectDetectorSetup(season, &robot.camera);
  const field::ObjectType* type = season.FindObjectType(c.type);
  ASSERT_NE(type, nullptr);
  int views = 0;
  for (int k = 0; k < 24; ++k) {
    platform::SimWorld world = platform::CreateWorld(season, 1);
    SimObject object;
    object.id = 1;
    object.type = type;
    object.colour = type->colours[static_cast<size_t>(k) % type->colours.size()];
    object.center_m = Eigen::Vector3d(c.x_m, -0.2, type->height_m / 2.0);
    world.objects = {object};
    // From the field's side of the object (bearings -70..70 deg).
    const double range = 0.8 + (c.max_range_m - 0.8) * k / 23.0, bearing = (k % 8 - 3.5) * 0.35;
    const Pose2D pose{c.x_m + range * std::cos(bearing), -0.2 + range * std::sin(bearing),
                      bearing + M_PI};
    platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{}, 1 + k);
    platform::FrameTruth truth;
    const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, &truth);
    if (truth.objects.empty() || truth.objects[0].pixels < 200) continue;
    ++views;
    // Detections on the object (other things of its colour may be in view: a wall stake).
    const cv::Rect object_box = truth.objects[0].box;
    const auto on_object = [&](const std::vector<Detection>& all) {
      std::vector<const Detection*> out;
      for (const Detection& d : all) {
        if ((d.box & object_box).area() > 0) out.push_back(&d);
      }
      return out;
    };
    SCOPED_TRACE("view " + std::to_string(k));
    const std::vector<Detection> found = Detect(frame.colour, frame.depth_mm, setup, {});
    const std::vector<const Detection*> seen = on_object(found);
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_FALSE(seen[0]->split);
    // Typing by size cannot tell Starstruck's star (0.28 m) from its cube (0.25 m).
    if (std::string(c.type) == "ring") {
      EXPECT_EQ(seen[0]->kind, "ring");
    }
  }
  EXPECT_GE(views, 16);
}

// A Push Back block framed on every side by a thing of its own colour 6 m behind it (a
// poster, a shirt): cut where the depth jumps (DetectOptions::depth_cut_min_m), the frame
// holds the block's region in its hole, and the block is still outlined on its own, found
// once, where it is; without the cut the two are one blob and the block is not found.
TEST(DepthCutTest, AnObjectFramedByItsColourFarBehindIsFound) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  const DetectorSetup setup = ObjectDetectorSetup(season, &robot.camera);
  const field::ObjectType* block = season.FindObjectType("block");
  ASSERT_NE(block, nullptr);
  platform::SimWorld world = platform::CreateWorld(season, 1);
  SimObject object;
  object.id = 1;
  object.type = block;
  object.colour = "red";
  object.center_m = Eigen::Vector3d(0.3, 0.3, block->height_m / 2.0);
  world.objects = {object};
  platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{}, 1);
  platform::FrameTruth truth;
  platform::RgbdFrame frame = renderer.Render(world, Pose2D{-0.9, 0.3, 0.0}, 0.0, &truth);
  ASSERT_EQ(truth.objects.size(), 1u);
  ASSERT_GT(truth.objects[0].pixels, 300);
  const cv::Mat block_pixels = truth.ids == 1;
  const cv::Scalar red = cv::mean(frame.colour, block_pixels);
  const cv::Rect box = truth.objects[0].box;
  const cv::Rect frame_box = (box + cv::Size(40, 40) - cv::Point(20, 20)) &
                             cv::Rect(0, 0, frame.colour.cols, frame.colour.rows);
  cv::Mat around(frame.colour.size(), CV_8UC1, cv::Scalar(0));
  around(frame_box).setTo(255);
  around.setTo(0, block_pixels);
  frame.colour.setTo(red, around);
  frame.depth_mm.setTo(6000, around);

  const auto on_block = [&](const Detection& d) {
    return d.colour == "red" &&
           box.contains(cv::Point(cvRound(d.centre_px.x), cvRound(d.centre_px.y))) &&
           d.area_px < 2.0 * truth.objects[0].pixels;
  };
  // The frame runs under the block too, 6 m away there as well, so the block floats over it:
  // the float test, which would clear it, is not what this test is about.
  DetectOptions options;
  options.drop_floating = false;
  const std::vector<Detection> with = Detect(frame.colour, frame.depth_mm, setup, options);
  ASSERT_EQ(std::count_if(with.begin(), with.end(), on_block), 1);
  const Detection& seen = *std::find_if(with.begin(), with.end(), on_block);
  ASSERT_TRUE(seen.measurement.has_value());
  EXPECT_NEAR(seen.measurement->position_robot_m.x(), 1.2, 0.1);
  DetectOptions without = options;
  without.depth_cut_min_m = 0.0;
  const std::vector<Detection> one_blob = Detect(frame.colour, frame.depth_mm, setup, without);
  EXPECT_EQ(std::count_if(one_blob.begin(), one_blob.end(), on_block), 0);
}

// Printed by type in test names (the default would print the struct's bytes, pointers too).
void PrintTo(const SingleObjectCase& c, std::ostream* out) { *out << c.season << "/" << c.type; }

INSTANTIATE_TEST_SUITE_P(Shapes, SingleObjectTest,
                         ::testing::Values(SingleObjectCase{"starstruck", "star", -1.6, 1.5},
                                           SingleObjectCase{"high_stakes", "ring", -1.1, 2.0}),
                         [](const ::testing::TestParamInfo<SingleObjectCase>& info) {
                           return std::string(info.param.type);
                         });

TEST(ColourClassesTest, RedHueWrapsAroundZero) {
  const ColourClass red = MakeColourClass("red", field::Rgb{220, 20, 40});  // hue ~354 deg
  cv::Mat hsv(1, 2, CV_8UC3);
  hsv.at<cv::Vec3b>(0, 0) = cv::Vec3b(2, 200, 200);    // hue 4 deg
  hsv.at<cv::Vec3b>(0, 1) = cv::Vec3b(176, 200, 200);  // hue 352 deg
  const cv::Mat mask = ThresholdHsv(hsv, red);
  EXPECT_EQ(mask.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(mask.at<uint8_t>(0, 1), 255);
  EXPECT_THROW(MakeColourClass("grey", field::Rgb{128, 128, 128}), std::invalid_argument);
}

// The one-pass threshold of several classes gives each class's ThresholdHsv mask, wrapping
// and fractional windows too. Both are windows on each channel separately, so every hue
// against every saturation (value 255) and every hue against every value (saturation 255)
// covers every window edge; hue runs past 180.
TEST(ColourClassesTest, OnePassThresholdMatchesEachClass) {
  std::vector<ColourClass> colours;
  for (const char* name : {"toss_up", "high_stakes", "over_under", "starstruck", "skyrise"}) {
    const field::SeasonConfig season = field::LoadSeasonConfig(name);
    for (const ColourClass& c : ObjectColourClasses(season)) colours.push_back(c);
    for (const ColourClass& c : LandmarkColourClasses(season)) colours.push_back(c);
  }
  ColourClass odd = MakeColourClass("odd", field::Rgb{250, 10, 120});
  odd.hue_deg = 359.3, odd.hue_tolerance_deg = 0.7, odd.min_saturation = 0, odd.min_value = 255;
  colours.push_back(odd);
  odd.hue_deg = 0.25, odd.hue_tolerance_deg = 1.25, odd.min_saturation = 255, odd.min_value = 0;
  colours.push_back(odd);
  odd.hue_deg = 181.0, odd.hue_tolerance_deg = 89.0, odd.min_saturation = 17, odd.min_value = 3;
  colours.push_back(odd);
  cv::Mat hsv(512, 263, CV_8UC3, cv::Scalar(0, 0, 0));  // 263: a row end past 16-pixel blocks
  for (int v = 0; v < 256; ++v) {
    for (int u = 0; u < 256; ++u) {
      hsv.at<cv::Vec3b>(v, (u + v) % 263) = cv::Vec3b(v, u, 255);
      hsv.at<cv::Vec3b>(256 + v, (u + v) % 263) = cv::Vec3b(v, 255, u);
    }
  }
  const std::vector<cv::Mat> masks = ThresholdHsv(hsv, colours);
  ASSERT_EQ(masks.size(), colours.size());
  for (size_t j = 0; j < colours.size(); ++j) {
    SCOPED_TRACE(colours[j].name);
    EXPECT_EQ(cv::norm(masks[j], ThresholdHsv(hsv, colours[j]), cv::NORM_INF), 0.0);
  }
}

}  // namespace
}  // namespace slamo::vision

namespace slamo::vision {
namespace {

// The season's landmark markers on the far wall: found in their colours, at their range.
TEST(LandmarkDetectionTest, FindsTheMarkersOnTheFarWall) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  platform::SimWorld world = platform::CreateWorld(season, 1);
  world.objects.clear();
  platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{}, 1);
  platform::FrameTruth truth;
  const platform::Pose2D pose{0.0, 0.0, 0.0};
  const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, &truth);
  const DetectorSetup setup = LandmarkDetectorSetup(season, &robot.camera);
  const std::vector<Detection> found = Detect(frame.colour, frame.depth_mm, setup, {});
  int matched = 0;
  for (const platform::LandmarkTruth& l : truth.landmarks) {
    if (l.pixels < 60) continue;  // barely in view
    const Eigen::Vector2d expected(std::hypot(l.position_m.x(), l.position_m.y()),
                                   std::atan2(l.position_m.y(), l.position_m.x()));
    for (const Detection& d : found) {
      if (d.colour != season.landmarks[l.index].colour || !d.measurement) continue;
      if (std::abs(d.measurement->bearing_rad - expected.y()) > 0.05) continue;
      EXPECT_NEAR(d.measurement->range_m, expected.x(), 0.05);
      ++matched;
    }
  }
  EXPECT_GE(matched, 2);
  EXPECT_LE(found.size(), truth.landmarks.size());  // nothing else taken for a marker
}

// High Stakes' stack of two beside the ladder, a red ring on a blue one, seen by the V5 robot's
// camera 0.8 m away: the blue ring shows only its side under the red (a band as wide as a ring
// and as tall as one, too small by its area for a ring seen whole). Both are found, each at its
// own height; before, the blue was refused by its size and the planner's picks of the red ring
// took the blue one under it (the intake meets the bottom ring first).
TEST(StackedRingsTest, TheLowerRingOfAStackOfTwoColoursIsFoundBySide) {
  const field::SeasonConfig season = field::LoadSeasonConfig("high_stakes");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  const platform::SimWorld world = platform::CreateWorld(season, 1);
  platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{}, 1);
  const platform::Pose2D pose{-0.37, 0.25, 195.0 * M_PI / 180.0};
  const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, nullptr);
  const DetectorSetup setup = ObjectDetectorSetup(season, &robot.camera);
  // The stack's rings, bottom first.
  std::vector<const SimObject*> stack;
  for (const SimObject& o : world.objects) {
    if (o.type->name == "ring" &&
        (o.center_m.head<2>() - Eigen::Vector2d(-1.196, 0.0)).norm() < 0.05)
      stack.push_back(&o);
  }
  std::sort(stack.begin(), stack.end(), [](const SimObject* a, const SimObject* b) {
    return a->center_m.z() < b->center_m.z();
  });
  ASSERT_EQ(stack.size(), 2u);
  ASSERT_EQ(stack[0]->colour, "blue");
  ASSERT_EQ(stack[1]->colour, "red");
  // The detections of `colour` within 8 cm of the stack (through the true pose), by height. (A
  // ring's range is taken to its centre half its thickness behind the surface seen, right
  // from above; seen from the side its centre lies a radius behind: the blue is placed 5.6 cm
  // short, a known bias of every ring seen low, not of this step.)
  const auto at_stack = [&](const DetectOptions& options, const std::string& colour) {
    std::vector<double> heights;
    for (const Detection& d : Detect(frame.colour, frame.depth_mm, setup, options)) {
      if (d.colour != colour || !d.measurement) continue;
      const Eigen::Vector3d& p = d.measurement->position_robot_m;
      const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
      const Eigen::Vector2d at(pose.x_m + c * p.x() - s * p.y(), pose.y_m + s * p.x() + c * p.y());
      if ((at - stack[0]->center_m.head<2>()).norm() < 0.08) heights.push_back(p.z());
    }
    return heights;
  };
  const std::vector<double> blue = at_stack({}, "blue"), red = at_stack({}, "red");
  ASSERT_EQ(blue.size(), 1u);
  ASSERT_EQ(red.size(), 1u);
  EXPECT_NEAR(blue[0], stack[0]->center_m.z(), 0.02);
  EXPECT_NEAR(red[0], stack[1]->center_m.z(), 0.02);
  DetectOptions by_area;
  by_area.flat_side_pieces = false;
  EXPECT_TRUE(at_stack(by_area, "blue").empty());
  EXPECT_EQ(at_stack(by_area, "red").size(), 1u);
}

// The readings under a mask, sixteen pixels at a time where it can: the same readings, in the
// same order, as one pixel at a time. Masks of runs (whole chunks set, whole chunks clear, and
// chunks of both), depth with holes, boxes of any size and views into larger images.
TEST(MaskedReadingsTest, SameAsPixelByPixel) {
  std::mt19937 rng(41);
  int whole_chunks = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const int w = 1 + static_cast<int>(rng() % 120), h = 1 + static_cast<int>(rng() % 40);
    cv::Mat mask(h + 2, w + 3, CV_8UC1, cv::Scalar(0)), depth(h + 2, w + 3, CV_16UC1);
    cv::randu(depth, 0, 4000);
    for (int v = 0; v < mask.rows; ++v) {
      for (int u = 0; u < mask.cols;) {
        const int run = 1 + static_cast<int>(rng() % 40);
        const uint8_t value = rng() % 2 == 0 ? 0 : static_cast<uint8_t>(1 + rng() % 255);
        for (int k = u; k < std::min(mask.cols, u + run); ++k) mask.at<uint8_t>(v, k) = value;
        u += run;
      }
      for (int u = 0; u < depth.cols; ++u) {  // no reading: 1 in 500, or 1 in 20
        if (rng() % (trial % 2 == 0 ? 500 : 20) == 0) {
          depth.at<uint16_t>(v, u) = 0;
        } else {
          depth.at<uint16_t>(v, u) |= 1;
        }
      }
    }
    const cv::Rect box(static_cast<int>(rng() % 3), static_cast<int>(rng() % 2), w, h);
    std::vector<uint16_t> expected;
    for (int v = box.y; v < box.y + box.height; ++v) {
      for (int u = box.x; u < box.x + box.width; ++u) {
        if (mask.at<uint8_t>(v, u) != 0 && depth.at<uint16_t>(v, u) != 0) {
          expected.push_back(depth.at<uint16_t>(v, u));
        }
      }
      for (int u = box.x; u + 16 <= box.x + box.width; u += 16) {
        bool all_valid = true;
        for (int k = u; k < u + 16; ++k) {
          all_valid &= mask.at<uint8_t>(v, k) != 0 && depth.at<uint16_t>(v, k) != 0;
        }
        whole_chunks += all_valid ? 1 : 0;
      }
    }
    std::vector<uint16_t> readings(trial % 3 == 0 ? 0 : 5);
    const size_t count = MaskedReadings(depth, mask, box, &readings);
    ASSERT_EQ(count, expected.size()) << "trial " << trial;
    ASSERT_TRUE(std::equal(expected.begin(), expected.end(), readings.begin()))
        << "trial " << trial;
  }
  EXPECT_GT(whole_chunks, 100);  // the sixteen-at-a-time path was taken
}

}  // namespace
}  // namespace slamo::vision
