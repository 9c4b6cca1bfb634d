#include "vision/field_gate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "field_configs/loader.h"
#include "platform/sim/sim_renderer.h"
#include "platform/sim/sim_world.h"
#include "vision/detector.h"

namespace slamo::vision {
namespace {

using platform::Pose2D;
using platform::SimObject;

class FieldGateTest : public ::testing::Test {
 protected:
  FieldGateTest()
      : season_(field::LoadSeasonConfig("toss_up")),
        robot_(field::LoadRobotConfig("thesis_robot")),
        camera_(robot_.camera),
        bounds_(FieldBoundsOf(season_)) {}

  // A detection with a depth measurement at `world` seen from `pose_`.
  Detection At(const Eigen::Vector3d& world) const {
    const double c = std::cos(pose_.z()), s = std::sin(pose_.z());
    const Eigen::Vector2d rel(world.x() - pose_.x(), world.y() - pose_.y());
    Measurement m;
    m.position_robot_m =
        Eigen::Vector3d(c * rel.x() + s * rel.y(), -s * rel.x() + c * rel.y(), world.z());
    m.range_m = m.position_robot_m.head<2>().norm();
    m.bearing_rad = std::atan2(m.position_robot_m.y(), m.position_robot_m.x());
    m.covariance = Eigen::Vector2d(0.01 * 0.01, 0.005 * 0.005).asDiagonal();
    m.depth_pixels = 100;
    Detection d;
    d.colour = "red";
    d.measurement = m;
    return d;
  }

  // A detection without a measurement whose lowest pixel is (u, v).
  static Detection Blob(int u, int v) {
    Detection d;
    d.colour = "red";
    d.box = cv::Rect(u - 5, v - 10, 11, 11);
    d.contour = {{u - 5, v - 10}, {u + 5, v - 10}, {u, v}};
    return d;
  }

  field::SeasonConfig season_;
  field::RobotConfig robot_;
  CameraModel camera_;
  FieldBounds bounds_;
  const Eigen::Vector3d pose_{-1.0, 0.2, 0.3};
};

// The bounds come from the season file: the perimeter's size, the tallest object (Toss Up's
// large ball is taller than the wall) and the stashes objects are scored into.
TEST_F(FieldGateTest, BoundsComeFromTheSeasonFile) {
  EXPECT_DOUBLE_EQ(bounds_.half_size_m, season_.HalfSize());
  EXPECT_DOUBLE_EQ(bounds_.floor_top_m, season_.FindObjectType("large_ball")->height_m);
  EXPECT_GT(bounds_.floor_top_m, season_.field.wall_height_m);
  // Red and blue stash, and the four large balls lying on the barrier.
  ASSERT_EQ(bounds_.raised.size(), 6u);
  double lowest = 1e9, highest = 0.0;
  for (const FieldBounds::Column& c : bounds_.raised)
    lowest = std::min(lowest, c.top_m), highest = std::max(highest, c.top_m);
  EXPECT_NEAR(highest, 0.61 + 0.40, 1e-9);  // a stash with a large ball on it
  EXPECT_NEAR(lowest, 0.35 + 0.40, 1e-9);   // a large ball on the barrier, its height above
  field::SeasonConfig wider = season_;
  wider.field.size_m = 5.0;
  EXPECT_DOUBLE_EQ(FieldBoundsOf(wider).half_size_m, 2.5);
}

// Planted detections with positions: off the field or above every object top go, the rest
// stay, and the count says how many went.
TEST_F(FieldGateTest, PositionsOffTheFieldOrTooHighAreRejected) {
  const double half = season_.HalfSize();
  const std::vector<Detection> planted = {
      At({0.5, 0.3, 0.06}),          // on the floor: kept
      At({half - 0.07, 1.0, 0.06}),  // against the wall: kept
      At({half + 0.8, 0.0, 0.5}),    // a poster beyond the wall: rejected
      At({0.0, -half - 0.5, 0.06}),  // beyond the side wall at floor height: rejected
      At({0.0, 0.0, 0.9}),           // above the open field: rejected
      At({0.78, 0.61, 0.9}),         // in the red stash, above the wall: kept
  };
  int rejected = 0;
  const std::vector<Detection> kept =
      RejectOffField(planted, camera_, pose_, bounds_, FieldGateOptions{}, {}, &rejected);
  EXPECT_EQ(rejected, 3);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_NEAR(kept[0].measurement->position_robot_m.z(), 0.06, 1e-12);
  EXPECT_NEAR(kept[2].measurement->position_robot_m.z(), 0.9, 1e-12);
  // The pose's uncertainty widens the field: a detection 0.1 m beyond the wall stays when
  // the pose is known to 0.1 m only.
  const Detection just_beyond = At({half + 0.1, 0.0, 0.06});
  EXPECT_FALSE(OnField(just_beyond, camera_, pose_, bounds_));
  FieldGateOptions loose;
  loose.pose_sigma_m = 0.1;
  EXPECT_TRUE(OnField(just_beyond, camera_, pose_, bounds_, loose));
}

// Without a position: a blob low in the image is on the floor; one at the top of the image
// looks over the wall from a robot facing it.
TEST_F(FieldGateTest, WithoutDepthTheRayMustComeDownIntoTheField) {
  const Eigen::Vector3d facing_wall(0.8, 0.0, 0.0);
  const int w = robot_.camera.width_px, h = robot_.camera.height_px;
  EXPECT_TRUE(OnField(Blob(w / 2, h - 5), camera_, facing_wall, bounds_));
  EXPECT_FALSE(OnField(Blob(w / 2, 10), camera_, facing_wall, bounds_));
}

// Against the renderer: in an arena frame facing a wall, the gate drops detections on the
// stands and keeps every detection of a real object where it is.
TEST_F(FieldGateTest, ArenaFrameLosesStandsNotObjects) {
  platform::SimWorld world = platform::CreateWorld(season_, 4);
  platform::RenderOptions options;
  options.arena = true;
  const DetectorSetup setup = ObjectDetectorSetup(season_, &robot_.camera);
  int rejected_objects = 0, rejected_total = 0, kept_objects = 0;
  for (int k = 0; k < 6; ++k) {
    const Pose2D pose{0.6 - 0.3 * k, -0.6 + 0.2 * k, 0.4 * k};
    platform::SimRenderer renderer(season_, robot_.camera, options, 11 + k);
    platform::FrameTruth truth;
    const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, &truth);
    for (const Detection& d : Detect(frame.colour, frame.depth_mm, setup, DetectOptions{})) {
      // The centre of a blob cut by the image's edge can round to just outside it.
      const cv::Point centre(std::clamp(cvRound(d.centre_px.x), 0, truth.ids.cols - 1),
                             std::clamp(cvRound(d.centre_px.y), 0, truth.ids.rows - 1));
      const int id = truth.ids.at<uint16_t>(centre);
      // A detection of a real object: on its pixels, and measured within 0.3 m of it (a
      // semi-transparent ball's depth can read the stands through it: that measurement is
      // not of the ball, and dropping it is right).
      bool object = false;
      for (const platform::ObjectTruth& o : truth.objects) {
        if (o.id != id || id <= 0 || id >= platform::kLandmarkIdBase || !d.measurement) continue;
        const Eigen::Vector2d r = d.measurement->position_robot_m.head<2>();
        const Eigen::Vector2d world =
            Eigen::Vector2d(pose.x_m, pose.y_m) + Eigen::Rotation2Dd(pose.theta_rad) * r;
        object = (world - o.position_m.head<2>()).norm() < 0.3;
      }
      const bool on = OnField(d, camera_, {pose.x_m, pose.y_m, pose.theta_rad}, bounds_);
      rejected_total += !on;
      rejected_objects += object && !on;
      kept_objects += object && on;
    }
  }
  EXPECT_GT(rejected_total, 5);
  EXPECT_EQ(rejected_objects, 0);
  EXPECT_GT(kept_objects, 5);
}

// The structures the gate treats as solid come from the season file, without those objects
// go into: Toss Up's stashes (balls rest on top) are solid; High Stakes' alliance stakes
// (rings thread onto them) and Push Back's loaders (blocks stacked inside) are not.
TEST_F(FieldGateTest, SolidsAreTheColouredStructuresObjectsCannotBeIn) {
  const auto names = [](const std::string& season_name) {
    const field::SeasonConfig season = field::LoadSeasonConfig(season_name);
    const FieldBounds bounds = FieldBoundsOf(season);
    std::vector<std::string> found;
    for (const FieldBounds::Solid& solid : bounds.solids) {
      for (const field::Structure& st : season.structures) {
        if (st.colour == solid.colour && st.center_m.x == solid.centre_m.x() &&
            st.center_m.y == solid.centre_m.y()) {
          found.push_back(st.name);
        }
      }
    }
    return found;
  };
  const auto has = [](const std::vector<std::string>& v, const std::string& name) {
    return std::find(v.begin(), v.end(), name) != v.end();
  };
  const std::vector<std::string> toss_up = names("toss_up");
  EXPECT_TRUE(has(toss_up, "red_goal"));
  EXPECT_TRUE(has(toss_up, "blue_goal"));
  const std::vector<std::string> high_stakes = names("high_stakes");
  EXPECT_FALSE(has(high_stakes, "red_alliance_stake"));
  EXPECT_FALSE(has(high_stakes, "blue_alliance_stake"));
  const std::vector<std::string> push_back = names("push_back");
  EXPECT_FALSE(has(push_back, "red_loader_left"));
  EXPECT_FALSE(has(push_back, "blue_loader_right"));
  EXPECT_FALSE(push_back.empty());  // its park-zone rails are
}

// Against the renderer: seen from the middle zone with the barrier's pipe across it, the red
// stash's top half passes the detector for a red ball (tests/vision/detector_test.cc); its
// centre lies inside the stash, where no object can be, so the gate drops it. A red ball
// beside the stash, and one scored on top of it, are both seen and kept.
TEST_F(FieldGateTest, ADetectionInsideAStructureOfItsColourIsThatStructure) {
  platform::SimWorld world = platform::CreateWorld(season_, 5);
  const auto ball = [&](int id, const std::string& type, double x, double y, double z) {
    SimObject o;
    o.id = id;
    o.type = season_.FindObjectType(type);
    o.colour = "red";
    o.center_m = Eigen::Vector3d(x, y, z + o.type->size_m / 2.0);
    return o;
  };
  const double buckyball = season_.FindObjectType("buckyball")->size_m;
  // Beside the stash's near side (radius 0.14; 8 cm from it, off to one side: a ball touching
  // it straight in front merges with the stash's blob and is not detected at all, a limit of
  // the detector, not of the gate), and a large ball stashed on its top (0.61).
  world.objects = {ball(1, "buckyball", 0.78 - 0.14 - buckyball / 2.0 - 0.005, 0.42, 0.0),
                   ball(2, "large_ball", 0.78, 0.61, 0.61)};
  const FieldBounds::Solid* stash = nullptr;
  for (const FieldBounds::Solid& solid : bounds_.solids) {
    if (solid.colour == "red" && solid.cylinder && solid.z_max_m > 0.5) stash = &solid;
  }
  ASSERT_NE(stash, nullptr) << "the red stash is a solid of the gate";
  FieldBounds without_solids = bounds_;
  without_solids.solids.clear();
  const Pose2D pose{-0.9, 0.55, 0.0};
  platform::SimRenderer renderer(season_, robot_.camera, platform::RenderOptions{}, 5);
  platform::FrameTruth truth;
  const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, &truth);
  DetectOptions kmeans;  // the large ball is semi-transparent
  kmeans.method = DetectMethod::kKMeans;
  int on_stash = 0, dropped_on_stash = 0;
  std::set<int> balls_kept;
  for (const Detection& d :
       Detect(frame.colour, frame.depth_mm, ObjectDetectorSetup(season_, &robot_.camera), kmeans)) {
    if (d.colour != "red" || !d.measurement) continue;
    const cv::Point centre(std::clamp(cvRound(d.centre_px.x), 0, truth.ids.cols - 1),
                           std::clamp(cvRound(d.centre_px.y), 0, truth.ids.rows - 1));
    const int id = truth.ids.at<uint16_t>(centre);
    const bool on = OnField(d, camera_, {pose.x_m, pose.y_m, pose.theta_rad}, bounds_);
    if (id == 1 || id == 2) {
      if (on) balls_kept.insert(id);
      EXPECT_TRUE(on) << "ball " << id << " at " << d.centre_px;
      continue;
    }
    const Eigen::Vector2d r = d.measurement->position_robot_m.head<2>();
    const Eigen::Vector2d at =
        Eigen::Vector2d(pose.x_m, pose.y_m) + Eigen::Rotation2Dd(pose.theta_rad) * r;
    if (stash->DistanceOutside(at) < 0.1) {
      ++on_stash;
      dropped_on_stash += !on;
      EXPECT_TRUE(OnField(d, camera_, {pose.x_m, pose.y_m, pose.theta_rad}, without_solids))
          << "only the structure test drops it";
    }
  }
  EXPECT_GT(on_stash, 0) << "the detector's weakness this test is about no longer shows";
  EXPECT_EQ(dropped_on_stash, on_stash);
  EXPECT_EQ(balls_kept.size(), 2u) << "both balls seen and kept";
}

// Item 2's last part: without depth, a ball on the floor gets its type from its apparent
// size at the ground-plane range, and that range is close to the truth.
// The stash goals are left out: seen across the barrier's pipe, the red stash's top half
// passes for a red ball (the detector weakness in tests/vision/detector_test.cc).
TEST_F(FieldGateTest, WithoutDepthTypeAndRangeComeFromTheGroundPlane) {
  field::SeasonConfig bare = season_;
  auto& structures = bare.structures;
  structures.erase(std::remove_if(structures.begin(), structures.end(),
                                  [](const field::Structure& st) {
                                    return st.name == "red_goal" || st.name == "blue_goal";
                                  }),
                   structures.end());
  platform::SimWorld world = platform::CreateWorld(bare, 3);
  const auto ball = [&](int id, const std::string& type, double x, double y) {
    SimObject o;
    o.id = id;
    o.type = season_.FindObjectType(type);
    o.colour = "red";
    o.center_m = Eigen::Vector3d(x, y, o.type->size_m / 2.0);
    return o;
  };
  world.objects = {ball(1, "buckyball", -0.5, 0.3), ball(2, "large_ball", 0.3, -0.2)};
  const Pose2D pose{-1.4, 0.1, 0.0};
  platform::SimRenderer renderer(bare, robot_.camera, platform::RenderOptions{}, 3);
  const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, nullptr);
  DetectOptions kmeans;  // the large ball is semi-transparent
  kmeans.method = DetectMethod::kKMeans;
  const std::vector<Detection> found =
      Detect(frame.colour, cv::Mat(), ObjectDetectorSetup(season_, &robot_.camera), kmeans);
  ASSERT_EQ(found.size(), 2u);
  for (const Detection& d : found) {
    ASSERT_TRUE(d.measurement.has_value());
    EXPECT_EQ(d.measurement->depth_pixels, 0);
    const SimObject& truth = d.kind == "buckyball" ? world.objects[0] : world.objects[1];
    ASSERT_TRUE(d.kind == "buckyball" || d.kind == "large_ball") << d.kind;
    const double true_range =
        std::hypot(truth.center_m.x() - pose.x_m - 0.0, truth.center_m.y() - pose.y_m);
    EXPECT_NEAR(d.measurement->range_m, true_range, 0.05) << d.kind;
  }
  EXPECT_NE(found[0].kind, found[1].kind);
}

}  // namespace
}  // namespace slamo::vision
