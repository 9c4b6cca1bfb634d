#include "vision/depth_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>

#include "field_configs/loader.h"
#include "platform/sim/sim_renderer.h"
#include "platform/sim/sim_world.h"

namespace slamo::vision {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) / kDegToRad;
}

// The unit normal facing the camera of a plane tilted from the optical axis by `pitch_deg`
// about x and `yaw_deg` about y.
Eigen::Vector3d TiltedNormal(double pitch_deg, double yaw_deg) {
  return (Eigen::AngleAxisd(yaw_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(pitch_deg * kDegToRad, Eigen::Vector3d::UnitX()) *
          Eigen::Vector3d(0, 0, -1))
      .normalized();
}

// `count` points on the plane n.p + distance = 0 within 1 m of its foot, Gaussian noise of
// `sigma_m`, and a fraction of outliers spread over the view.
std::vector<Eigen::Vector3d> NoisyPlane(const Eigen::Vector3d& normal, double distance_m, int count,
                                        double sigma_m, double outlier_fraction, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, sigma_m);
  std::bernoulli_distribution outlier(outlier_fraction);
  const Eigen::Vector3d e1 = normal.unitOrthogonal(), e2 = normal.cross(e1);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    if (outlier(rng)) {
      points.emplace_back(1.5 * unit(rng), 1.0 * unit(rng), 2.0 + 1.5 * unit(rng));
    } else {
      points.push_back(-distance_m * normal + unit(rng) * e1 + unit(rng) * e2 +
                       Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    }
  }
  return points;
}

TEST(FitPlaneRansacTest, RecoversANoisyTiltedPlaneAmongOutliers) {
  const Eigen::Vector3d normal = TiltedNormal(6.0, -4.0);
  const std::vector<Eigen::Vector3d> points = NoisyPlane(normal, 1.8, 4000, 0.005, 0.3, 3);
  const std::optional<PlaneFit> fit = FitPlaneRansac(points, PlaneFitOptions{});
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->distance_m, 1.8, 0.005);
  EXPECT_LT(AngleDeg(fit->plane.head<3>(), normal), 1.0);  // facing the camera, as given
  EXPECT_NEAR(fit->plane.head<3>().norm(), 1.0, 1e-12);
  EXPECT_GT(fit->plane.w(), 0.0);
  EXPECT_EQ(fit->points, 4000);
  EXPECT_NEAR(fit->inliers, 4000 * 0.7, 4000 * 0.05);
  EXPECT_NEAR(fit->rms_m, 0.005 * std::sqrt(1.0), 0.003);
}

TEST(FitPlaneRansacTest, SameSeedSamePlane) {
  const std::vector<Eigen::Vector3d> points =
      NoisyPlane(TiltedNormal(3.0, 2.0), 1.2, 2000, 0.005, 0.3, 5);
  const PlaneFit a = *FitPlaneRansac(points, PlaneFitOptions{});
  const PlaneFit b = *FitPlaneRansac(points, PlaneFitOptions{});
  EXPECT_EQ(a.plane, b.plane);
}

// Thesis 3.4.4: only planes within 10 deg of the camera axis count; a wall seen at 20 deg,
// or the floor, gives no plane.
TEST(FitPlaneRansacTest, RejectsAPlaneTiltedBeyondTheAngleConstraint) {
  const std::vector<Eigen::Vector3d> tilted =
      NoisyPlane(TiltedNormal(20.0, 0.0), 1.5, 3000, 0.003, 0.0, 7);
  EXPECT_FALSE(FitPlaneRansac(tilted, PlaneFitOptions{}).has_value());
  // Just beyond the limit is also out, and a looser limit accepts it.
  const std::vector<Eigen::Vector3d> steep =
      NoisyPlane(TiltedNormal(0.0, 12.0), 1.5, 3000, 0.003, 0.0, 8);
  EXPECT_FALSE(FitPlaneRansac(steep, PlaneFitOptions{}).has_value());
  PlaneFitOptions loose;
  loose.max_normal_angle_deg = 15.0;
  const std::optional<PlaneFit> fit = FitPlaneRansac(steep, loose);
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->distance_m, 1.5, 0.005);
}

TEST(FitPlaneRansacTest, TooFewPointsGiveNoPlane) {
  const std::vector<Eigen::Vector3d> points =
      NoisyPlane(TiltedNormal(0.0, 0.0), 1.0, 99, 0.001, 0.0, 9);
  EXPECT_FALSE(FitPlaneRansac(points, PlaneFitOptions{}).has_value());
  EXPECT_FALSE(FitPlaneRansac({}, PlaneFitOptions{}).has_value());
  PlaneFitOptions few;
  few.min_inliers = 0;
  EXPECT_FALSE(FitPlaneRansac({{0, 0, 1}, {1, 0, 1}}, few).has_value());
  // Three collinear points: no model at all.
  EXPECT_FALSE(FitPlaneRansac({{0, 0, 1}, {1, 0, 1}, {2, 0, 1}}, few).has_value());
}

TEST(FitLinearCorrectionTest, RecoversAAndBFromNoisyPairs) {
  const double a = 1.0384, b_mm = -1.9835;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 2.0);
  std::vector<std::pair<double, double>> pairs;
  for (double true_mm = 500; true_mm <= 3500; true_mm += 500) {
    for (int j = 0; j < 50; ++j) pairs.emplace_back(a * true_mm + b_mm + noise(rng), true_mm);
  }
  const LinearCorrection fit = FitLinearCorrection(pairs);
  EXPECT_NEAR(fit.a, a, 0.001);
  EXPECT_NEAR(fit.b_mm, b_mm, 1.0);
  EXPECT_NEAR(fit.rms_mm, 2.0, 0.2);
  EXPECT_EQ(fit.pairs, 350);
}

TEST(FitLinearCorrectionTest, ExactPairsAndBadInput) {
  const LinearCorrection fit = FitLinearCorrection({{1030.0, 1000.0}, {2050.0, 2000.0}});
  EXPECT_NEAR(fit.a, 1.02, 1e-12);
  EXPECT_NEAR(fit.b_mm, 10.0, 1e-9);
  EXPECT_NEAR(fit.rms_mm, 0.0, 1e-9);
  EXPECT_THROW(FitLinearCorrection({}), std::invalid_argument);
  EXPECT_THROW(FitLinearCorrection({{1000.0, 1000.0}}), std::invalid_argument);
  EXPECT_THROW(FitLinearCorrection({{1000.0, 1000.0}, {1010.0, 1000.0}}), std::invalid_argument);
  EXPECT_THROW(FitLinearCorrection({{2000.0, 1000.0}, {1000.0, 2000.0}}), std::invalid_argument);
  EXPECT_THROW(FitLinearCorrection({{NAN, 1000.0}, {1000.0, 2000.0}}), std::invalid_argument);
}

// Eq. 3-1 by hand: squares 0.01^2 + 0.01^2 + 0.03^2 = 0.0011, E = sqrt(0.0011) / 2.
TEST(AccumulatedErrorTest, MatchesTheThesisFormula) {
  EXPECT_NEAR(AccumulatedError({{1.01, 0.99}, {2.03}}, {1.0, 2.0}), 0.016583124, 1e-9);
  EXPECT_DOUBLE_EQ(AccumulatedError({{1.0, 1.0}}, {1.0}), 0.0);
  EXPECT_THROW(AccumulatedError({}, {}), std::invalid_argument);
  EXPECT_THROW(AccumulatedError({{1.0}}, {1.0, 2.0}), std::invalid_argument);
}

class DepthPairsCsvTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& text) {
    const std::string path = ::testing::TempDir() + "/depth_pairs_" +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                             ".csv";
    std::ofstream(path) << text;
    return path;
  }

  // The message of the std::invalid_argument the file throws, "" if none.
  std::string ErrorOf(const std::string& text) {
    try {
      ReadDepthPairsCsv(Write(text));
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  }
};

TEST_F(DepthPairsCsvTest, ReadsMillimetresAndMetres) {
  const auto mm =
      ReadDepthPairsCsv(Write("measured_mm,true_mm\n1040,1000\n\n# comment\n2080, 2000\r\n"));
  ASSERT_EQ(mm.size(), 2u);
  EXPECT_DOUBLE_EQ(mm[1].first, 2080.0);
  EXPECT_DOUBLE_EQ(mm[1].second, 2000.0);
  const auto m = ReadDepthPairsCsv(Write("measured_m,true_m\n1.04,1.0\n"));
  ASSERT_EQ(m.size(), 1u);
  EXPECT_DOUBLE_EQ(m[0].first, 1040.0);
  EXPECT_DOUBLE_EQ(m[0].second, 1000.0);
}

TEST_F(DepthPairsCsvTest, ErrorsNameTheFileAndLine) {
  const std::string bad_number = ErrorOf("measured_mm,true_mm\n1040,1000\n10x0,2000\n");
  EXPECT_NE(bad_number.find(".csv:3:"), std::string::npos) << bad_number;
  EXPECT_NE(bad_number.find("10x0"), std::string::npos) << bad_number;
  EXPECT_NE(ErrorOf("measured_mm,true_mm\n1040\n").find(".csv:2: expected two"), std::string::npos);
  EXPECT_NE(ErrorOf("measured_mm,true_mm\n1040,1000,5\n").find(".csv:2:"), std::string::npos);
  EXPECT_NE(ErrorOf("measured_mm,true_mm\n1040,\n").find(".csv:2:"), std::string::npos);
  EXPECT_NE(ErrorOf("measured_mm,true_mm\n-5,1000\n").find(".csv:2: depths must be positive"),
            std::string::npos);
  EXPECT_NE(ErrorOf("depth,truth\n1,2\n").find(".csv:1: expected the header"), std::string::npos);
  EXPECT_NE(ErrorOf("").find(".csv:1: empty file"), std::string::npos);
  EXPECT_NE(ErrorOf("measured_mm,true_mm\n").find("no data rows"), std::string::npos);
  try {
    ReadDepthPairsCsv("/nonexistent/pairs.csv");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/pairs.csv: cannot open"), std::string::npos);
  }
}

class DepthToPointsTest : public ::testing::Test {
 protected:
  DepthToPointsTest() : camera_(field::LoadRobotConfig("thesis_robot").camera) {}
  cv::Mat Depth(int type, double value) const {
    return cv::Mat(camera_.config().height_px, camera_.config().width_px, type, cv::Scalar(value));
  }
  CameraModel camera_;
};

TEST_F(DepthToPointsTest, BackProjectsEveryPixelWithDepth) {
  cv::Mat depth = Depth(CV_16UC1, 1000);
  depth.at<uint16_t>(10, 20) = 0;  // no reading
  const auto raw = DepthToPoints(depth, camera_, false);
  EXPECT_EQ(raw.size(), static_cast<size_t>(depth.total() - 1));
  EXPECT_DOUBLE_EQ(raw.front().z(), 1.0);
  EXPECT_NEAR(raw.front().x(), (0.5 - camera_.config().cx) / camera_.config().fx, 1e-12);
  const auto corrected = DepthToPoints(depth, camera_, true);
  EXPECT_DOUBLE_EQ(corrected.front().z(), camera_.CorrectDepthM(1000));
  const auto strided = DepthToPoints(depth, camera_, false, 4);
  EXPECT_EQ(strided.size(), static_cast<size_t>(((depth.rows + 3) / 4) * ((depth.cols + 3) / 4)));
}

TEST_F(DepthToPointsTest, RejectsWrongImagesWithAClearMessage) {
  try {
    DepthToPoints(Depth(CV_8UC1, 100), camera_, true);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("got 8UC1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(DepthToPoints(Depth(CV_8UC3, 100), camera_, true), std::invalid_argument);
  EXPECT_THROW(DepthToPoints(cv::Mat(), camera_, true), std::invalid_argument);
  EXPECT_THROW(DepthToPoints(cv::Mat(10, 10, CV_16UC1, cv::Scalar(1000)), camera_, true),
               std::invalid_argument);
  EXPECT_THROW(DepthToPoints(Depth(CV_16UC1, 1000), camera_, true, 0), std::invalid_argument);
}

// The levelled frame undoes the mount's pitch: the camera's optical axis, 15 deg down,
// becomes (0, sin 15, cos 15), and a point on the floor is dropped.
TEST_F(DepthToPointsTest, LevelledFrameUndoesThePitch) {
  const Eigen::Vector3d axis = LevelledFromCamera(camera_) * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(axis.x(), 0.0, 1e-12);
  EXPECT_NEAR(axis.y(), std::sin(15.0 * kDegToRad), 1e-12);
  EXPECT_NEAR(axis.z(), std::cos(15.0 * kDegToRad), 1e-12);
  const double on_floor = 0.5 / std::sin(15.0 * kDegToRad);  // along the axis
  const auto kept = LevelAboveFloor({{0, 0, on_floor}, {0, 0, 1.0}}, camera_, 0.03);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_NEAR(kept[0].z(), std::cos(15.0 * kDegToRad), 1e-12);
}

// End to end on the simulator: the robot at (1.0, 0) faces the +x perimeter wall (inner face
// at x = 1.783); the camera, 0.1 m ahead of the centre, is 0.683 m from it along the floor.
// Pitched 15 deg down it sees the wall in the middle rows, the floor below and nothing over
// the 0.3 m wall: levelling and dropping the floor leaves the wall, whose plane distance
// after the depth correction is the truth within 1 cm (the raw depth reads ~26 mm long).
TEST(DepthCalibrationSimTest, WallDistanceFromARenderedFrame) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  platform::SimWorld world = platform::CreateWorld(season, 1);
  world.objects.clear();
  world.opponents.clear();
  platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{}, 3);
  const platform::RgbdFrame frame =
      renderer.Render(world, platform::Pose2D{1.0, 0.0, 0.0}, 0.0, nullptr);
  const CameraModel camera(robot.camera);
  const double truth_m = season.HalfSize() - (1.0 + robot.camera.mount.x_m);

  const std::optional<PlaneFit> fit = FitPlaneRansac(
      LevelAboveFloor(DepthToPoints(frame.depth_mm, camera, true), camera, 0.03), {});
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->distance_m, truth_m, 0.01);
  EXPECT_LT(AngleDeg(fit->plane.head<3>(), Eigen::Vector3d(0, 0, -1)), 1.0);
  EXPECT_GT(fit->inliers, 10000);

  const std::optional<PlaneFit> raw = FitPlaneRansac(
      LevelAboveFloor(DepthToPoints(frame.depth_mm, camera, false), camera, 0.03), {});
  ASSERT_TRUE(raw.has_value());
  EXPECT_GT(raw->distance_m - truth_m, 0.015);
}

}  // namespace
}  // namespace slamo::vision
