#include "mapping/object_tracker.h"

#include <gtest/gtest.h>

#include <random>

#include "mapping/ekf_slam.h"

namespace slamo::mapping {
namespace {

ObjectObservation See(const Eigen::Vector3d& pose, const Eigen::Vector2d& object,
                      std::mt19937_64* rng, const char* colour = "blue") {
  std::normal_distribution<double> n01(0.0, 1.0);
  const Eigen::Vector2d z = EkfSlam::Observe(pose, object);
  ObjectObservation o;
  o.kind = "buckyball";
  o.colour = colour;
  o.range_m = z.x() + 0.01 * n01(*rng);
  o.bearing_rad = z.y() + 0.005 * n01(*rng);
  o.covariance = Eigen::Vector2d(1e-4, 2.5e-5).asDiagonal();
  return o;
}

TEST(ObjectTrackerTest, RepeatedSightingsConvergeOnOneTrack) {
  std::mt19937_64 rng(1);
  ObjectTracker tracker;
  const Eigen::Vector3d pose(0, 0, 0);
  const Eigen::Matrix3d pose_cov = Eigen::Matrix3d::Identity() * 1e-6;
  const Eigen::Vector2d truth(1.5, 0.4);
  for (int frame = 0; frame < 20; ++frame)
    tracker.Update(pose, pose_cov, {See(pose, truth, &rng)}, frame * 0.1);
  ASSERT_EQ(tracker.objects().size(), 1u);
  const TrackedObject& o = tracker.objects()[0];
  EXPECT_EQ(o.times_seen, 20);
  EXPECT_LT((o.position_m - truth).norm(), 0.01);
  EXPECT_LT(o.covariance.trace(), 2e-5);
  EXPECT_DOUBLE_EQ(o.confidence, 1.0);
}

TEST(ObjectTrackerTest, SameColourObjectsApartAndColoursApart) {
  std::mt19937_64 rng(2);
  ObjectTracker tracker;
  const Eigen::Vector3d pose(0, 0, 0);
  const Eigen::Matrix3d pose_cov = Eigen::Matrix3d::Identity() * 1e-6;
  for (int frame = 0; frame < 5; ++frame) {
    tracker.Update(pose, pose_cov,
                   {See(pose, {1.5, 0.4}, &rng), See(pose, {1.5, -0.4}, &rng),
                    See(pose, {1.5, 0.4}, &rng, "red")},
                   frame * 0.1);
  }
  EXPECT_EQ(tracker.objects().size(), 3u);
}

TEST(ObjectTrackerTest, PoseUncertaintyWidensTheObject) {
  std::mt19937_64 rng(3);
  ObjectTracker sure, unsure;
  const Eigen::Vector3d pose(0, 0, 0);
  sure.Update(pose, Eigen::Matrix3d::Identity() * 1e-6, {See(pose, {2.0, 0.0}, &rng)}, 0.0);
  unsure.Update(pose, Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal(), {See(pose, {2.0, 0.0}, &rng)},
                0.0);
  EXPECT_GT(unsure.objects()[0].covariance.trace(), 10 * sure.objects()[0].covariance.trace());
}

// An object a robot took away: expected in view, not seen, it fades and goes.
TEST(ObjectTrackerTest, MissingObjectsFadeAndGo) {
  std::mt19937_64 rng(4);
  ObjectTracker tracker;
  const Eigen::Vector3d pose(0, 0, 0);
  const Eigen::Matrix3d pose_cov = Eigen::Matrix3d::Identity() * 1e-6;
  const auto in_view = [](const TrackedObject& o) {
    return o.position_m.x() > 0.5 && o.position_m.x() < 4.0;
  };
  for (int frame = 0; frame < 3; ++frame)
    tracker.Update(pose, pose_cov, {See(pose, {1.5, 0.4}, &rng)}, frame, in_view);
  ASSERT_EQ(tracker.objects().size(), 1u);
  int frames_to_forget = 0;
  while (!tracker.objects().empty() && frames_to_forget < 20) {
    tracker.Update(pose, pose_cov, {}, 3 + frames_to_forget, in_view);
    ++frames_to_forget;
  }
  EXPECT_TRUE(tracker.objects().empty());
  EXPECT_LE(frames_to_forget, 5);
  // Out of view, it is kept.
  ObjectTracker behind;
  behind.Update(pose, pose_cov, {See(pose, {1.5, 0.4}, &rng)}, 0.0, in_view);
  for (int frame = 1; frame < 10; ++frame)
    behind.Update(pose, pose_cov, {}, frame, [](const TrackedObject&) { return false; });
  EXPECT_EQ(behind.objects().size(), 1u);
}

}  // namespace
}  // namespace slamo::mapping
