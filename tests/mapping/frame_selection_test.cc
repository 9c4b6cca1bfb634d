#include "mapping/frame_selection.h"

#include <functional>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace slamo::mapping {
namespace {

// A pose covariance whose position trace is `trace` (split evenly over x and y).
Eigen::Matrix3d CovarianceWithTrace(double trace) {
  return Eigen::Vector3d(trace / 2.0, trace / 2.0, 1e-4).asDiagonal();
}

// Runs a selector over covariance traces (one per frame) at a fixed pose; returns the frames
// it took.
int FramesTaken(FrameSelector* selector, double start_trace, const std::vector<double>& traces) {
  selector->Start(CovarianceWithTrace(start_trace));
  int taken = 0;
  for (double trace : traces) {
    ++taken;
    if (!selector->Continue(Eigen::Vector3d::Zero(), CovarianceWithTrace(trace))) break;
  }
  return taken;
}

// Runs a selector (up to 20 frames) over estimates pose_at(k) for the k-th frame, the
// covariance halving each frame (never stalled); returns the frames it took.
int FramesTakenMoving(FrameSelector* selector, const std::function<Eigen::Vector3d(int)>& pose_at) {
  selector->Start(CovarianceWithTrace(1.0));
  int taken = 0;
  double trace = 1.0;
  while (taken < 20) {
    ++taken;
    trace *= 0.5;
    if (!selector->Continue(pose_at(taken), CovarianceWithTrace(trace))) break;
  }
  return taken;
}

TEST(FrameRuleTest, ParsesEveryRuleAndItsNumber) {
  FrameSelectionOptions options;
  ParseFrameRule("fixed:7", &options);
  EXPECT_EQ(options.rule, FrameRule::kFixed);
  EXPECT_EQ(options.fixed_frames, 7);
  EXPECT_EQ(Describe(options), "fixed:7");

  ParseFrameRule("covariance:0.002", &options);
  EXPECT_EQ(options.rule, FrameRule::kCovariance);
  EXPECT_DOUBLE_EQ(options.covariance_threshold, 0.002);
  EXPECT_EQ(Describe(options), "covariance:0.002");

  ParseFrameRule("covariance", &options);
  EXPECT_DOUBLE_EQ(options.covariance_threshold, 0.0);  // derived from the motion noise

  ParseFrameRule("gmm", &options);
  EXPECT_EQ(options.rule, FrameRule::kGmm);
  EXPECT_EQ(Describe(options), "gmm");
}

TEST(FrameRuleTest, AFixedCountAboveTheCapRaisesTheCap) {
  FrameSelectionOptions options;
  options.max_frames = 30;
  ParseFrameRule("fixed:50", &options);
  EXPECT_EQ(options.max_frames, 50);
}

TEST(FrameRuleTest, RejectsUnknownRulesAndBadNumbers) {
  FrameSelectionOptions options;
  for (const char* bad : {"", "fixed", "fixed:", "fixed:0", "fixed:2x", "fixed:1001",
                          "covariance:-1", "covariance:abc", "gmm:3", "random"}) {
    EXPECT_THROW(ParseFrameRule(bad, &options), std::invalid_argument) << bad;
  }
}

TEST(FrameRuleTest, DerivedThresholdIsOneLegOfMotionNoise) {
  MotionNoise noise;
  noise.sigma_per_m = 0.2;
  noise.lateral_sigma_per_m = 0.1;
  noise.floor_m = 0.0;
  // A 0.5 m leg: forward sigma 0.1 m, sideways 0.05 m.
  EXPECT_DOUBLE_EQ(DerivedCovarianceThreshold(noise, 0.5), 0.1 * 0.1 + 0.05 * 0.05);
  EXPECT_GT(DerivedCovarianceThreshold(noise, 1.0), DerivedCovarianceThreshold(noise, 0.5));
}

TEST(FrameSelectorTest, FixedRuleTakesExactlyItsCount) {
  FrameSelectionOptions options;
  options.rule = FrameRule::kFixed;
  options.fixed_frames = 4;
  FrameSelector selector(options);
  // Even a covariance that keeps shrinking does not stop it early.
  EXPECT_EQ(FramesTaken(&selector, 1.0, {0.5, 0.25, 0.12, 0.06, 0.03, 0.01}), 4);
  EXPECT_EQ(selector.reason(), "count");
  EXPECT_EQ(selector.frames(), 4);
}

TEST(FrameSelectorTest, CovarianceRuleStopsOnceBelowTheThreshold) {
  FrameSelectionOptions options;
  options.rule = FrameRule::kCovariance;
  options.covariance_threshold = 0.1;
  FrameSelector selector(options);
  EXPECT_EQ(FramesTaken(&selector, 1.0, {0.5, 0.3, 0.15, 0.09, 0.05}), 4);
  EXPECT_EQ(selector.reason(), "threshold");
}

TEST(FrameSelectorTest, CovarianceRuleStopsWhenTheCovarianceStalls) {
  FrameSelectionOptions options;
  options.rule = FrameRule::kCovariance;
  options.covariance_threshold = 0.01;  // never reached
  options.stall_frames = 3;
  options.min_improvement = 0.01;
  FrameSelector selector(options);
  // Two improving frames, then three that improve by less than 1 %.
  EXPECT_EQ(FramesTaken(&selector, 1.0, {0.5, 0.3, 0.299, 0.298, 0.297, 0.296}), 5);
  EXPECT_EQ(selector.reason(), "stalled");
}

TEST(FrameSelectorTest, EveryRuleStopsAtTheCap) {
  for (FrameRule rule : {FrameRule::kFixed, FrameRule::kCovariance, FrameRule::kGmm}) {
    FrameSelectionOptions options;
    options.rule = rule;
    options.fixed_frames = 100;
    options.covariance_threshold = 1e-9;
    options.gmm_max_frames = 100;
    options.max_frames = 6;
    FrameSelector selector(options);
    // Never stalled, never below the threshold; for GMM a pose that keeps moving.
    EXPECT_EQ(FramesTakenMoving(&selector, [](int k) { return Eigen::Vector3d(0.1 * k, 0, 0); }), 6)
        << static_cast<int>(rule);
    EXPECT_EQ(selector.reason(), "max") << static_cast<int>(rule);
  }
}

TEST(FrameSelectorTest, GmmStopsWhenEstimatesConvergeButNotBeforeItsMinimum) {
  FrameSelectionOptions options;
  options.rule = FrameRule::kGmm;
  options.gmm_min_frames = 5;
  options.gmm_threshold_m = 0.005;
  FrameSelector selector(options);
  // The same pose every frame: converged from the second frame, but the minimum holds.
  EXPECT_EQ(FramesTakenMoving(&selector, [](int) { return Eigen::Vector3d(1.0, 2.0, 0.0); }), 5);
  EXPECT_EQ(selector.reason(), "converged");
}

TEST(FrameSelectorTest, GmmKeepsGoingWhileEstimatesMove) {
  FrameSelectionOptions options;
  options.rule = FrameRule::kGmm;
  options.gmm_min_frames = 3;
  options.gmm_max_frames = 8;
  options.gmm_threshold_m = 0.005;
  FrameSelector selector(options);
  // Each estimate 5 cm from the last: never within 5 mm of the running mean.
  EXPECT_EQ(FramesTakenMoving(&selector, [](int k) { return Eigen::Vector3d(0.05 * k, 0, 0); }), 8);
  EXPECT_EQ(selector.reason(), "max");
}

TEST(FrameSelectorTest, StartResetsTheCount) {
  FrameSelectionOptions options;
  options.rule = FrameRule::kFixed;
  options.fixed_frames = 3;
  FrameSelector selector(options);
  EXPECT_EQ(FramesTaken(&selector, 1.0, {0.5, 0.4, 0.3, 0.2}), 3);
  EXPECT_EQ(FramesTaken(&selector, 1.0, {0.5, 0.4, 0.3, 0.2}), 3);
}

}  // namespace
}  // namespace slamo::mapping
