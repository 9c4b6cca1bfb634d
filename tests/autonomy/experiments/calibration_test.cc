// Success models fitted to attempt records: a known logistic law is recovered, the two-fold
// reliability table of a well-specified model is calibrated, and a file fitted for another
// season or robot is refused.
#include "autonomy/experiments/calibration.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

namespace slamo::autonomy {
namespace {

// Attempts drawn from P = logistic(2 - 3 range + 0 bearing - 20 sigma).
std::vector<AttemptSample> Drawn(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> range(0.3, 1.2), bearing(-1.0, 1.0), sigma(0.0, 0.15);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<AttemptSample> out;
  for (int i = 0; i < n; ++i) {
    AttemptSample s;
    s.action = "PICK";
    s.kind = "buckyball";
    s.range_m = range(rng);
    s.bearing_rad = bearing(rng);
    s.sigma_m = sigma(rng);
    const double p = 1.0 / (1.0 + std::exp(-(2.0 - 3.0 * s.range_m - 20.0 * s.sigma_m)));
    s.success = unit(rng) < p;
    s.seed = static_cast<uint64_t>(i + 1);
    out.push_back(s);
  }
  return out;
}

TEST(Calibration, AKnownLogisticLawIsRecovered) {
  const SuccessModel m = FitSuccessModel(Drawn(4000, 7), "PICK", "buckyball");
  EXPECT_EQ(m.samples, 4000);
  EXPECT_NEAR(m.weights[0], 2.0, 0.35);
  EXPECT_NEAR(m.weights[1], -3.0, 0.4);
  EXPECT_NEAR(m.weights[2], 0.0, 0.25);
  EXPECT_NEAR(m.weights[3], -20.0, 2.5);
  // A kind that always worked still gets a finite, high probability.
  std::vector<AttemptSample> always = Drawn(50, 3);
  for (AttemptSample& s : always) s.success = true;
  const SuccessModel sure = FitSuccessModel(always, "PICK", "buckyball");
  for (double w : sure.weights) EXPECT_TRUE(std::isfinite(w));
  EXPECT_GT(sure.Predict(0.5, 0.0, 0.05), 0.9);
}

TEST(Calibration, TheTwoFoldReliabilityOfAWellSpecifiedModelIsCalibrated) {
  const std::vector<AttemptSample> samples = Drawn(4000, 11);
  int counted = 0;
  for (const ReliabilityBin& b : Reliability(samples, "PICK", 5)) {
    counted += b.attempts;
    if (b.attempts < 200) continue;
    EXPECT_NEAR(double(b.successes) / b.attempts, b.mean_predicted, 0.06)
        << b.low << "-" << b.high << ": " << b.attempts << " attempts";
    EXPECT_GE(b.mean_predicted, b.low);
    EXPECT_LE(b.mean_predicted, b.high);
  }
  EXPECT_EQ(counted, 4000);  // every attempt predicted once, by the other fold's model
}

TEST(Calibration, TheFileRoundTripsAndIsRefusedForAnotherSeasonOrRobot) {
  const Calibration c = Calibrate(Drawn(100, 5), "toss_up", "thesis_robot");
  ASSERT_EQ(c.models.size(), 2u);  // PICK over every kind, and for buckyballs
  ASSERT_NE(c.Find("PICK", "buckyball"), nullptr);
  EXPECT_EQ(c.Find("PICK", "large_ball"), c.Find("PICK", ""));  // falls back to every kind
  EXPECT_EQ(c.Find("SCORE", "buckyball"), nullptr);             // too few attempts: none
  const std::string path = ::testing::TempDir() + "/calibration_test.json";
  std::ofstream(path) << ToJson(c).dump(2);
  const Calibration back = LoadCalibration(path, "toss_up", "thesis_robot");
  ASSERT_EQ(back.models.size(), c.models.size());
  EXPECT_DOUBLE_EQ(back.models[1].weights[3], c.models[1].weights[3]);
  const auto learned = LearnedSuccess(back);
  EXPECT_DOUBLE_EQ(*learned("PICK", "buckyball", 0.5, 0.0, 0.05),
                   c.Find("PICK", "buckyball")->Predict(0.5, 0.0, 0.05));
  EXPECT_FALSE(learned("SCORE", "buckyball", 0.5, 0.0, 0.05).has_value());
  EXPECT_THROW(LoadCalibration(path, "high_stakes", "thesis_robot"), std::invalid_argument);
  EXPECT_THROW(LoadCalibration(path, "toss_up", "v5_drivetrain"), std::invalid_argument);
  EXPECT_THROW(LoadCalibration(path + ".missing", "toss_up", "thesis_robot"),
               std::invalid_argument);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace slamo::autonomy
