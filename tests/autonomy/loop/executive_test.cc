// The executive end to end on the simulated field: a full dry run, and the deadline rules.
#include "autonomy/loop/executive.h"
#include "autonomy/io/sim_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "autonomy/loop/match_world.h"
#include "autonomy/reports/match_report.h"
#include "field_configs/loader.h"
#include "platform/field_geometry.h"

namespace slamo::autonomy {
namespace {

TEST(Executive, FullDryRunScoresWithinTheDeadlineAndMapsItsObjects) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  MatchSetup setup;  // the planner strategy, covariance frame rule
  const std::string dir = ::testing::TempDir() + "/executive_dry_run";
  std::filesystem::create_directories(dir);
  const MatchResult r = RunMatch(season, robot, setup, 3, dir);

  EXPECT_EQ(r.deadline_s, 45.0);
  EXPECT_GT(r.points, 0);
  EXPECT_GT(r.points, r.points_start) << "seed 3 scores its preload (measured +4)";
  EXPECT_EQ(r.overrun_s, 0.0);
  EXPECT_LE(r.duration_s, r.deadline_s);
  // Measured 0.038 m for this seed; the bound leaves room for numerical differences.
  EXPECT_LT(r.pose_ate_m, 0.10);
  EXPECT_GE(r.samples.size(), 20u);
  ASSERT_FALSE(r.objects.empty());
  int matched = 0;
  for (const ObjectReport& o : r.objects) matched += o.matched ? 1 : 0;
  EXPECT_GE(matched, static_cast<int>(r.objects.size()) / 2);
  ASSERT_FALSE(r.timeline.empty());
  EXPECT_EQ(r.timeline.front().action, "OBSERVE");
  for (const TimelineEntry& t : r.timeline) {
    EXPECT_LE(t.t_s, t.end_s);
    EXPECT_LE(t.t_s, r.deadline_s);
  }

  // The report files a dry run writes.
  const nlohmann::json j = ReportJson(r);
  for (const char* key : {"season", "seed", "strategy", "points", "duration_s", "deadline_s",
                          "pose_ate_m", "objects", "timeline"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["season"], "toss_up");
  EXPECT_EQ(j["strategy"], "planner");
  for (const auto& o : j["objects"]) {
    for (const char* key : {"class", "est_x", "est_y", "true_x", "true_y"})
      EXPECT_TRUE(o.contains(key)) << key;
  }
  for (const auto& t : j["timeline"]) {
    EXPECT_TRUE(t.contains("t_s"));
    EXPECT_TRUE(t.contains("action"));
  }
  // The filter against the truth: every update's NEES, every pick/score attempt's error.
  ASSERT_TRUE(j.contains("nees"));
  EXPECT_EQ(j["nees"]["updates"].get<int>(), static_cast<int>(r.samples.size()));
  EXPECT_EQ(j["nees"]["in_band"].get<int>() + j["nees"]["conservative"].get<int>() +
                j["nees"]["overconfident"].get<int>(),
            j["nees"]["updates"].get<int>());
  ASSERT_EQ(j["updates"].size(), r.samples.size());
  int picks_and_scores = 0;  // and knocks: the push of a knock
  for (const TimelineEntry& t : r.timeline)
    picks_and_scores += t.action == "PICK" || t.action == "SCORE" ||
                        (t.action == "NAVIGATE" && t.detail.rfind("knock ", 0) == 0);
  ASSERT_EQ(j["attempts"].size(), static_cast<size_t>(picks_and_scores));
  EXPECT_GT(picks_and_scores, 0);
  for (const auto& a : j["attempts"]) {
    EXPECT_EQ(a["inside_three_sigma"].get<bool>(),
              a["error_m"].get<double>() <= a["three_sigma_m"].get<double>());
    EXPECT_GT(a["three_sigma_m"].get<double>(), 0.0);
    // Judged on the simulator's objects: a pick that took its target reported success, one
    // that took nothing did not; a release scored exactly when it reported so.
    const std::string outcome = a["outcome"].get<std::string>();
    const bool ok = a["ok"].get<bool>();
    if (a["action"] == "PICK") {
      EXPECT_NE(std::find(PickOutcomes().begin(), PickOutcomes().end(), outcome),
                PickOutcomes().end())
          << outcome;
      if (outcome == "target") {
        EXPECT_TRUE(ok);
      }
      if (outcome == "nothing") {
        EXPECT_FALSE(ok);
      }
    } else if (a["action"] == "KNOCK") {
      // Judged by where the object is after the push, whatever the drive reported.
      EXPECT_NE(std::find(KnockOutcomes().begin(), KnockOutcomes().end(), outcome),
                KnockOutcomes().end())
          << outcome;
    } else {
      EXPECT_EQ(outcome == "scored", ok) << outcome;
    }
    EXPECT_GT(a["range_m"].get<double>(), 0.0);
  }
  WriteTum(r, dir + "/trajectory.tum");
  std::ifstream tum(dir + "/trajectory.tum");
  std::string line;
  size_t poses = 0;
  while (std::getline(tum, line)) poses += (!line.empty() && line[0] != '#') ? 1 : 0;
  EXPECT_EQ(poses, r.samples.size());
  EXPECT_GT(std::filesystem::file_size(dir + "/objects.bt"), 0u);
  EXPECT_FALSE(DrawMatchMap(r).empty());
}

// Where each update's NEES falls against one update's 95 % band [0.22, 9.35] (3 dof).
TEST(Executive, PoseConsistencyCountsTheBandConservativeAndOverconfident) {
  const Eigen::Matrix3d covariance = Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal();
  const auto sample = [&](double sigmas) {
    PoseSample s;
    s.truth = Eigen::Vector3d(1.0, 2.0, 0.3);
    s.estimate = s.truth + Eigen::Vector3d(0.1, 0.1, 0.1) * sigmas;  // NEES 3 sigmas^2
    s.covariance = covariance;
    return s;
  };
  PoseSample unknown = sample(10.0);
  unknown.truth_known = false;  // hardware: not counted
  const PoseConsistency c =
      PoseConsistencyOf({sample(0.1), sample(1.0), sample(1.5), sample(3.0), unknown});
  EXPECT_EQ(c.updates, 4);
  EXPECT_EQ(c.below, 1);    // NEES 0.03: conservative
  EXPECT_EQ(c.in_band, 2);  // 3 and 6.75
  EXPECT_EQ(c.above, 1);    // 27: overconfident
  EXPECT_DOUBLE_EQ(c.HonestFraction(), 0.75);
  EXPECT_NEAR(c.band_low, 0.216, 1e-3);
  EXPECT_NEAR(c.band_high, 9.348, 1e-3);
}

// One pick at `aim`, aimed at an object of `kind` (red), then nothing.
class PickOnce : public strategy::Strategy {
 public:
  PickOnce(Eigen::Vector2d aim, std::string kind) : aim_(aim), kind_(std::move(kind)) {}
  std::string name() const override { return "pick-once"; }
  bool perceives() const override { return false; }
  strategy::Action Next(const strategy::Belief&, const strategy::StrategyContext&) override {
    strategy::Action a;
    if (done_) return a;
    done_ = true;
    a.kind = strategy::ActionKind::kPick;
    a.target = Eigen::Vector3d(aim_.x(), aim_.y(), 0.0);
    a.object_kind = kind_;
    a.object_colour = "red";
    a.expected_s = 4.0;
    return a;
  }
  void Feedback(const strategy::Action&, bool) override {}

 private:
  Eigen::Vector2d aim_;
  std::string kind_;
  bool done_ = false;
};

// What a pick took, judged on the simulator's objects: the object the strategy aimed at,
// another one, or nothing. The field holds one red buckyball 0.8 m ahead of the start (or
// none), and the robot, preload-free, picks there once.
TEST(Executive, APickIsJudgedByTheObjectTheIntakeTook) {
  field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  season.rules.autonomous_s = 10.0;
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  const platform::Pose2D start = platform::StartPose(season, field::Alliance::kRed, 0);
  const Eigen::Vector2d ahead(start.x_m + 0.8 * std::cos(start.theta_rad),
                              start.y_m + 0.8 * std::sin(start.theta_rad));
  field::ObjectPlacement ball;
  ball.type = "buckyball";
  ball.colour = "red";
  ball.position_m = field::Vec2{ahead.x(), ahead.y()};
  MatchSetup setup;
  setup.placement_jitter_m = 0.0;
  const auto pick = [&](bool with_ball, const std::string& kind) {
    field::SeasonConfig s = season;
    s.objects.clear();
    if (with_ball) s.objects.push_back(ball);
    const MatchResult r = RunMatchWith(std::make_unique<PickOnce>(ahead, kind), s, robot, setup, 1);
    EXPECT_EQ(r.attempts.size(), 1u);
    return r.attempts.empty() ? AttemptCheck{} : r.attempts.front();
  };
  const AttemptCheck target = pick(true, "buckyball");
  EXPECT_EQ(target.outcome, "target");
  EXPECT_TRUE(target.ok);
  EXPECT_GE(target.target_truth_id, 1);
  EXPECT_LT(target.target_error_m, 1e-9);  // no jitter: the aim is the ball's centre
  EXPECT_NEAR(target.range_m, 0.8, 1e-6);
  EXPECT_NEAR(target.bearing_rad, 0.0, 1e-6);
  EXPECT_EQ(target.kind, "buckyball");
  // Aimed at a large ball where only a buckyball lies: the intake takes the buckyball.
  const AttemptCheck other = pick(true, "large_ball");
  EXPECT_EQ(other.outcome, "other");
  EXPECT_EQ(other.target_truth_id, -1);
  const AttemptCheck nothing = pick(false, "buckyball");
  EXPECT_EQ(nothing.outcome, "nothing");
  EXPECT_FALSE(nothing.ok);
}

// A knock is judged by where the ball is after the push: the scripted route knocks both red
// large balls off the barrier (raised objects are not jittered, so its aim is exact), and the
// bumper, stopped just short of the barrier, pushes them off the top into the goal zone. (In
// seed 1 the drive to the second knock brings that ball down first: no ball is left up there
// to aim at, and that knock took "nothing".)
TEST(Executive, AKnockIsJudgedByWhereTheBallCameDown) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  MatchSetup setup;
  setup.strategy = "scripted";
  const MatchResult r = RunMatch(season, robot, setup, 1);
  int knocks = 0, scored = 0;
  for (const AttemptCheck& a : r.attempts) {
    if (a.action != "KNOCK") continue;
    ++knocks;
    EXPECT_EQ(a.kind, "large_ball");
    EXPECT_EQ(a.colour, "red");
    if (a.target_truth_id >= 1) {
      EXPECT_LT(a.target_error_m, 1e-9);
    } else {
      EXPECT_EQ(a.outcome, "nothing");
    }
    scored += a.outcome == "scored";
  }
  EXPECT_EQ(knocks, 2);
  EXPECT_GE(scored, 1);
  EXPECT_GE(r.points - r.points_start, 10);
}

// A robot whose start lies inside the planner's clearance margin with its back to the wall
// (the V5-class robot on High Stakes' tiles) cannot back out of it: it drives out ahead, and
// its first navigation is planned (before, it reversed into the wall and no plan could start).
TEST(Executive, ARobotStartingInsideTheMarginDrivesOutAhead) {
  const field::SeasonConfig season = field::LoadSeasonConfig("high_stakes");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  MatchSetup setup;
  setup.strategy = "planner";
  const MatchResult r = RunMatch(season, robot, setup, 1);
  int navigations = 0, reached = 0;
  for (const TimelineEntry& t : r.timeline) {
    if (t.action != "NAVIGATE") continue;
    ++navigations;
    reached += t.ok;
  }
  EXPECT_GT(navigations, 0);
  EXPECT_GT(reached, 0);
}

// The robot and its strategy are told the season as its file has it; only the simulator
// knows where this seed's jitter put the objects (the scripted route plans from the nominal
// spots, as a team's would).
TEST(Executive, TheRobotIsToldTheSeasonFileNotThePlacement) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  MatchSetup setup;
  setup.strategy = "scripted";
  setup.placement_jitter_m = 0.15;
  const MatchResult r = RunMatch(season, robot, setup, 2);
  ASSERT_EQ(r.field.objects.size(), season.objects.size());
  for (size_t i = 0; i < season.objects.size(); ++i) {
    if (!season.objects[i].position_m) continue;
    EXPECT_EQ(r.field.objects[i].position_m->x, season.objects[i].position_m->x) << i;
    EXPECT_EQ(r.field.objects[i].position_m->y, season.objects[i].position_m->y) << i;
  }
  // ... while the simulator moved them: the first object's true spot is not its file's.
  const field::SeasonConfig placed = PlaceObjects(season, 0.15, 2);
  double moved = 0.0;
  for (size_t i = 0; i < season.objects.size(); ++i) {
    if (!season.objects[i].position_m) continue;
    moved = std::max(moved,
                     std::hypot(placed.objects[i].position_m->x - season.objects[i].position_m->x,
                                placed.objects[i].position_m->y - season.objects[i].position_m->y));
  }
  EXPECT_GT(moved, 0.05);
}

// The disturbed layout: every fixed-position floor object 0.3-0.8 m from its spot, clear of
// the walls and of what blocks it; preloads, raised objects and objects held in a structure
// (a loader) where the file puts them.
TEST(Executive, TheDisturbedLayoutMovesEveryLooseFloorObjectThirtyToEightyCentimetres) {
  for (const std::string name : {"toss_up", "high_stakes", "over_under", "push_back"}) {
    const field::SeasonConfig season = field::LoadSeasonConfig(name);
    for (uint64_t seed : {1, 2, 3}) {
      const field::SeasonConfig placed = PlaceObjects(season, 0.15, seed, Scenario::kDisturbed);
      ASSERT_EQ(placed.objects.size(), season.objects.size());
      int moved = 0, floor = 0, held_objects = 0;
      for (size_t i = 0; i < season.objects.size(); ++i) {
        const field::ObjectPlacement& p = season.objects[i];
        if (!p.position_m) continue;
        const Eigen::Vector2d from(p.position_m->x, p.position_m->y);
        const Eigen::Vector2d to(placed.objects[i].position_m->x, placed.objects[i].position_m->y);
        const double d = (to - from).norm();
        const bool preload =
            std::any_of(season.starts.begin(), season.starts.end(), [&](const field::StartTile& s) {
              return (from - Eigen::Vector2d(s.center_m.x, s.center_m.y)).norm() < 0.3;
            });
        const field::ObjectType* type = season.FindObjectType(p.type);
        ASSERT_NE(type, nullptr);
        // In a structure (Push Back's loader columns): held there, the whole stack.
        const bool held =
            (p.z_m <= 0.0 || p.stack_level > 0) &&
            platform::PointBlocksObject(season, from, type->size_m / 2.0, type->height_m);
        if (held) {
          ++held_objects;
          EXPECT_EQ(d, 0.0) << name << " object " << i;
          continue;
        }
        if (p.z_m > 0.0 || preload) {
          if (p.stack_level == 0) {
            EXPECT_EQ(d, 0.0) << name << " object " << i;
          }
          continue;
        }
        if (p.stack_level > 0) continue;  // follows its stack's bottom object
        ++floor;
        if (d == 0.0) continue;  // no clear spot found: left where it was (counted below)
        ++moved;
        EXPECT_GE(d, kDisturbMin_m - 1e-9) << name << " object " << i;
        EXPECT_LE(d, kDisturbMax_m + 1e-9) << name << " object " << i;
        EXPECT_LE(std::max(std::abs(to.x()), std::abs(to.y())),
                  season.HalfSize() - type->size_m / 2.0 + 1e-9)
            << name << " object " << i;
        EXPECT_FALSE(platform::PointBlocksObject(season, to, type->size_m / 2.0, type->height_m))
            << name << " object " << i;
      }
      EXPECT_GT(floor, 0) << name;
      EXPECT_GE(moved, floor * 9 / 10) << name << " seed " << seed;
      if (name == "push_back") {
        EXPECT_EQ(held_objects, 4 * 6) << "four loaders of 6";
      }
    }
  }
  // The nominal layout stays within its jitter along each axis.
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::SeasonConfig nominal = PlaceObjects(season, 0.15, 4, Scenario::kNominal);
  double largest = 0.0;
  for (size_t i = 0; i < season.objects.size(); ++i) {
    if (!season.objects[i].position_m) continue;
    largest = std::max(
        {largest, std::abs(nominal.objects[i].position_m->x - season.objects[i].position_m->x),
         std::abs(nominal.objects[i].position_m->y - season.objects[i].position_m->y)});
  }
  EXPECT_LE(largest, 0.15 + 1e-9);
  EXPECT_GT(largest, 0.05);
}

// A strategy that always asks to drive far away, claiming the drive takes `claimed_s`.
class FarAway : public strategy::Strategy {
 public:
  explicit FarAway(double claimed_s) : claimed_s_(claimed_s) {}
  std::string name() const override { return "far-away"; }
  strategy::Action Next(const strategy::Belief&, const strategy::StrategyContext&) override {
    strategy::Action a;
    a.kind = strategy::ActionKind::kNavigate;
    a.target = Eigen::Vector3d(0.2, -1.3, 0.0);  // across the field, this side of the barrier
    a.expected_s = claimed_s_;
    a.why = "far away";
    return a;
  }
  void Feedback(const strategy::Action&, bool) override {}

 private:
  double claimed_s_;
};

// A held object no goal takes for us is released at once, on the field's own intake: here
// the season is changed so that buckyballs score nothing, and the robot starts with one.
TEST(Executive, AnObjectThatScoresNothingIsDroppedToFreeTheIntake) {
  field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  season.rules.autonomous_s = 10.0;
  for (field::Goal& g : season.goals) g.points.erase("buckyball");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  for (const std::string strategy : {"planner", "greedy"}) {
    MatchSetup setup;
    setup.strategy = strategy;
    const MatchResult r = RunMatch(season, robot, setup, 1);
    ASSERT_GE(r.timeline.size(), 3u) << strategy;
    EXPECT_EQ(r.timeline[0].action, "OBSERVE") << strategy;  // the initial survey
    EXPECT_EQ(r.timeline[1].action, "DROP") << strategy;
    EXPECT_TRUE(r.timeline[1].ok) << strategy;
    // A turn aside and the release: no drive to anywhere first.
    EXPECT_LE(r.timeline[1].end_s - r.timeline[1].t_s, r.timeline[1].expected_s + 0.5) << strategy;
    for (size_t i = 2; i < r.timeline.size(); ++i) {
      EXPECT_NE(r.timeline[i].action, "DROP") << strategy << ": the intake is empty";
    }
  }
}

// The 15 s seasons with the V5 robot (#15): on seed 1 every strategy gained nothing. Over
// Under: the planner's grid took the 0.073 m barrier robots climb over for a wall, so no goal
// or zone of red's was reachable and the planner idled from 3 s. Push Back: releases went at
// the long goal's side, which blocks go in only through its ends.
TEST(Executive, TheV5RobotScoresInOverUnderAndPushBack) {
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  for (const std::string name : {"over_under", "push_back"}) {
    const field::SeasonConfig season = field::LoadSeasonConfig(name);
    for (const std::string strategy : {"planner", "scripted"}) {
      MatchSetup setup;
      setup.strategy = strategy;
      const MatchResult r = RunMatch(season, robot, setup, 1);
      EXPECT_GT(r.points, r.points_start) << name << " " << strategy;
      EXPECT_EQ(r.overrun_s, 0.0) << name << " " << strategy;
      int scored = 0;
      for (const AttemptCheck& a : r.attempts)
        scored += a.action == "SCORE" && a.outcome == "scored";
      EXPECT_GT(scored, 0) << name << " " << strategy << ": a release into a goal";
    }
  }
}

// Push Back seed 5 with the V5 robot, the planner without looks before cycles or arrival
// fixes: after its preload it picks a block beside the long goal and goes back to the
// goal's end. Before, it released from beside the tube's stage at an angle and missed; it now
// scores both. The way back is a short leg behind the robot: driven backwards it is shorter
// on the match clock than turning round twice.
TEST(Executive, TheV5RobotReentersALongGoalAlongItsAxisAndBacksUpShortLegs) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  const auto run = [&](double reverse_max_m) {
    MatchSetup setup;
    setup.strategy = "planner";
    setup.strategy_options.frame_choices = {0};
    // Sequences that fit or not, as when the seed was chosen: valued by their chance of ending
    // in time, the way back goes to the centre goal instead, whose estimate is shorter.
    setup.strategy_options.duration_spread = 0.0;
    setup.arrival_fixes = 0;
    setup.reverse_max_m = reverse_max_m;
    return RunMatch(season, robot, setup, 5);
  };
  const MatchResult backwards = run(0.6), forwards = run(0.0);
  int scored = 0;
  for (const AttemptCheck& a : backwards.attempts)
    scored += a.action == "SCORE" && a.outcome == "scored";
  EXPECT_EQ(scored, 2);
  EXPECT_EQ(backwards.overrun_s, 0.0);
  // The drive back to the goal after the pick, in both runs.
  const auto drive_back = [](const MatchResult& r) {
    bool picked = false;
    for (const TimelineEntry& t : r.timeline) {
      if (t.action == "PICK") picked = true;
      if (picked && t.action == "NAVIGATE") return t.end_s - t.t_s;
    }
    return -1.0;
  };
  ASSERT_GT(drive_back(backwards), 0.0);
  ASSERT_GT(drive_back(forwards), 0.0);
  EXPECT_LT(drive_back(backwards), drive_back(forwards) - 0.5);
}

// The drive of the commits that chose the seeds of the tests that call this: frames only at
// stops, a quick look every 1.2 m of path, legs held on the encoders. Frames while driving and
// steering from the estimate became the defaults later (README, #15) and take those seeds
// other courses; the tests keep the traces they were written on, each showing its own
// mechanism.
void DriveAsWhenSeedsWereChosen(MatchSetup* setup) {
  setup->moving_frame_period_s = 0.0;
  setup->steer_on_estimate = false;
  setup->check_spacing_m = 1.2;
}

// Toss Up seed 11: the planner finds a red buckyball on the floor and pushes it into a zone
// that pays more. The attempt is judged on the simulator's ball, and the match gains 2 more
// than the same seed without floor pushes. (Seed 7 was used until the pick and release stopped
// looking twice from one standstill; its push then missed. Over seeds 1-30 with duration_spread
// 0, `slamo tune --season toss_up --param strategy=planner --param floor_push=0,1 --param
// duration_spread=0`, 10 matches pushed and 8 of those pushes scored. The test then ran with
// duration_spread 0, free looks and the old driving, as when the seed was chosen; under
// today's defaults, `slamo tune --season toss_up --matches 60 --param strategy=planner
// --param floor_push=0,1`, 24 of 60 matches push, 17 of those pushes score, 11.38 -> 11.98
// gained, and seed 11 still pushes once and scores: 10 -> 12.)
TEST(Executive, APushAlongTheFloorIsJudgedAndScores) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  const auto run = [&](bool pushes) {
    MatchSetup setup;
    setup.strategy = "planner";
    setup.strategy_options.floor_pushes = pushes;
    return RunMatch(season, robot, setup, 11);
  };
  const MatchResult with = run(true), without = run(false);
  int pushes = 0, scored = 0;
  for (const AttemptCheck& a : with.attempts) {
    if (a.action != "PUSH") continue;
    ++pushes;
    scored += a.outcome == "scored";
    EXPECT_EQ(a.kind, "buckyball");
    EXPECT_GE(a.target_truth_id, 0);
  }
  EXPECT_EQ(pushes, 1);
  EXPECT_EQ(scored, 1);
  for (const AttemptCheck& a : without.attempts) EXPECT_NE(a.action, "PUSH");
  // The push's 2 points at least (measured on the old driving: +2 before the tracker forgot
  // the objects the robot's footprint met on its way, +4 since; +2 on today's defaults).
  EXPECT_GE(with.points - with.points_start, without.points - without.points_start + 2);
  EXPECT_EQ(with.overrun_s, 0.0);
}

// High Stakes with the V5 robot: the scripted route releases the preload and a picked ring
// onto a mobile goal's stake (the stakes stand on their bases and move with them; before, the
// robot pushed the base away from a stake that stayed put, and released onto the floor).
TEST(Executive, TheV5RobotScoresRingsOnAHighStakesMobileGoal) {
  const field::SeasonConfig season = field::LoadSeasonConfig("high_stakes");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  MatchSetup setup;
  setup.strategy = "scripted";
  const MatchResult r = RunMatch(season, robot, setup, 1);
  EXPECT_GE(r.points - r.points_start, 2) << "the preload and one ring (measured +2)";
  EXPECT_EQ(r.overrun_s, 0.0);
  for (const AttemptCheck& a : r.attempts) {
    if (a.action == "SCORE" && a.outcome == "scored") {
      EXPECT_EQ(season.goals[a.goal_index].on_object, "mobile_goal");
    }
  }
}

// A path leg shorter than the arrival tolerance is not driven: the arrival accepts that
// error. Before, a leg of 3 cm to the robot's side was a quarter turn there and back (on Push
// Back seed 1, 1.5 s of a 15 s period).
TEST(Executive, ALegShorterThanTheArrivalToleranceIsNotTurnedFor) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  MatchSetup setup;
  MatchWorld world(MakeSimIo(field::Alliance::kRed, 1), season, robot, setup, 1, true);
  world.Observe(10);
  // Out of the starting tile first (its corner lies inside the planner's clearance margin).
  ASSERT_TRUE(world.Navigate(Eigen::Vector3d(-0.9, -0.3, 0.0), 0.0, 0));
  const Eigen::Vector3d pose = world.slam().pose();
  const double side = 0.75 * setup.arrival_tolerance_m;
  const Eigen::Vector3d target =
      pose + Eigen::Vector3d(-std::sin(pose.z()) * side, std::cos(pose.z()) * side, 0.0);
  const double start_s = world.now_s();
  EXPECT_TRUE(world.Navigate(target, 0.0, 0));
  const Eigen::Vector3d after = world.slam().pose();
  EXPECT_NEAR(std::remainder(after.z() - pose.z(), 2.0 * M_PI), 0.0, 5.0 * M_PI / 180.0);
  // The arrival's look only (5 frames at 30 Hz), no quarter turns.
  EXPECT_LT(world.now_s() - start_s, 0.5);
}

// An arrival's error that the next action's own aim absorbs is not driven off: on Over Under's
// disturbed seed 3 the planner's drive to the red goal ended 6 cm off its stage, and the
// correction (a turn to back up, the drive, the turn back) cost 1.6 s before the release,
// which aims at the goal from the estimate anyway. (Over Under disturbed, 200 seeds: +0.28
// points a match; nominal, Push Back, Toss Up and High Stakes within their noise.) Seed 3 shows
// it with the old driving only; with today's (frames while driving, steered legs) seed 20 does:
// the first drive takes 7.38 s with only the 4 cm tolerance accepted, 5.95 s by default, the
// same points (`slamo dry-run --season over_under --robot v5_drivetrain --scenario disturbed
// --seed 20 [--param arrival_slack=0]`; seeds 2, 21 and 31 of 1-40 save more than 1 s too).
TEST(Executive, AnArrivalErrorTheNextActionAbsorbsIsNotDrivenOff) {
  const field::SeasonConfig season = field::LoadSeasonConfig("over_under");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  const auto first = [&](double slack_m) {
    MatchSetup setup;
    setup.strategy = "planner";
    setup.scenario = Scenario::kDisturbed;
    setup.arrival_slack_m = slack_m;
    const MatchResult r = RunMatch(season, robot, setup, 20);
    EXPECT_EQ(r.overrun_s, 0.0);
    for (const TimelineEntry& e : r.timeline) {
      if (e.action == "NAVIGATE") return std::make_pair(e.end_s - e.t_s, r);
    }
    ADD_FAILURE() << "no NAVIGATE";
    return std::make_pair(0.0, r);
  };
  const auto [corrected_s, corrected] = first(0.0);  // only the 4 cm tolerance accepted
  const auto [absorbed_s, absorbed] = first(-1.0);   // the default: half the approach margin
  EXPECT_LT(absorbed_s, corrected_s - 1.0) << corrected_s << " s against " << absorbed_s;
  EXPECT_GE(absorbed.points, corrected.points);
}

// Over Under disturbed seed 37 with the V5 robot: the planner's path to its first goal bends
// round an inflated disc in two corners 0.06 m apart, and the robot stopped to turn at both.
// Merged into one where the legs meet, the drive takes 5.4 s instead of 6.1 s and the time
// saved buys a second release (`slamo dry-run --season over_under --robot v5_drivetrain
// --scenario disturbed --seed 37 [--param corner_merge=0]`).
TEST(Executive, TwoPathCornersAFewCentimetresApartAreOneTurn) {
  const field::SeasonConfig season = field::LoadSeasonConfig("over_under");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  const auto run = [&](double merge_m) {
    MatchSetup setup;
    setup.strategy = "planner";
    setup.scenario = Scenario::kDisturbed;
    setup.corner_merge_m = merge_m;
    return RunMatch(season, robot, setup, 37);
  };
  const MatchResult apart = run(0.0), merged = run(0.15);
  // The shortest leg between two turns of a path (its ends are not turns).
  const auto shortest_inner_leg = [](const std::vector<Eigen::Vector2d>& path) {
    double shortest = std::numeric_limits<double>::infinity();
    for (size_t i = 1; i + 2 < path.size(); ++i)
      shortest = std::min(shortest, (path[i + 1] - path[i]).norm());
    return shortest;
  };
  ASSERT_FALSE(apart.paths.empty());
  ASSERT_FALSE(merged.paths.empty());
  EXPECT_LT(shortest_inner_leg(apart.paths.front()), 0.1);
  EXPECT_GE(shortest_inner_leg(merged.paths.front()), 0.15);
  EXPECT_EQ(merged.paths.front().size() + 1, apart.paths.front().size());
  const auto first_drive_s = [](const MatchResult& r) {
    for (const TimelineEntry& e : r.timeline)
      if (e.action == "NAVIGATE") return e.end_s - e.t_s;
    return -1.0;
  };
  ASSERT_GT(first_drive_s(apart), 0.0);
  EXPECT_LT(first_drive_s(merged), first_drive_s(apart) - 0.5);
  EXPECT_GT(merged.points, apart.points);
  EXPECT_EQ(merged.overrun_s, 0.0);
}

// Push Back disturbed seed 2 with the V5 robot: driving to its first goal the robot pushes a
// block 0.4 m from where it saw it, and the map keeps it there (the footprint's margin for the
// errors is wider than the push). The first pick finds nothing in the intake's mouth. Before,
// the margin kept the target mapped after it too, and the planner tried the same empty spot
// again (PICK x, PICK x, 2 s lost); the target of a pick that found nothing is forgotten.
// (200 seeds disturbed: picks 219 -> 208, took their target 0.69 -> 0.73, points 5.10 -> 5.08;
// nominal and Over Under unchanged.)
MatchResult PushBackDisturbed(uint64_t seed, bool pick_in_view, bool old_driving = true) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  MatchSetup setup;
  setup.strategy = "planner";
  setup.scenario = Scenario::kDisturbed;
  setup.strategy_options.pick_in_view = pick_in_view;
  if (old_driving) DriveAsWhenSeedsWereChosen(&setup);
  return RunMatch(season, robot, setup, seed);
}

// The spots of the picks of `r` that took nothing, each checked against those before it.
std::vector<Eigen::Vector2d> EmptySpotsNeverTriedTwice(const MatchResult& r, uint64_t seed) {
  std::vector<Eigen::Vector2d> empty;
  for (const AttemptCheck& a : r.attempts) {
    if (a.action != "PICK" || a.outcome != "nothing") continue;
    for (const Eigen::Vector2d& e : empty)
      EXPECT_GT((a.aim_m - e).norm(), 0.05) << "seed " << seed << " at " << a.t_s;
    empty.push_back(a.aim_m);
  }
  return empty;
}

TEST(Executive, APickThatFoundNothingIsNotTriedOnTheSameTargetAgain) {
  const MatchResult r = PushBackDisturbed(2, false);
  EXPECT_EQ(r.overrun_s, 0.0);
  EXPECT_FALSE(EmptySpotsNeverTriedTwice(r, 2).empty());  // the pushed block's spot, tried once
  // With today's driving (frames while driving, steered legs) the seeds of 1-80 with a pick
  // that took nothing (`slamo tune --season push_back --robot v5_drivetrain --matches 80
  // --param strategy=planner --scenario disturbed`, attempts.csv).
  for (const uint64_t seed : {13, 35, 44, 68, 69}) {
    const MatchResult now = PushBackDisturbed(seed, false, false);
    EXPECT_EQ(now.overrun_s, 0.0) << seed;
    EXPECT_FALSE(EmptySpotsNeverTriedTwice(now, seed).empty()) << seed;
  }
}

// With StrategyOptions::pick_in_view the pick is staged where the camera sees its target
// whole, and given up before its approach when the look there does not find it (no approach,
// judged "skipped", not an attempt that took nothing). Push Back disturbed seed 116:
// the block believed 0.45 m from any block of its kind.
TEST(Executive, WithPickInViewAPickWhoseTargetIsGoneIsSkipped) {
  const MatchResult r = PushBackDisturbed(116, true);
  EXPECT_EQ(r.overrun_s, 0.0);
  int skipped = 0;
  for (const AttemptCheck& a : r.attempts) {
    if (a.action != "PICK") continue;
    EXPECT_NE(a.outcome, "nothing") << a.t_s;
    if (a.outcome != "skipped") continue;
    ++skipped;
    EXPECT_GT(a.target_error_m, 0.2);  // nothing of its kind where it was believed
  }
  EXPECT_GE(skipped, 1);
  // A pick tried waits the intake's pick_s (1 s) at least; one given up took at most a look.
  int given_up = 0;
  for (const TimelineEntry& e : r.timeline)
    given_up += e.action == "PICK" && !e.ok && e.end_s - e.t_s < 0.5;
  EXPECT_EQ(given_up, skipped);
}

// A look before a cycle is charged the time it takes at the best rate of the sequences without
// one: the search sees only two cycles ahead, and without the charge a look that lifts a
// release's modelled chance by a little was free whenever both sequences fit. Push Back
// nominal seed 73: 1 look before a cycle instead of 5, and the second release ends in time (3
// points without the charge, 6 with it; 200 seeds +0.045 nominal, +0.03 disturbed when it came).
// The seed is one of those where the charge pays: seed 68, the case first, maps its blocks
// differently since the pieces split by size stopped overlapping; seed 87, the next, scores 3
// either way since the simulator renders the camera's latency (frames taken as the wheels
// coast out after a drive). Now 6 of 200 nominal seeds score 3 more with the charge (37, 73,
// 78, 134, 135, 179), none less: `slamo tune --season push_back --robot v5_drivetrain
// --matches 200 --param strategy=planner --param look_charge=0,1`, 5.85 -> 5.94.
// Since frames while driving and steered legs became the defaults the charge changes no
// match of seeds 1-120 (5.97 either way; not traced further). The test keeps the driving of
// its seed.
TEST(Executive, ALookBeforeACycleIsChargedItsTime) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  const auto run = [&](double look_charge) {
    MatchSetup setup;
    setup.strategy = "planner";
    setup.strategy_options.look_charge = look_charge;
    DriveAsWhenSeedsWereChosen(&setup);
    const MatchResult r = RunMatch(season, robot, setup, 73);
    EXPECT_EQ(r.overrun_s, 0.0);
    int looks = 0;
    for (const TimelineEntry& e : r.timeline)
      looks += e.detail.find("observe before the cycle") != std::string::npos;
    return std::make_pair(looks, r.points - r.points_start);
  };
  const auto [free_looks, free_points] = run(0.0);
  const auto [charged_looks, charged_points] = run(1.0);  // the default
  EXPECT_LT(charged_looks, free_looks);
  EXPECT_GT(charged_points, free_points) << "measured 3 without the charge, 6 with it";
}

// A pick or release right after a look from the same standstill does not look again (the same
// view, and the stop's shared bias would be counted twice); after the robot moved, or after a
// release on the floor put the held object in front of it, it does.
TEST(Executive, APickOrReleaseLooksOnlyWhenTheSceneChangedSinceTheLastLook) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  MatchSetup setup;
  ASSERT_GT(setup.correction_frames, 0);
  enum class Before { kNothing, kTurn, kDrop };
  // The frames the action took at stops after a 5-frame look and then `before`.
  const auto frames_of = [&](strategy::ActionKind kind, Before before) {
    MatchWorld world(MakeSimIo(field::Alliance::kRed, 1), season, robot, setup, 1, true);
    EXPECT_TRUE(world.Belief().held.has_value());  // the preload
    EXPECT_GT(world.Observe(5), 0);
    const Eigen::Vector3d pose = world.slam().pose();
    if (before == Before::kTurn) {
      EXPECT_TRUE(world.TurnTo(pose.z() + 0.3));
    }
    if (before == Before::kDrop) {
      strategy::Action drop;
      drop.kind = strategy::ActionKind::kDrop;
      drop.target = pose;  // where it faces: no turn
      EXPECT_TRUE(world.Drop(drop));
    }
    strategy::Action a;
    a.kind = kind;
    a.goal_index = 0;
    a.target = pose + Eigen::Vector3d(0.5 * std::cos(pose.z()), 0.5 * std::sin(pose.z()), 0.0);
    // Frames at stops: the approach's frames while driving are not looks.
    const int frames_before = world.frames() - world.moving_frames();
    if (kind == strategy::ActionKind::kScore) {
      world.Score(a);
    } else {
      world.Pick(a);
    }
    return world.frames() - world.moving_frames() - frames_before;
  };
  EXPECT_EQ(frames_of(strategy::ActionKind::kScore, Before::kNothing), 0);
  EXPECT_GT(frames_of(strategy::ActionKind::kScore, Before::kTurn), 0);
  EXPECT_EQ(frames_of(strategy::ActionKind::kPick, Before::kNothing), 0);
  EXPECT_GT(frames_of(strategy::ActionKind::kPick, Before::kTurn), 0);
  EXPECT_GT(frames_of(strategy::ActionKind::kPick, Before::kDrop), 0);
}

// Over Under seed 36 with the V5 robot: after its preload the planner sets off to push a far
// green triball, and the drive carries a green triball lying in our offensive zone out of it
// (2 points lost). Charged for that loss, the sequence is not worth it. (Over seeds 1-30
// nominal, `--param push_loss=0,1`: 4.73 -> 5.33 gained, no seed worse, at e453a17; then seeds
// 14, 6 and 22 showed it, each until timing changes turned the planner away from the push on
// their own; seed 36 since frames while driving and steered legs became the defaults, found
// with `slamo tune --season over_under --robot v5_drivetrain --matches 60 --param
// strategy=planner --param push_loss=0,1`: 8.02 -> 8.25, 6 seeds better, 2 worse.)
// Points the planner gains on `season` with the V5 robot, seed `seed`, with the push-loss rules
// on or off (StrategyOptions::count_push_loss); no overrun either way. Path corners are not
// merged (MatchSetup::corner_merge_m 0), as when the seed was found: merged, seed 36's drives
// take other times and both gain 3 (with the rules, a pick instead of the push, which gains no
// more).
int GainedWithPushLoss(const std::string& season_name, uint64_t seed, bool count) {
  const field::SeasonConfig season = field::LoadSeasonConfig(season_name);
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  MatchSetup setup;
  setup.strategy = "planner";
  setup.strategy_options.count_push_loss = count;
  setup.corner_merge_m = 0.0;
  const MatchResult r = RunMatch(season, robot, setup, seed);
  EXPECT_EQ(r.overrun_s, 0.0);
  return r.points - r.points_start;
}

TEST(Executive, ADriveThatWouldPushOurTriballOutOfItsZoneIsNotTaken) {
  // The preload's 5, less the triball pushed out; then the preload's 5.
  EXPECT_EQ(GainedWithPushLoss("over_under", 36, false), 3);
  EXPECT_EQ(GainedWithPushLoss("over_under", 36, true), 5);
}

// The second cycle of a sequence is not planned on objects the first one's drive pushes on.
// Push Back seed 1 with the V5 robot: the red cluster of three near the start lies on the
// straight way to the upper centre goal. Through it, the planner scored its preload in the
// centre goal, found no block near it after (the cluster pushed away, and forgotten) and ran
// out of time on a far one: 3 points. Round it, by the long goal, the cluster is still there
// for the second cycle, as the scripted route does it: 6. (Blocks on the floor earn nothing
// where they lie, so `count_push_loss` changes nothing else here.)
TEST(Executive, TheSecondCycleIsNotPlannedOnWhatTheFirstDrivePushesAway) {
  EXPECT_EQ(GainedWithPushLoss("push_back", 1, false), 3);
  EXPECT_EQ(GainedWithPushLoss("push_back", 1, true), 6);
}

// The release takes the robot file's time: the same release with a quicker intake ends that
// much sooner.
TEST(Executive, AReleaseTakesTheRobotFilesIntakeTime) {
  const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
  field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  MatchSetup setup;
  strategy::Action score;
  score.kind = strategy::ActionKind::kScore;
  score.goal_index = 0;
  const auto release_time = [&](double release_s) {
    robot.intake.release_s = release_s;
    MatchWorld world(MakeSimIo(field::Alliance::kRed, 1), season, robot, setup, 1, true);
    world.Observe(5);
    const double start_s = world.now_s();
    world.Score(score);
    return world.now_s() - start_s;
  };
  EXPECT_NEAR(release_time(1.0) - release_time(0.2), 0.8, 0.03);
}

TEST(Executive, ActionThatWouldOverrunIsNotStarted) {
  field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  season.rules.autonomous_s = 5.0;
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  MatchSetup setup;
  const MatchResult r = RunMatchWith(std::make_unique<FarAway>(6.0), season, robot, setup, 1);
  ASSERT_FALSE(r.timeline.empty());
  EXPECT_EQ(r.timeline.front().action, "REFUSED");
  for (const TimelineEntry& t : r.timeline) EXPECT_NE(t.action, "NAVIGATE");
  EXPECT_GT(r.refused, 0);
  // Nothing moved: the robot is where it started and never drove.
  const Eigen::Vector3d start = r.samples.front().truth, end = r.samples.back().truth;
  EXPECT_LT((end - start).head<2>().norm(), 1e-6);
  EXPECT_EQ(r.overrun_s, 0.0);
}

TEST(Executive, MotionStopsAtTheDeadlineEvenWhenTheEstimateWasWrong) {
  field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  season.rules.autonomous_s = 5.0;
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  MatchSetup setup;
  // Claims 1 s for a drive across the field: it starts, and the deadline cuts it.
  const MatchResult r = RunMatchWith(std::make_unique<FarAway>(1.0), season, robot, setup, 1);
  bool navigated = false;
  for (const TimelineEntry& t : r.timeline) navigated |= t.action == "NAVIGATE";
  EXPECT_TRUE(navigated);
  EXPECT_EQ(r.overrun_s, 0.0);
  EXPECT_LE(r.duration_s, 5.0 + 1e-9);
  EXPECT_GT((r.samples.back().truth - r.samples.front().truth).head<2>().norm(), 0.05)
      << "it did drive";
}

// Frames while driving (#15 item 5): every 0.2 s of a straight drive a frame goes into
// SLAM-O, paired with the odometry of its exposure camera.latency_s (the V5 robot's 0.05 s,
// which the simulator renders) before the latest reading. Over Under disturbed, six seeds: the
// pose error at the filter's updates falls well below the stops-only run's, and the latency
// costs little against a camera without any. Measured with the defaults: 0.0180 m stops only
// (a quick look every 1.2 m of path), 0.0076 m while driving (legs steered from the frames, a
// look every 2.4 m), 0.0073 m without latency; before the steering 0.0066 and 0.0051 m, and
// paired with the odometry of the moment the frame arrives instead (a throw-away patch),
// 0.0164 m.
TEST(Executive, FramesWhileDrivingArePairedWithTheOdometryOfTheirExposure) {
  const field::SeasonConfig season = field::LoadSeasonConfig("over_under");
  const field::RobotConfig robot = field::LoadRobotConfig("v5_drivetrain");
  ASSERT_GT(robot.camera.latency_s, 0.0);
  field::RobotConfig no_latency = robot;
  no_latency.camera.latency_s = 0.0;
  double stops = 0.0, moving = 0.0, moving_no_latency = 0.0;
  const int seeds = 6;
  for (int seed = 1; seed <= seeds; ++seed) {
    MatchSetup setup;
    setup.scenario = Scenario::kDisturbed;
    setup.moving_frame_period_s = 0.0;  // frames only at stops
    const MatchResult a = RunMatch(season, robot, setup, seed);
    EXPECT_EQ(a.moving_frames, 0);
    setup.moving_frame_period_s = 0.2;
    const MatchResult b = RunMatch(season, robot, setup, seed);
    const MatchResult c = RunMatch(season, no_latency, setup, seed);
    EXPECT_GT(b.moving_frames, 10) << seed;
    EXPECT_LT(b.moving_frames, b.frames_taken) << seed;
    EXPECT_EQ(b.overrun_s, 0.0) << seed;
    stops += a.pose_ate_m / seeds;
    moving += b.pose_ate_m / seeds;
    moving_no_latency += c.pose_ate_m / seeds;
  }
  std::printf("ATE m: stops only %.4f, while driving %.4f, no latency %.4f\n", stops, moving,
              moving_no_latency);
  EXPECT_LT(moving, 0.5 * stops);
  EXPECT_LT(moving, 2.0 * moving_no_latency);
}

}  // namespace
}  // namespace slamo::autonomy
