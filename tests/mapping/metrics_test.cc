#include "mapping/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

namespace slamo::mapping {
namespace {

// A wandering planar path, 10 Hz.
std::vector<TimedPose> Path(int n) {
  std::vector<TimedPose> poses;
  for (int i = 0; i < n; ++i) {
    const double t = 0.1 * i;
    poses.push_back({t, 2.0 * std::cos(0.3 * t) + 0.1 * t, 1.5 * std::sin(0.5 * t),
                     std::remainder(0.4 * t, 2.0 * M_PI)});
  }
  return poses;
}

std::string TempPath(const std::string& name) { return testing::TempDir() + "/" + name; }

TEST(AteTest, IdenticalTrajectoriesHaveZeroError) {
  const std::vector<TimedPose> path = Path(200);
  for (bool align : {true, false}) {
    const AteResult ate = AbsoluteTrajectoryError(path, path, 0.02, align);
    EXPECT_EQ(ate.pairs, 200);
    EXPECT_NEAR(ate.rmse_m, 0.0, 1e-9);
    EXPECT_NEAR(ate.max_m, 0.0, 1e-9);
  }
}

TEST(AteTest, RigidlyMovedCopyIsZeroAlignedAndTheOffsetUnaligned) {
  const std::vector<TimedPose> truth = Path(200);
  // Rotated and shifted: alignment recovers the transform exactly.
  Rigid2d moved{0.7, Eigen::Vector2d(1.0, -2.0)};
  std::vector<TimedPose> estimate;
  for (const TimedPose& p : truth) estimate.push_back(moved.Apply(p));
  const AteResult aligned = AbsoluteTrajectoryError(truth, estimate);
  EXPECT_NEAR(aligned.rmse_m, 0.0, 1e-9);
  // The alignment is the inverse of the move.
  EXPECT_NEAR(aligned.alignment.theta_rad, -0.7, 1e-9);

  // Shifted only: unaligned, every pose is off by the shift.
  const Rigid2d shift{0.0, Eigen::Vector2d(0.3, 0.4)};
  estimate.clear();
  for (const TimedPose& p : truth) estimate.push_back(shift.Apply(p));
  const AteResult raw = AbsoluteTrajectoryError(truth, estimate, 0.02, /*align=*/false);
  EXPECT_NEAR(raw.rmse_m, 0.5, 1e-9);
  EXPECT_NEAR(raw.mean_m, 0.5, 1e-9);
  EXPECT_NEAR(raw.max_m, 0.5, 1e-9);
  EXPECT_NEAR(AbsoluteTrajectoryError(truth, estimate).rmse_m, 0.0, 1e-9);
}

TEST(AteTest, NoisyCopyGivesTheNoise) {
  const std::vector<TimedPose> truth = Path(2000);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<TimedPose> estimate = truth;
  for (TimedPose& p : estimate) p.x_m += noise(rng), p.y_m += noise(rng);
  // Per-axis sigma 0.05 -> RMS distance 0.05 sqrt(2); alignment absorbs a little of it.
  const double expected = 0.05 * std::sqrt(2.0);
  EXPECT_NEAR(AbsoluteTrajectoryError(truth, estimate, 0.02, false).rmse_m, expected,
              0.05 * expected);
  const AteResult aligned = AbsoluteTrajectoryError(truth, estimate);
  EXPECT_NEAR(aligned.rmse_m, expected, 0.05 * expected);
  EXPECT_LE(aligned.rmse_m, AbsoluteTrajectoryError(truth, estimate, 0.02, false).rmse_m);
  EXPECT_LT(aligned.mean_m, aligned.rmse_m);
  EXPECT_LT(aligned.median_m, aligned.max_m);
}

TEST(AteTest, AssociatesByNearestTimestampWithinTheWindow) {
  const std::vector<TimedPose> truth = Path(50);
  std::vector<TimedPose> estimate = truth;
  for (TimedPose& p : estimate) p.t_s += 0.01;  // within 0.02 s
  EXPECT_EQ(AbsoluteTrajectoryError(truth, estimate).pairs, 50);
  for (TimedPose& p : estimate) p.t_s += 0.02;  // 0.03 s late: nothing pairs
  EXPECT_THROW(AbsoluteTrajectoryError(truth, estimate), std::invalid_argument);
  EXPECT_EQ(AbsoluteTrajectoryError(truth, estimate, 0.04).pairs, 50);

  // Each timestamp is used once, closest first.
  const std::vector<TimedPose> a = {{1.0, 0, 0, 0}, {1.1, 0, 0, 0}};
  const std::vector<TimedPose> b = {{1.04, 0, 0, 0}, {1.06, 0, 0, 0}};
  const auto pairs = AssociateByTime(a, b, 0.1);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], std::make_pair(0, 0));
  EXPECT_EQ(pairs[1], std::make_pair(1, 1));
}

TEST(AteTest, AlignRigidRecoversATransform) {
  const Rigid2d truth{-2.0, Eigen::Vector2d(0.5, 3.0)};
  std::vector<Eigen::Vector2d> from = {{0, 0}, {1, 0}, {0, 2}, {-1, 1}}, to;
  for (const auto& p : from) to.push_back(truth.Apply(p));
  const Rigid2d found = AlignRigid(from, to);
  EXPECT_NEAR(found.theta_rad, -2.0, 1e-12);
  EXPECT_NEAR((found.translation_m - truth.translation_m).norm(), 0.0, 1e-12);
}

TEST(TumTest, RoundTrip) {
  std::vector<TimedPose> poses = Path(100);
  poses.push_back({20.0, -1.0, 2.0, M_PI - 1e-4});
  poses.push_back({20.1, -1.0, 2.0, -M_PI + 1e-4});
  const std::string path = TempPath("round_trip.tum");
  WriteTumTrajectory(path, poses);
  const std::vector<TimedPose> read = ReadTumTrajectory(path);
  ASSERT_EQ(read.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(read[i].t_s, poses[i].t_s, 1e-6);
    EXPECT_NEAR(read[i].x_m, poses[i].x_m, 1e-6);
    EXPECT_NEAR(read[i].y_m, poses[i].y_m, 1e-6);
    EXPECT_NEAR(std::remainder(read[i].theta_rad - poses[i].theta_rad, 2 * M_PI), 0.0, 1e-6);
  }
}

TEST(TumTest, ReadsTheStandardFormatAndNamesTheBadLine) {
  const std::string path = TempPath("format.tum");
  {
    std::ofstream out(path);
    out << "# timestamp tx ty tz qx qy qz qw\n\n"
        << "1305031102.175304 1.3405 0.6266 1.6575 0.6574 0.6126 -0.2949 -0.3248\n"
        << "1.0 2.0 3.0 0 0 0 0.7071067811865476 0.7071067811865476\n";
  }
  const std::vector<TimedPose> poses = ReadTumTrajectory(path);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_NEAR(poses[0].t_s, 1305031102.175304, 1e-6);
  EXPECT_NEAR(poses[1].x_m, 2.0, 1e-12);
  EXPECT_NEAR(poses[1].theta_rad, M_PI / 2, 1e-9);

  {
    std::ofstream out(path);
    out << "1.0 2.0 3.0 0 0 0 0 1\n1.1 2.0 3.0 0 0 0 1\n";
  }
  try {
    ReadTumTrajectory(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":2:"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(path);
    out << "1.0 2.0 nan 0 0 0 0 1\n";
  }
  EXPECT_THROW(ReadTumTrajectory(path), std::runtime_error);
}

TEST(LandmarkRmseTest, MatchesByIdAndAfterTheAlignment) {
  const std::vector<LandmarkPoint> truth = {{0, 1.0, 1.0}, {1, 3.0, -1.0}, {2, -2.0, 0.5}};
  // The estimate lives in a rotated and shifted frame; its alignment maps it back.
  const Rigid2d frame{0.4, Eigen::Vector2d(-0.5, 0.2)};
  Rigid2d inverse;
  inverse.theta_rad = -frame.theta_rad;
  inverse.translation_m = -(Eigen::Rotation2Dd(-frame.theta_rad) * frame.translation_m);
  std::vector<LandmarkPoint> estimate;
  for (const LandmarkPoint& l : truth) {
    const Eigen::Vector2d p = frame.Apply(Eigen::Vector2d(l.x_m, l.y_m));
    estimate.push_back({l.id, p.x(), p.y()});
  }
  EXPECT_NEAR(LandmarkRmse(truth, estimate, inverse).rmse_m, 0.0, 1e-12);
  EXPECT_GT(LandmarkRmse(truth, estimate).rmse_m, 0.1);

  // Ids decide the pairing; an id-less estimate takes the nearest unmatched landmark.
  const std::vector<LandmarkPoint> offset = {{1, 3.1, -1.0}, {-1, -2.0, 0.4}};
  const LandmarkError error = LandmarkRmse(truth, offset);
  EXPECT_EQ(error.pairs, 2);
  EXPECT_EQ(error.missing, 1);
  EXPECT_NEAR(error.rmse_m, 0.1, 1e-12);
  EXPECT_THROW(LandmarkRmse(truth, {{7, 0, 0}}), std::invalid_argument);
}

TEST(LandmarkCsvTest, ReadsWithOrWithoutAHeader) {
  const std::string path = TempPath("landmarks.csv");
  {
    std::ofstream out(path);
    out << "id,x_m,y_m,sxx,sxy,syy\n0,1.5,-2,0.01,0,0.01\n3, 0.25 , 4\n";
  }
  const std::vector<LandmarkPoint> landmarks = ReadLandmarkCsv(path);
  ASSERT_EQ(landmarks.size(), 2u);
  EXPECT_EQ(landmarks[1].id, 3);
  EXPECT_DOUBLE_EQ(landmarks[1].x_m, 0.25);
  {
    std::ofstream out(path);
    out << "0,1,2\n1,x,2\n";
  }
  try {
    ReadLandmarkCsv(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(":2:"), std::string::npos) << e.what();
  }
}

// The truth files MRPT's simul-landmarks writes, as it writes them (headers and spacing from a
// run of simul-landmarks 2.x), told apart from TUM and CSV by their first line.
TEST(SimulLandmarksTruthTest, ReadsThePathAndTheMapAndTellsTheFormats) {
  const std::string path_file = TempPath("gen.rawlog_ground_truth_robot_path.txt");
  const std::string map_file = TempPath("gen.rawlog_ground_truth.txt");
  {
    std::ofstream out(path_file);
    out << "% Columns are: x(m) y(m) z(m) yaw(rad) pitch(rad) roll(rad)\n"
           "% File generated with mrpt-math at Thu Dec  3 10:53:42 2026\n\n"
           "%------------------------------------\n"
           "0.0000000000000000 0.0000000000000000 0.0000000000000000 0.0000000000000000 "
           "-0.0000000000000000 0.0000000000000000\n"
           "0.5 0.25 0 1.5707963267948966 0 0\n";
  }
  {
    std::ofstream out(map_file);
    out << "  7.525192  11.957772   0.000000    5    0   0.000000 1 \n"
           " -1.950009  -2.998284   0.000000    5    0   0.000000 2 \n";
  }
  EXPECT_EQ(DetectTruthFormat(path_file), TruthFormat::kSimulLandmarksPath);
  EXPECT_EQ(DetectTruthFormat(map_file), TruthFormat::kSimulLandmarksMap);
  const std::vector<SimulLandmarksPose> path = ReadSimulLandmarksPath(path_file);
  ASSERT_EQ(path.size(), 2u);
  EXPECT_DOUBLE_EQ(path[1].x_m, 0.5);
  EXPECT_DOUBLE_EQ(path[1].y_m, 0.25);
  EXPECT_DOUBLE_EQ(path[1].yaw_rad, M_PI / 2);
  const std::vector<LandmarkPoint> map = ReadSimulLandmarksMap(map_file);
  ASSERT_EQ(map.size(), 2u);
  EXPECT_EQ(map[0].id, 1);
  EXPECT_DOUBLE_EQ(map[1].x_m, -1.950009);
  EXPECT_DOUBLE_EQ(map[1].y_m, -2.998284);

  // TUM and CSV stay theirs.
  const std::string tum = TempPath("simul_tum.tum");
  WriteTumTrajectory(tum, Path(3), "true pose");
  EXPECT_EQ(DetectTruthFormat(tum), TruthFormat::kTumOrCsv);
  {
    std::ofstream out(tum);
    out << "0.1 1 2 0 0 0 0 1\n";  // no header
  }
  EXPECT_EQ(DetectTruthFormat(tum), TruthFormat::kTumOrCsv);
  const std::string csv = TempPath("simul_landmarks.csv");
  {
    std::ofstream out(csv);
    out << "0,1.5,-2\n";
  }
  EXPECT_EQ(DetectTruthFormat(csv), TruthFormat::kTumOrCsv);

  // Bad lines are named.
  {
    std::ofstream out(map_file);
    out << "1 2 0 5 0 0 3\n1 2 0 5 0 0 2.5\n";
  }
  try {
    ReadSimulLandmarksMap(map_file);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(":2: the id"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(path_file);
    out << "% x y z yaw pitch roll\n0 0 0\n";
  }
  try {
    ReadSimulLandmarksPath(path_file);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(":2: expected"), std::string::npos) << e.what();
  }
  EXPECT_THROW(DetectTruthFormat(TempPath("no_such_truth.txt")), std::runtime_error);
}

}  // namespace
}  // namespace slamo::mapping
