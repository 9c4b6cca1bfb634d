// SLAM-O's front end on frames rendered by the simulator, checked against the renderer's truth.
#include "mapping/slam_o.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include <gtest/gtest.h>

#include "field_configs/loader.h"
#include "platform/camera_geometry.h"
#include "platform/sim/sim_renderer.h"
#include "platform/sim/sim_world.h"

namespace slamo::mapping {
namespace {

using platform::kPi;

class SlamOTest : public ::testing::Test {
 protected:
  SlamOTest()
      : season_(field::LoadSeasonConfig("toss_up")),
        robot_(field::LoadRobotConfig(field::kDefaultRobot)),
        world_(platform::CreateWorld(season_, 7)),
        renderer_(season_, robot_.camera, platform::RenderOptions{}, 7) {}

  // A start at `pose` with `covariance`, over the surveyed markers as the renderer draws them.
  SlamOPrior Prior(const Eigen::Vector3d& pose, const Eigen::Matrix3d& covariance) const {
    SlamOPrior prior;
    prior.pose = pose;
    prior.covariance = covariance;
    for (const Eigen::Vector3d& c : renderer_.landmark_centres())
      prior.surveyed_markers.push_back(c.head<2>());
    return prior;
  }
  platform::RgbdFrame Render(const platform::Pose2D& pose, double t_s) {
    return renderer_.Render(world_, pose, t_s, nullptr);
  }
  static Eigen::Vector3d V(const platform::Pose2D& p) {
    return Eigen::Vector3d(p.x_m, p.y_m, p.theta_rad);
  }
  // Frames at `truth` until the frame rule stops; returns the frames taken.
  int ObserveStop(SlamO* slam, const platform::Pose2D& truth, double t_s) {
    slam->BeginStop();
    for (int taken = 1; taken <= 30; ++taken) {
      if (!slam->UpdateLandmarks(Render(truth, t_s + taken / 30.0)).more_frames) return taken;
    }
    return 30;
  }

  field::SeasonConfig season_;
  field::RobotConfig robot_;
  platform::SimWorld world_;
  platform::SimRenderer renderer_;
};

// Mid field, facing the -x wall's markers.
const platform::Pose2D kTruth{0.3, 0.2, kPi};

TEST_F(SlamOTest, FramesOfMarkersPullAnOffsetPoseBackToTheTruth) {
  SlamOOptions options;
  options.ekf.add_landmarks = false;
  const Eigen::Vector3d start = V(kTruth) + Eigen::Vector3d(0.06, -0.05, 0.03);
  SlamO slam(season_, robot_.camera,
             Prior(start, Eigen::Vector3d(0.08 * 0.08, 0.08 * 0.08, 0.05 * 0.05).asDiagonal()),
             options);
  const double before = (slam.pose() - V(kTruth)).head<2>().norm();
  const int frames = ObserveStop(&slam, kTruth, 0.0);
  const double after = (slam.pose() - V(kTruth)).head<2>().norm();
  EXPECT_GT(before, 0.07);
  EXPECT_LT(after, 0.03) << "after " << frames << " frames";
  EXPECT_EQ(slam.frames(), frames);
  EXPECT_EQ(slam.gated_frames(), 0);
  // The belief shrank, and the truth lies inside it.
  EXPECT_LT((slam.pose_covariance().topLeftCorner<2, 2>().trace()), 0.0064);
  EXPECT_LT(PoseNees(V(kTruth), slam.pose(), slam.pose_covariance()), 16.3);  // chi2(3), 99.9 %
}

TEST_F(SlamOTest, AKidnappedRobotIsReacquiredOnlyWhenRelocalisationIsOn) {
  // The filter believes the robot 0.5 m from where it is, and is sure of it.
  const Eigen::Vector3d believed = V(kTruth) + Eigen::Vector3d(0.0, 0.5, 0.0);
  const Eigen::Matrix3d sure = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
  for (const bool relocalise : {false, true}) {
    SlamOOptions options;
    options.ekf.add_landmarks = false;
    options.relocalise = relocalise;
    SlamO slam(season_, robot_.camera, Prior(believed, sure), options);
    ObserveStop(&slam, kTruth, 0.0);
    ObserveStop(&slam, kTruth, 2.0);
    const double error = (slam.pose() - V(kTruth)).head<2>().norm();
    if (relocalise) {
      EXPECT_GE(slam.relocalisations(), 1);
      EXPECT_LT(error, 0.05);
    } else {
      EXPECT_EQ(slam.relocalisations(), 0);
      EXPECT_GT(error, 0.3);
    }
  }
}

TEST_F(SlamOTest, FramesOfOneStopShareTheBiasAndAMoveStartsANewStop) {
  SlamOOptions options;
  options.ekf.add_landmarks = false;
  options.white_covariance = Eigen::Vector2d(1e-4, 1e-5).asDiagonal();
  options.stop_bias_covariance = Eigen::Vector2d(4e-4, 4e-5).asDiagonal();
  SlamO slam(season_, robot_.camera, Prior(V(kTruth), Eigen::Matrix3d::Identity() * 1e-4), options);
  const platform::RgbdFrame frame = Render(kTruth, 0.0);
  const LandmarkFrame first = slam.Process(frame, {0.0, 0.0, 0.0}, false);
  const LandmarkFrame second = slam.Process(frame, {0.0, 0.0, 0.0}, false);
  const LandmarkFrame moved = slam.Process(frame, {0.01, 0.0, 0.0}, false);
  ASSERT_FALSE(first.measurements.empty());
  const Eigen::Matrix2d w = options.white_covariance, b = options.stop_bias_covariance;
  EXPECT_TRUE(first.measurements[0].covariance.isApprox(IteratedFrameCovariance(w, b, 1)));
  EXPECT_TRUE(second.measurements[0].covariance.isApprox(IteratedFrameCovariance(w, b, 2)));
  EXPECT_TRUE(moved.measurements[0].covariance.isApprox(IteratedFrameCovariance(w, b, 1)));
  // The second frame of a stop weighs less than the first.
  EXPECT_GT(second.measurements[0].covariance(0, 0), first.measurements[0].covariance(0, 0));
}

// Facing the -x wall turned 0.3 rad to the left of kTruth: from kTruth itself the end of the
// blue hanging bar (x = -1.45) is cut by the image's edge and passes for a blue buckyball (a
// detector weakness with same-coloured structures seen in part, not handled yet).
const platform::Pose2D kObjectsView{0.3, 0.2, kPi + 0.3};

TEST_F(SlamOTest, ObjectsSeenTwiceAreMappedWhereTheyAre) {
  SlamOOptions options;
  options.ekf.add_landmarks = false;
  SlamO slam(season_, robot_.camera, Prior(V(kObjectsView), Eigen::Matrix3d::Identity() * 1e-6),
             options);
  const platform::RgbdFrame frame = Render(kObjectsView, 0.0);
  slam.TrackObjects(frame, 0.0);
  EXPECT_TRUE(slam.ConfirmedObjects().empty());  // one sighting confirms nothing
  slam.TrackObjects(Render(kObjectsView, 0.5), 0.5);
  const std::vector<TrackedObject> confirmed = slam.ConfirmedObjects();
  ASSERT_GE(confirmed.size(), 2u);
  for (const TrackedObject& o : confirmed) {
    double nearest = 1e9;
    for (const platform::SimObject& t : world_.objects) {
      if (t.colour == o.colour && t.type->name == o.kind)
        nearest = std::min(nearest, (t.center_m.head<2>() - o.position_m).norm());
    }
    EXPECT_LT(nearest, 0.1) << o.kind << " " << o.colour << " " << o.position_m.transpose();
  }
  // The maps: every confirmed object in the object map but the one taken off the field; the
  // obstacle map only when asked, and only objects at least as wide as the rule's minimum.
  const auto centre = [&](const TrackedObject& o) {
    return Eigen::Vector3d(o.position_m.x(), o.position_m.y(),
                           season_.FindObjectType(o.kind)->height_m / 2.0);
  };
  const int taken = confirmed.front().id;
  ObstacleRule wide_only;
  wide_only.min_size_m = 10.0;  // nothing is this wide: no obstacles
  slam.UpdateMaps({taken}, wide_only);
  EXPECT_FALSE(slam.object_map().IsOccupied(centre(confirmed.front())));
  for (size_t k = 1; k < confirmed.size(); ++k) {
    EXPECT_TRUE(slam.object_map().IsOccupied(centre(confirmed[k]))) << k;
    EXPECT_FALSE(slam.obstacle_map().IsOccupied(centre(confirmed[k]))) << k;
  }
  slam.UpdateMaps({}, ObstacleRule{});
  for (const TrackedObject& o : confirmed) EXPECT_TRUE(slam.obstacle_map().IsOccupied(centre(o)));
  EXPECT_EQ(slam.ConfirmedObjects({taken}).size(), confirmed.size() - 1);
}

// A start known exactly, over the surveyed markers as `renderer` draws them.
SlamOPrior KnownStart(const platform::SimRenderer& renderer, const platform::Pose2D& start) {
  SlamOPrior prior;
  prior.pose = Eigen::Vector3d(start.x_m, start.y_m, start.theta_rad);
  prior.covariance = Eigen::Matrix3d::Identity() * 1e-6;
  for (const Eigen::Vector3d& c : renderer.landmark_centres())
    prior.surveyed_markers.push_back(c.head<2>());
  return prior;
}

// Push Back's blocks lie in touching groups (three red ones in an L in front of the red
// start). The match detector separates blobs of a colour with no round kind by the blocks' known
// size: without it the group is one blob three blocks wide, rejected by size, and the planner
// never knew the blocks nearest it (`slamo dry-run --season push_back --robot v5_drivetrain`).
TEST(SlamOBlocksTest, ATouchingGroupOfBlocksIsTrackedBlockByBlock) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  const platform::SimWorld world = platform::CreateWorld(season, 3);
  platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{}, 3);
  const platform::Pose2D start{-1.45, 0.6, 0.0};  // 0.85 m behind the group, facing it
  SlamOOptions options;
  options.ekf.add_landmarks = false;
  const SlamOPrior prior = KnownStart(renderer, start);
  SlamO slam(season, robot.camera, prior, options);
  for (int k = 0; k < 3; ++k)
    slam.TrackObjects(renderer.Render(world, start, k / 30.0, nullptr), k / 30.0);
  // The group's blocks: red, on the floor, 0.5-1.1 m ahead of the robot (not the preloads).
  std::vector<Eigen::Vector2d> group;
  for (const platform::SimObject& t : world.objects) {
    const Eigen::Vector2d rel = t.center_m.head<2>() - Eigen::Vector2d(start.x_m, start.y_m);
    if (t.colour == "red" && t.center_m.z() < 0.1 && rel.x() > 0.5 && rel.norm() < 1.1)
      group.push_back(t.center_m.head<2>());
  }
  ASSERT_EQ(group.size(), 3u);
  std::vector<bool> found(group.size(), false);
  for (const TrackedObject& o : slam.ConfirmedObjects()) {
    if (o.colour != "red") continue;
    for (size_t k = 0; k < group.size(); ++k) {
      if ((group[k] - o.position_m).norm() < 0.05) found[k] = true;
    }
  }
  for (size_t k = 0; k < group.size(); ++k)
    EXPECT_TRUE(found[k]) << "block at " << group[k].transpose() << " not tracked";
}

// An object the camera should see whole and does not is not where it was believed: it loses
// confidence. Near the robot the camera, looking down, loses an object below its view: that
// one is kept. Which is which comes from the camera's mount and the object's size
// (platform::WholeInView), not a fixed range: the V5 robot's camera sees a Push Back block
// whole from 0.64 m.
TEST(SlamOBlocksTest, ANearObjectTakenAwayFadesOnlyWhereTheCameraSeesIt) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  platform::SimWorld world = platform::CreateWorld(season, 3);
  platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{}, 3);
  const platform::Pose2D start{-1.45, 0.6, 0.0};  // 0.85 m behind a group of three blocks
  SlamOOptions options;
  options.ekf.add_landmarks = false;
  const SlamOPrior prior = KnownStart(renderer, start);
  const field::ObjectType* block = season.FindObjectType("block");
  ASSERT_NE(block, nullptr);
  // The nearest red block of the group is taken off the field once it is mapped; the robot
  // then drives to face where it was from `back_m` behind it and looks (two frames).
  // Returns its confidence before and after.
  const auto look_from = [&](double back_m) {
    SlamO slam(season, robot.camera, prior, options);
    platform::SimWorld field = world;
    for (int k = 0; k < 3; ++k)
      slam.TrackObjects(renderer.Render(field, start, k / 30.0, nullptr), k / 30.0);
    const Eigen::Vector2d from(start.x_m, start.y_m);
    auto nearest = field.objects.end();
    for (auto it = field.objects.begin(); it != field.objects.end(); ++it) {
      const Eigen::Vector2d rel = it->center_m.head<2>() - from;
      if (it->colour != "red" || it->center_m.z() > 0.1 || rel.x() < 0.5) continue;
      if (nearest == field.objects.end() ||
          rel.norm() < (nearest->center_m.head<2>() - from).norm())
        nearest = it;
    }
    std::pair<double, double> confidence(-1.0, -1.0);
    if (nearest == field.objects.end()) return confidence;
    const Eigen::Vector2d at = nearest->center_m.head<2>();
    field.objects.erase(nearest);
    int id = -1;
    for (const TrackedObject& o : slam.ConfirmedObjects()) {
      if (o.colour == "red" && (o.position_m - at).norm() < 0.05)
        id = o.id, confidence.first = o.confidence;
    }
    const Eigen::Vector2d dir = (at - from).normalized();
    const Eigen::Vector2d stand = at - back_m * dir;
    const platform::Pose2D pose{stand.x(), stand.y(), std::atan2(dir.y(), dir.x())};
    slam.Predict(OdometryIncrement(start, pose));
    for (int k = 0; k < 2; ++k)
      slam.TrackObjects(renderer.Render(field, pose, 1.0 + k / 30.0, nullptr), 1.0 + k / 30.0);
    for (const TrackedObject& o : slam.ConfirmedObjects())
      if (o.id == id) confidence.second = o.confidence;
    return confidence;
  };
  // 0.7 m from the robot's centre: in view, and not seen in either frame.
  const auto [seen_before, seen_after] = look_from(0.7);
  ASSERT_GT(seen_before, 0.0) << "the block was not mapped";
  EXPECT_LT(seen_after, seen_before - 0.4);
  // 0.45 m: below the view, kept. (With the fixed 0.8 m range SLAM-O had, both were kept.)
  const auto [below_before, below_after] = look_from(0.45);
  ASSERT_GT(below_before, 0.0);
  EXPECT_DOUBLE_EQ(below_after, below_before);
  // The distance comes from the mount: the block's near bottom edge on the lowest ray of the
  // view less the margin, in pixels (0.63 m for this camera, 0.38 m high, pitched 15 degrees).
  const field::CameraConfig& camera = robot.camera;
  const double lowest_v = camera.height_px - camera.fy * std::tan(0.05);
  const double lowest =
      camera.mount.pitch_deg * kPi / 180.0 + std::atan((lowest_v - camera.cy) / camera.fy);
  EXPECT_NEAR(platform::NearestWholeInView(camera, block->size_m, block->height_m, 0.05, 2.0),
              camera.mount.x_m + camera.mount.height_m / std::tan(lowest) + block->size_m / 2.0,
              0.015);
}

// An object believed where the robot stands cannot be there: it is forgotten, unless it lies
// on a structure. Objects beside the robot, or within the errors of the footprint's edge, stay.
TEST_F(SlamOTest, ObjectsBelievedUnderTheRobotAreForgotten) {
  SlamOOptions options;
  options.ekf.add_landmarks = false;
  SlamO slam(season_, robot_.camera, Prior(V(kObjectsView), Eigen::Matrix3d::Identity() * 1e-6),
             options);
  slam.TrackObjects(Render(kObjectsView, 0.0), 0.0);
  slam.TrackObjects(Render(kObjectsView, 0.5), 0.5);
  const std::vector<TrackedObject> confirmed = slam.ConfirmedObjects();
  ASSERT_GE(confirmed.size(), 2u);
  // The nearest object, in the robot's frame: a footprint just reaching it (within the
  // errors of its edge) keeps it; one 0.1 m larger each way covers it, and nothing else.
  const Eigen::Vector2d at(kObjectsView.x_m, kObjectsView.y_m);
  const Eigen::Vector2d ahead(std::cos(kObjectsView.theta_rad), std::sin(kObjectsView.theta_rad));
  const auto along = [&](const TrackedObject& o) {
    return std::abs((o.position_m - at).dot(ahead));
  };
  const auto side = [&](const TrackedObject& o) {
    const Eigen::Vector2d rel = o.position_m - at;
    return std::abs(rel.x() * ahead.y() - rel.y() * ahead.x());
  };
  const TrackedObject nearest = *std::min_element(
      confirmed.begin(), confirmed.end(), [&](const TrackedObject& a, const TrackedObject& b) {
        return (a.position_m - at).norm() < (b.position_m - at).norm();
      });
  const double length = 2.0 * along(nearest), width = 2.0 * side(nearest);
  for (const TrackedObject& o : confirmed) {
    if (o.id == nearest.id) continue;
    ASSERT_TRUE(along(o) > length / 2.0 + 0.1 || side(o) > width / 2.0 + 0.1);
  }
  EXPECT_EQ(slam.ForgetObjectsUnderRobot(length + 0.01, width + 0.01), 0);
  // Length runs along the heading: the footprint with its sides swapped misses it when it lies
  // further ahead than aside (or the other way) by more than the errors.
  ASSERT_GT(std::abs(length - width), 0.2);
  EXPECT_EQ(slam.ForgetObjectsUnderRobot(width + 0.2, length + 0.2), 0);
  EXPECT_EQ(slam.ForgetObjectsUnderRobot(length + 0.2, width + 0.2), 1);
  EXPECT_EQ(slam.ConfirmedObjects().size(), confirmed.size() - 1);
  EXPECT_EQ(slam.forgotten_under_robot(), 1);
}

// An object the footprint met on the way of the drive that ended here (its centre within
// half the width plus its radius of the way, less the errors) was pushed along and is
// forgotten; one beside the way stays. Here the robot came backwards from 1 m beyond the
// nearest object, along its heading.
TEST_F(SlamOTest, ObjectsTheFootprintMetOnTheWayAreForgotten) {
  SlamOOptions options;
  options.ekf.add_landmarks = false;
  SlamO slam(season_, robot_.camera, Prior(V(kObjectsView), Eigen::Matrix3d::Identity() * 1e-6),
             options);
  slam.TrackObjects(Render(kObjectsView, 0.0), 0.0);
  slam.TrackObjects(Render(kObjectsView, 0.5), 0.5);
  const std::vector<TrackedObject> confirmed = slam.ConfirmedObjects();
  ASSERT_GE(confirmed.size(), 2u);
  const Eigen::Vector2d at(kObjectsView.x_m, kObjectsView.y_m);
  const Eigen::Vector2d ahead(std::cos(kObjectsView.theta_rad), std::sin(kObjectsView.theta_rad));
  const auto side = [&](const TrackedObject& o) {
    const Eigen::Vector2d rel = o.position_m - at;
    return std::abs(rel.x() * ahead.y() - rel.y() * ahead.x());
  };
  const TrackedObject nearest = *std::min_element(
      confirmed.begin(), confirmed.end(), [&](const TrackedObject& a, const TrackedObject& b) {
        return (a.position_m - at).norm() < (b.position_m - at).norm();
      });
  const double beyond = (nearest.position_m - at).dot(ahead) + 1.0;
  const Eigen::Vector3d from(at.x() + beyond * ahead.x(), at.y() + beyond * ahead.y(),
                             kObjectsView.theta_rad);
  const double r = season_.FindObjectType(nearest.kind)->size_m / 2.0;
  const double length = 0.1;  // the footprint where the robot stands covers nothing
  ASSERT_GT(side(nearest) - r - 0.1, 0.0) << "a footprint of some width misses it";
  // A footprint whose side passes 0.1 m short of the object's edge misses it.
  EXPECT_EQ(slam.ForgetObjectsUnderRobot(length, 2.0 * (side(nearest) - r - 0.1), from), 0);
  // One whose side reaches 0.15 m past its centre meets it, and every other object it meets.
  const double width = 2.0 * (side(nearest) + 0.15 - r);
  int met = 0;
  for (const TrackedObject& o : confirmed) {
    const double along = (o.position_m - at).dot(ahead);
    const double ro = season_.FindObjectType(o.kind)->size_m / 2.0;
    if (along > -length / 2.0 && along < beyond + length / 2.0 && side(o) < width / 2.0 + ro) ++met;
  }
  EXPECT_EQ(slam.ForgetObjectsUnderRobot(length, width, from), met);
  for (const TrackedObject& o : slam.ConfirmedObjects()) EXPECT_NE(o.id, nearest.id);
  // Without the way, the same footprint where the robot stands meets nothing.
  EXPECT_EQ(slam.ForgetObjectsUnderRobot(length, width), 0);
}

// After a pick that took nothing, what was believed in the intake's mouth (reach_m beyond the
// front bumper, to the object's near edge) is forgotten; what lies beyond it stays.
TEST_F(SlamOTest, ObjectsBelievedInAnEmptyIntakeAreForgotten) {
  SlamOOptions options;
  options.ekf.add_landmarks = false;
  SlamO slam(season_, robot_.camera, Prior(V(kObjectsView), Eigen::Matrix3d::Identity() * 1e-6),
             options);
  slam.TrackObjects(Render(kObjectsView, 0.0), 0.0);
  slam.TrackObjects(Render(kObjectsView, 0.5), 0.5);
  const std::vector<TrackedObject> confirmed = slam.ConfirmedObjects();
  ASSERT_GE(confirmed.size(), 2u);
  const Eigen::Vector2d at(kObjectsView.x_m, kObjectsView.y_m);
  const Eigen::Vector2d ahead(std::cos(kObjectsView.theta_rad), std::sin(kObjectsView.theta_rad));
  const TrackedObject nearest = *std::min_element(
      confirmed.begin(), confirmed.end(), [&](const TrackedObject& a, const TrackedObject& b) {
        return (a.position_m - at).norm() < (b.position_m - at).norm();
      });
  const Eigen::Vector2d rel = nearest.position_m - at;
  const double along = rel.dot(ahead);
  const double side = std::abs(rel.x() * ahead.y() - rel.y() * ahead.x());
  const double r = season_.FindObjectType(nearest.kind)->size_m / 2.0;
  // A robot whose bumper stands 0.1 m short of the object's near edge, wide enough to cover it.
  const double length = 2.0 * (along - r - 0.1), width = 2.0 * side + 0.4;
  ASSERT_GT(length, 0.2);
  EXPECT_EQ(slam.ForgetObjectsUnderRobot(length, width, std::nullopt, 0.0), 0);
  EXPECT_EQ(slam.ForgetObjectsUnderRobot(length, width, std::nullopt, 0.05), 0);  // short of it
  EXPECT_GE(slam.ForgetObjectsUnderRobot(length, width, std::nullopt, 0.25), 1);
  for (const TrackedObject& o : slam.ConfirmedObjects()) EXPECT_NE(o.id, nearest.id);
}

TEST(OdometryIncrementTest, IsTheMoveInTheFirstPosesFrame) {
  const platform::Pose2D from{1.0, 2.0, kPi / 2};
  const platform::Pose2D to{1.0, 3.0, kPi};
  const OdometryStep u = OdometryIncrement(from, to);
  EXPECT_NEAR(u.dx_m, 1.0, 1e-12);  // straight ahead of a robot facing +y
  EXPECT_NEAR(u.dy_m, 0.0, 1e-12);
  EXPECT_NEAR(u.dtheta_rad, kPi / 2, 1e-12);
  // Moving `from` by the increment gives `to`.
  const Eigen::Vector3d moved =
      EkfSlam::Move(Eigen::Vector3d(from.x_m, from.y_m, from.theta_rad), u, nullptr, nullptr);
  EXPECT_NEAR(moved.x(), to.x_m, 1e-12);
  EXPECT_NEAR(moved.y(), to.y_m, 1e-12);
}

}  // namespace
}  // namespace slamo::mapping
