#include "vision/camera_model.h"

#include <gtest/gtest.h>

#include "field_configs/loader.h"

namespace slamo::vision {
namespace {

TEST(CameraModelTest, BackProjectionIsTheThesisFormulaAndInvertsProjection) {
  const CameraModel camera(field::LoadRobotConfig("thesis_robot").camera);
  const Eigen::Vector3d p = camera.BackProject(300.0, 100.0, 2.0);
  EXPECT_NEAR(p.x(), (300.0 - 254.878) * 2.0 / 365.456, 1e-12);
  EXPECT_NEAR(p.y(), (100.0 - 205.390) * 2.0 / 365.456, 1e-12);
  EXPECT_DOUBLE_EQ(p.z(), 2.0);
  const Eigen::Vector2d uv = camera.Project(p);
  EXPECT_NEAR(uv.x(), 300.0, 1e-9);
  EXPECT_NEAR(uv.y(), 100.0, 1e-9);
}

TEST(CameraModelTest, DepthCorrectionUndoesTheLinearError) {
  const CameraModel camera(field::LoadRobotConfig("thesis_robot").camera);
  const double a = camera.config().depth_correction.a, b = camera.config().depth_correction.b_mm;
  EXPECT_NEAR(camera.CorrectDepthM(a * 1500.0 + b), 1.5, 1e-12);
}

// The optical axis of the thesis robot's camera (pitched 15 deg down, 0.5 m up, 0.1 m
// forward) meets the floor 0.5 / tan(15 deg) ahead of the camera.
TEST(CameraModelTest, CameraToRobotFollowsTheMount) {
  const CameraModel camera(field::LoadRobotConfig("thesis_robot").camera);
  const double pitch = 15.0 * M_PI / 180.0;
  const double along_axis = 0.5 / std::sin(pitch);
  const Eigen::Vector3d floor_point =
      camera.CameraToRobot(camera.BackProject(camera.config().cx, camera.config().cy, along_axis));
  EXPECT_NEAR(floor_point.z(), 0.0, 1e-9);
  EXPECT_NEAR(floor_point.x(), 0.1 + 0.5 / std::tan(pitch), 1e-9);
  EXPECT_NEAR(floor_point.y(), 0.0, 1e-9);
}

TEST(CameraModelTest, ScaledIntrinsics) {
  const CameraModel camera(field::LoadRobotConfig("thesis_robot").camera);
  const CameraModel big = camera.Scaled(1024, 848);
  EXPECT_DOUBLE_EQ(big.config().fx, 2.0 * camera.config().fx);
  EXPECT_DOUBLE_EQ(big.config().cy, 2.0 * camera.config().cy);
}

}  // namespace
}  // namespace slamo::vision
