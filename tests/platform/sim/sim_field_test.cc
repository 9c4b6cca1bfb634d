#include "platform/sim/sim_field.h"

#include <gtest/gtest.h>

#include <cmath>

#include "field_configs/loader.h"
#include "platform/drive_script.h"
#include "platform/sim/sim_drive_script.h"
#include "platform/sim/sim_renderer.h"

namespace slamo::platform {
namespace {

using field::Alliance;

// Toss Up with only the objects a test places, driven from an open spot.
class SimFieldTest : public ::testing::Test {
 protected:
  SimFieldTest() : robot_(field::LoadRobotConfig("thesis_robot")) {
    season_ = field::LoadSeasonConfig("toss_up");
    season_.objects.clear();
  }

  void Place(const std::string& type, const std::string& colour, double x, double y) {
    field::ObjectPlacement p;
    p.type = type;
    p.colour = colour;
    p.position_m = field::Vec2{x, y};
    season_.objects.push_back(p);
  }

  // Drives a script on the field (objects and opponents move with the robot).
  std::vector<DriveStepResult> Drive(SimField* field, const std::string& script) {
    SimClock clock;
    return RunDriveScript(ParseDriveScript(script), DriveControllerOptionsFor(robot_.drive),
                          &field->drive(), &clock, [field](double dt) { field->Step(dt); });
  }

  static double Distance(const Eigen::Vector3d& a, double x, double y) {
    return std::hypot(a.x() - x, a.y() - y);
  }

  field::SeasonConfig season_;
  field::RobotConfig robot_;
};

TEST_F(SimFieldTest, RobotPushesABallInItsWay) {
  Place("buckyball", "red", -0.3, -0.6);  // on the bump line, 0.6 m ahead of the start
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{-0.9, -0.6, 0.0});
  Drive(&field, "forward 0.8");
  const SimObject& ball = field.world().objects[0];
  const Pose2D& robot = field.robot_pose();
  EXPECT_GT(robot.x_m, -0.3);  // the robot drove through the ball's start...
  // ...and the ball went ahead of it, touching the bumper, not overlapping it.
  const double ahead = ball.center_m.x() - robot.x_m;
  EXPECT_GE(ahead, robot_.length_m / 2.0 + 0.0635 - 0.01);
  EXPECT_LE(ahead, robot_.length_m / 2.0 + 0.0635 + 0.03);
  EXPECT_NEAR(ball.center_m.y(), robot.y_m, 0.08);
}

TEST_F(SimFieldTest, BallPinnedAgainstTheWallStopsTheRobot) {
  // The robot drives along the left wall (x = -1.783) into the corner, where a ball lies
  // against the side wall (y = -1.783). It cannot roll out past the bumper's wall side, and a
  // post blocks the other side: pinned, it stops the robot.
  const double x = -season_.HalfSize() + robot_.width_m / 2.0 + 0.01;
  Place("buckyball", "red", x, -1.70);
  field::Structure post;
  post.name = "post";
  post.shape = field::SolidShape::kCylinder;
  post.center_m = field::Vec2{x + robot_.width_m / 2.0 + 0.0635 + 0.03, -1.70};
  post.radius_m = 0.03;
  post.height_m = 0.5;
  season_.structures.push_back(post);
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{x, -1.1, -kPi / 2.0});
  Drive(&field, "forward 0.6");
  const SimObject& ball = field.world().objects[0];
  EXPECT_GE(std::abs(ball.center_m.y()), 1.70 - 1e-9);  // never pushed into the wall
  EXPECT_LE(std::abs(ball.center_m.y()), season_.HalfSize() - 0.0635 + 1e-9);
  // The robot stopped with the ball between its bumper and the wall.
  EXPECT_GT(field.robot_pose().y_m, -1.70 + robot_.length_m / 2.0);
}

TEST_F(SimFieldTest, PinnedBallWithAFreeSideRollsOutPastTheBumper) {
  // The same ball against the side wall, met in the open: it rolls out past the bumper's side
  // and the robot drives on to the wall.
  Place("buckyball", "red", -0.9, -1.70);
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{-0.9, -1.1, -kPi / 2.0});
  Drive(&field, "forward 0.6");
  const SimObject& ball = field.world().objects[0];
  EXPECT_GT(std::abs(ball.center_m.x() + 0.9), robot_.width_m / 2.0);
  EXPECT_LT(field.robot_pose().y_m, -1.70 + robot_.length_m / 2.0);
}

// Toss Up's barrier (x = 0.61, raised 0.30 m): a large ball on it scores nothing there; the
// thesis robot (0.60 m tall) cannot pass under it, but driving into the barrier knocks the ball
// off into the goal zone (5 points for red).
TEST_F(SimFieldTest, LargeBallKnockedOffTheBarrierScoresInTheGoalZone) {
  Place("large_ball", "red", 0.61, 1.0);
  season_.objects.back().z_m = 0.35;
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{0.0, 1.0, 0.0});
  EXPECT_EQ(field.Score(Alliance::kRed), 0);
  Drive(&field, "forward 0.5");
  // Stopped by the barrier: the body never went under it.
  EXPECT_LT(field.robot_pose().x_m + robot_.length_m / 2.0, 0.585 + 0.01);
  const SimObject& ball = field.world().objects[0];
  EXPECT_GT(ball.center_m.x(), 0.635);         // off the barrier's far side
  EXPECT_NEAR(ball.center_m.z(), 0.20, 1e-6);  // on the floor
  EXPECT_EQ(field.Score(Alliance::kRed), 5);
}

// A robot lower than the barrier's underside drives under it, and so does a buckyball it pushes.
TEST_F(SimFieldTest, LowRobotDrivesUnderTheBarrier) {
  robot_.height_m = 0.25;
  Place("buckyball", "red", 0.40, 0.0);  // between the stashes
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{0.0, 0.0, 0.0});
  Drive(&field, "forward 0.9");
  EXPECT_GT(field.robot_pose().x_m, 0.61);                 // its centre past the barrier's line
  EXPECT_GT(field.world().objects[0].center_m.x(), 0.61);  // pushed into the goal zone
  EXPECT_EQ(field.Score(Alliance::kRed), 2);
}

TEST_F(SimFieldTest, IntakePicksOnlyWithinReachInFront) {
  Place("buckyball", "red", -0.9 + 0.225 + 0.0635 + 0.05, -0.6);  // 5 cm ahead of the bumper
  Place("buckyball", "blue", -0.9 - 0.5, -0.6);                   // behind the robot
  Place("buckyball", "blue", -0.9 + 0.8, -0.6);                   // too far ahead
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{-0.9, -0.6, 0.0});
  const std::optional<int> picked = field.Pick();
  ASSERT_TRUE(picked.has_value());
  EXPECT_EQ(*picked, 1);
  EXPECT_TRUE(field.world().objects[0].held);
  EXPECT_EQ(field.HeldCount(), 1);
  EXPECT_FALSE(field.Pick().has_value());  // capacity 1
  ASSERT_TRUE(field.Release().has_value());
  EXPECT_FALSE(field.Pick().has_value() && field.world().objects[1].held);  // behind: never
}

TEST_F(SimFieldTest, ReleaseInTheGoalZoneScoresByTheRules) {
  // The robot faces the far wall from inside the goal zone (x > 0.61 in Toss Up).
  Place("buckyball", "red", 1.0 + 0.225 + 0.0635 + 0.03, 1.5);
  Place("buckyball", "blue", 1.0 + 0.225 + 0.0635 + 0.03, -1.5);
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{1.0, 1.5, 0.0});
  const int before_red = field.Score(Alliance::kRed);
  ASSERT_TRUE(field.Pick().has_value());
  EXPECT_EQ(field.Score(Alliance::kRed), before_red - 2);  // held: it no longer counts
  const std::optional<ReleaseResult> released = field.Release();
  ASSERT_TRUE(released.has_value());
  ASSERT_TRUE(released->goal_index.has_value());
  EXPECT_EQ(season_.goals[*released->goal_index].name, "goal_zone");
  EXPECT_EQ(released->points, 2);  // a red buckyball in the goal zone, for red
  EXPECT_EQ(field.Score(Alliance::kRed), before_red);
  // Own-colour rule: the blue ball in the goal zone earns red nothing, blue 2.
  EXPECT_EQ(field.ObjectPoints(field.world().objects[1], Alliance::kRed), 0);
  EXPECT_EQ(field.ObjectPoints(field.world().objects[1], Alliance::kBlue), 2);
}

TEST_F(SimFieldTest, ReleaseOverTheStashScoresTheGoal) {
  // The red stash is a cylinder at (0.78, 0.61), radius 0.14, beyond the barrier: drop into it
  // from the goal zone, facing west.
  Place("buckyball", "red", 0.78 + 0.14 + 0.30 - 0.05, 0.61);
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{0.78 + 0.14 + 0.30 + 0.225, 0.61, kPi});
  ASSERT_TRUE(field.Pick().has_value());
  // Drive up to the stash (the ball is held, so the bumper reaches the goal).
  Drive(&field, "forward 0.35");  // stops against the stash
  const std::optional<ReleaseResult> released = field.Release();
  ASSERT_TRUE(released.has_value());
  ASSERT_TRUE(released->goal_index.has_value());
  EXPECT_EQ(season_.goals[*released->goal_index].name, "red_stash");
  EXPECT_EQ(released->points, 5);
}

// Push Back's long goals are tubes blocks enter through their ends (entry: ends): a block
// released from the tube's side stays in the intake; from the end, facing along the tube, it
// goes in and scores 3.
TEST(SimFieldPushBackTest, ABlockGoesIntoALongGoalThroughItsEndOnly) {
  field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  season.objects.clear();
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  const double r = 0.081 / 2.0;
  const double bumper = robot.length_m / 2.0;
  const auto block_ahead = [&](const Pose2D& pose) {
    field::ObjectPlacement p;
    p.type = "block";
    p.colour = "red";
    p.position_m = field::Vec2{pose.x_m + (bumper + r + 0.02) * std::cos(pose.theta_rad),
                               pose.y_m + (bumper + r + 0.02) * std::sin(pose.theta_rad)};
    field::SeasonConfig s = season;
    s.objects.push_back(p);
    return s;
  };
  // The long goal at y = -1.198 runs x = -0.62..0.62, 0.14 m wide. From the field side, the
  // bumper 1.5 cm short of its side, the drop lands inside the tube's footprint.
  const Pose2D side{0.0, -1.198 + 0.07 + 0.015 + bumper, -kPi / 2.0};
  const field::SeasonConfig at_side = block_ahead(side);
  SimField from_side(at_side, robot, Alliance::kRed, 1, side);
  ASSERT_TRUE(from_side.Pick().has_value());
  EXPECT_FALSE(from_side.Release().has_value()) << "no way in through the tube's side";
  EXPECT_EQ(from_side.HeldCount(), 1);
  // At the -x end, facing +x, the bumper 1.5 cm short of the mouth.
  const Pose2D end{-0.62 - 0.015 - bumper, -1.198, 0.0};
  const field::SeasonConfig at_end = block_ahead(end);
  SimField from_end(at_end, robot, Alliance::kRed, 1, end);
  ASSERT_TRUE(from_end.Pick().has_value());
  const std::optional<ReleaseResult> released = from_end.Release();
  ASSERT_TRUE(released.has_value());
  ASSERT_TRUE(released->goal_index.has_value());
  EXPECT_EQ(season.goals[*released->goal_index].name, "long_goal_right");
  EXPECT_EQ(released->points, 3);
}

// Over Under: a triball pushed along the floor in under a goal's front bar (the frame 0.16 m
// up, a triball 0.157 m tall) is in the goal and scores 5, as a released one; the robot, taller
// than the bar, stops at it. Before, only a release put anything in a goal, and the triballs
// the robot pushed under the net still counted as lying in the offensive zone (2).
TEST(SimFieldOverUnderTest, ATriballPushedUnderTheGoalsBarIsInTheGoal) {
  field::SeasonConfig season = field::LoadSeasonConfig("over_under");
  season.objects.clear();
  season.opponents.clear();
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  field::ObjectPlacement p;
  p.type = "triball";
  p.colour = "green";
  p.position_m = field::Vec2{0.85, 0.05};
  season.objects.push_back(p);
  SimField field(season, robot, Alliance::kRed, 1, Pose2D{0.35, 0.05, 0.0});
  EXPECT_EQ(field.Score(Alliance::kRed), 2);  // in the red offensive zone
  SimClock clock;
  RunDriveScript(ParseDriveScript("forward 0.9"), DriveControllerOptionsFor(robot.drive),
                 &field.drive(), &clock, [&field](double dt) { field.Step(dt); });
  const SimObject& triball = field.world().objects[0];
  EXPECT_GT(triball.center_m.x(), 1.19);  // past the front bar
  EXPECT_GE(triball.in_goal, 0);
  EXPECT_EQ(field.Score(Alliance::kRed), 5);
  EXPECT_EQ(field.Score(Alliance::kBlue), 0);
  EXPECT_LT(field.robot_pose().x_m + robot.length_m / 2.0, 1.19 + 0.01);  // stopped at the bar
  // In the goal it is not pushed about any more: backing off leaves it there.
  const Eigen::Vector3d in = triball.center_m;
  RunDriveScript(ParseDriveScript("back 0.3"), DriveControllerOptionsFor(robot.drive),
                 &field.drive(), &clock, [&field](double dt) { field.Step(dt); });
  EXPECT_EQ((field.world().objects[0].center_m - in).norm(), 0.0);
  EXPECT_EQ(field.Score(Alliance::kRed), 5);
}

// High Stakes: a mobile goal's stake stands on its base and moves with it (on_object). A ring
// released with the bumper at the base, the stake within the intake's reach, goes onto the
// stake and scores 1, wherever the goal has been pushed to; before, the stakes stayed at the
// file's spots while the robot pushed the bases away, and releases went onto the floor.
TEST(SimFieldHighStakesTest, ARingGoesOntoTheStakeOfTheMobileGoalItWasPushedWith) {
  field::SeasonConfig season = field::LoadSeasonConfig("high_stakes");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  // Mobile goal 1 only, moved 0.3 m from its spot (-0.599, 0.599) as after a push, and a red
  // ring to take.
  season.objects.clear();
  field::ObjectPlacement goal;
  goal.type = "mobile_goal";
  goal.colour = "yellow";
  goal.position_m = field::Vec2{-0.899, 0.599};
  season.objects.push_back(goal);
  const double base_r = 0.264 / 2.0, bumper = robot.length_m / 2.0;
  const Pose2D pose{-0.899 - base_r - 0.015 - bumper, 0.599, 0.0};
  field::ObjectPlacement ring;  // the preload, under the robot
  ring.type = "ring";
  ring.colour = "red";
  ring.position_m = field::Vec2{pose.x_m, pose.y_m};
  season.objects.push_back(ring);
  // The goal follows its base: its stake is where the base was placed, not at the file's spot.
  int goal_index = -1;
  for (size_t g = 0; g < season.goals.size(); ++g)
    if (season.goals[g].name == "mobile_goal_1") goal_index = static_cast<int>(g);
  ASSERT_GE(goal_index, 0);
  SimFieldOptions options;
  options.preload = true;
  SimField field(season, robot, Alliance::kRed, 1, pose, {}, options);
  ASSERT_EQ(field.HeldCount(), 1);
  const std::optional<ReleaseResult> released = field.Release();
  ASSERT_TRUE(released.has_value());
  ASSERT_TRUE(released->goal_index.has_value());
  EXPECT_EQ(*released->goal_index, goal_index);
  EXPECT_EQ(released->points, 1);
  // Pushed on by the robot, the base carries the stake and the ring on it.
  SimClock clock;
  RunDriveScript(ParseDriveScript("forward 0.15"), DriveControllerOptionsFor(robot.drive),
                 &field.drive(), &clock, [&field](double dt) { field.Step(dt); });
  EXPECT_GT(field.world().objects[0].center_m.x(), -0.899 + 0.05);
  EXPECT_EQ(field.Score(Alliance::kRed), 1);
}

TEST_F(SimFieldTest, OpponentFollowsItsPathAndPushesObjects) {
  Place("buckyball", "blue", 0.0, 1.45);  // on the opponent's path
  field::OpponentRobot opponent;
  opponent.alliance = Alliance::kBlue;
  opponent.size_m = field::Vec2{0.4, 0.4};
  opponent.speed_mps = 0.5;
  opponent.path_m = {{-0.9, 1.45}, {1.3, 1.45}, {1.3, 0.0}};  // past the barrier's end
  season_.opponents = {opponent};
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{-0.9, -1.2, 0.0});
  for (int i = 0; i < 440; ++i) field.Step(0.01);  // 4.4 s: the 2.2 m first leg
  const SimOpponent& o = field.world().opponents[0];
  EXPECT_NEAR(o.pose.x_m, 1.3, 0.02);
  EXPECT_NEAR(o.pose.y_m, 1.45, 0.02);
  // The ball was shoved along in front of it, never left overlapping.
  const SimObject& ball = field.world().objects[0];
  EXPECT_GT(ball.center_m.x(), 0.5);
  EXPECT_GE(
      std::max(std::abs(ball.center_m.x() - o.pose.x_m), std::abs(ball.center_m.y() - o.pose.y_m)),
      0.2 + 0.0635 - 1e-6);
  for (int i = 0; i < 400; ++i) field.Step(0.01);
  EXPECT_NEAR(field.world().opponents[0].pose.y_m, 0.0, 0.02);  // finished, no loop
  EXPECT_NEAR(field.world().opponents[0].pose.x_m, 1.3, 0.02);
}

TEST_F(SimFieldTest, OpponentIsRendered) {
  field::OpponentRobot opponent;
  opponent.alliance = Alliance::kBlue;
  opponent.size_m = field::Vec2{0.4, 0.4};
  opponent.speed_mps = 0.3;
  opponent.path_m = {{0.0, -0.6}, {0.0, 0.6}};
  season_.opponents = {opponent};
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{-1.2, -0.6, 0.0});
  SimRenderer renderer(season_, robot_.camera, RenderOptions{}, 1);
  FrameTruth truth;
  renderer.Render(field.world(), field.robot_pose(), 0.0, &truth);
  EXPECT_GT(cv::countNonZero(truth.ids == kOpponentIdBase), 1000);
}

TEST_F(SimFieldTest, RobotCannotDriveThroughAnOpponent) {
  field::OpponentRobot opponent;
  opponent.alliance = Alliance::kBlue;
  opponent.size_m = field::Vec2{0.4, 0.4};
  opponent.speed_mps = 0.1;
  opponent.path_m = {{0.0, -0.6}, {0.0, -0.6001}};  // parked
  season_.opponents = {opponent};
  SimField field(season_, robot_, Alliance::kRed, 1, Pose2D{-0.9, -0.6, 0.0});
  Drive(&field, "forward 1.2");
  EXPECT_LE(field.robot_pose().x_m, -0.2 - 0.225 + 0.01);
}

}  // namespace
}  // namespace slamo::platform
