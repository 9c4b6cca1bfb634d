#include "autonomy/experiments/peer_bench.h"

#include <gtest/gtest.h>

#include <cmath>

namespace slamo::autonomy {
namespace {

constexpr double kTwoPi = 6.283185307179586;

TEST(PeerBenchTest, ScenarioDrivesTheLapsAndSeesLandmarksByIdWithinRange) {
  const PeerBenchOptions options;
  const PeerScenario scenario = SimulatePeerScenario(options, 1);
  ASSERT_EQ(scenario.landmarks.size(), 8u);
  // Step 0, then 2 laps of 4 sides of 20 steps and a corner.
  ASSERT_EQ(scenario.steps.size(), 1u + 2u * 4u * 21u);
  EXPECT_FALSE(scenario.steps.front().measurements.empty());
  // The robot is back at the start after whole laps.
  EXPECT_NEAR(scenario.steps.back().truth.head<2>().norm(), 0.0, 1e-9);
  for (const PeerStep& step : scenario.steps) {
    for (const mapping::RangeBearing& z : step.measurements) {
      EXPECT_LE(z.range_m, options.max_range_m);
      EXPECT_GE(z.id, 0);
      EXPECT_LT(z.id, 8);
    }
  }
  // Seeded: the same seed gives the same odometry.
  const PeerScenario again = SimulatePeerScenario(options, 1);
  EXPECT_EQ(again.steps[5].odometry.dx_m, scenario.steps[5].odometry.dx_m);
}

TEST(PeerBenchTest, SlamoAndMrptAgreeOnTheSameRun) {
  const PeerBenchOptions options;
  for (uint64_t seed : {1u, 2u, 3u}) {
    const PeerScenario scenario = SimulatePeerScenario(options, seed);
    const std::vector<mapping::TimedPose> truth = PeerTruth(scenario, options);
    const PeerTrack slamo = RunSlamoFilter(scenario, options);
    const PeerTrack mrpt = RunMrptFilter(scenario, options);
    ASSERT_EQ(slamo.poses.size(), scenario.steps.size());
    ASSERT_EQ(mrpt.poses.size(), scenario.steps.size());
    for (const PeerTrack* track : {&slamo, &mrpt}) {
      for (const mapping::TimedPose& p : track->poses) {
        ASSERT_TRUE(std::isfinite(p.x_m) && std::isfinite(p.y_m) && std::isfinite(p.theta_rad))
            << "seed " << seed;
      }
    }
    EXPECT_EQ(slamo.rejected, 0) << "seed " << seed;
    EXPECT_LT(mapping::AbsoluteTrajectoryError(truth, slamo.poses).rmse_m, 0.1) << "seed " << seed;
    // Same problem, same noise: the final poses agree.
    const mapping::TimedPose& a = slamo.poses.back();
    const mapping::TimedPose& b = mrpt.poses.back();
    EXPECT_LT(std::hypot(a.x_m - b.x_m, a.y_m - b.y_m), 0.05) << "seed " << seed;
    EXPECT_LT(std::abs(std::remainder(a.theta_rad - b.theta_rad, kTwoPi)), 0.05) << "seed " << seed;
  }
}

}  // namespace
}  // namespace slamo::autonomy
