// The executive: one simulated autonomous period, end to end (see RunMatch in executive.cc,
// which reads as the match loop from top to bottom).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autonomy/loop/match_world.h"
#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "strategy/strategy.h"

namespace slamo::autonomy {

struct TimelineEntry {
  double t_s = 0.0;    // when the action started
  double end_s = 0.0;  // when it ended
  std::string action;  // OBSERVE, NAVIGATE, PICK, SCORE, IDLE, or REFUSED (would overrun)
  std::string detail;
  bool ok = true;
  double expected_s = 0.0;  // the strategy's estimate
};

struct ObjectReport {
  int id = 0;
  std::string kind;
  std::string colour;
  Eigen::Vector2d estimate_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  bool matched = false;  // a true object of its kind and colour within 0.5 m
  Eigen::Vector2d truth_m = Eigen::Vector2d::Zero();
  double error_m = 0.0;
};

// A pick or score attempt against the truth, when it began: the robot's position error and the
// filter's 3-sigma (three times the position covariance's longest axis); what was aimed at,
// from where; and what came of it, judged on the simulator's objects.
struct AttemptCheck {
  double t_s = 0.0;
  std::string action;  // PICK, SCORE or KNOCK (a push off a raised structure)
  bool ok = false;     // what the action reported
  Eigen::Vector2d estimate_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d truth_m = Eigen::Vector2d::Zero();
  double error_m = 0.0;
  double three_sigma_m = 0.0;
  bool Inside() const { return error_m <= three_sigma_m; }

  // PICK, KNOCK: the target's kind and colour (empty: any); SCORE: the held object's, and the
  // goal (KNOCK: the zone it should land in).
  std::string kind, colour;
  int goal_index = -1;
  // From the estimated pose when the attempt began, to the believed target (PICK) or the
  // goal's centre (SCORE): distance, and bearing off the robot's heading (the turn of the
  // approach, rad).
  Eigen::Vector2d aim_m = Eigen::Vector2d::Zero();
  double range_m = 0.0;
  double bearing_rad = 0.0;
  // PICK, KNOCK: the true object the belief stood for (the nearest of its kind and colour
  // within kTargetMatch_m; KNOCK: on a raised structure), and how far the belief was from it;
  // -1 when there was none.
  int target_truth_id = -1;
  double target_error_m = -1.0;
  // PICK: "target" (the intake took that object), "other" (it took another), "nothing",
  // "skipped" (given up before the approach: the look there did not find the target).
  // SCORE: "scored" (in the goal aimed at), "missed" (released elsewhere), "nothing" (nothing
  // left the intake). KNOCK: "scored" (the object came down into the zone aimed at), "off"
  // (it came down elsewhere), "nothing" (it is still up there, or there was none).
  std::string outcome;
  // PICK: the kind and colour of what the intake took (empty: nothing).
  std::string taken_kind, taken_colour;
};
inline constexpr double kTargetMatch_m = 0.5;
const std::vector<std::string>& PickOutcomes();   // target, other, nothing, skipped
const std::vector<std::string>& ScoreOutcomes();  // scored, missed, nothing
const std::vector<std::string>& KnockOutcomes();  // scored, off, nothing

struct MatchResult {
  std::string robot_io;                 // what the match ran on (RobotIo::Describe)
  bool truth_known = true;              // false on hardware: points and object errors are unknown
  std::map<std::string, double> board;  // hardware counters (RobotIo::Status)
  std::string season;
  uint64_t seed = 0;
  std::string strategy;
  std::string frames;    // the frame rule, described
  std::string scenario;  // the object layout: nominal or disturbed (ScenarioName)
  int points = 0;        // the alliance's score at the deadline
  int points_start = 0;  // ... and at the start (objects already in scoring zones)
  double deadline_s = 0.0;
  double duration_s = 0.0;  // until the last motion command (never after the deadline)
  double overrun_s = 0.0;   // motors driven after the deadline (goal: 0)
  int refused = 0;          // actions not started because they could not finish in time
  double pose_ate_m = 0.0;  // RMS position error of the estimate at every filter update (NaN:
                            // no truth)
  double observe_s = 0.0, drive_s = 0.0, score_s = 0.0, idle_s = 0.0;
  int frames_taken = 0;
  int moving_frames = 0;  // of frames_taken: while driving (MatchSetup::moving_frame_period_s)
  int replans = 0;
  int relocalisations = 0;      // frames paired again after widening a lost pose belief
  int rejected_frames = 0;      // frames whose update would have thrown the pose off
  double odometry_scale = 1.0;  // true distance per encoder distance, calibrated before the match
  PoseConsistency consistency;  // the pose NEES at every update (when the truth is known)
  std::vector<AttemptCheck> attempts;  // every pick and score attempt (when the truth is known)
  double wall_s = 0.0;                 // compute time of the run on this machine
  std::vector<ObjectReport> objects;
  std::vector<TimelineEntry> timeline;
  std::vector<PoseSample> samples;
  std::vector<Snapshot> snapshots;
  std::vector<std::vector<Eigen::Vector2d>> paths;
  std::vector<Eigen::Vector2d> landmark_estimates, landmark_truth;
  std::vector<Eigen::Matrix2d> landmark_covariances;
  field::SeasonConfig field;  // the season the robot was given (its file, not the placement)
};

// One autonomous period on `io` (the robot: autonomy/hardware_io.h), with the season's objects
// where its file puts them; `seed` seeds the planners. Truth-based figures (points, ATE,
// object errors) are reported only when `io` knows the truth.
MatchResult RunMatchOn(std::unique_ptr<RobotIo> io, std::unique_ptr<strategy::Strategy> strategy,
                       const field::SeasonConfig& season, const field::RobotConfig& robot,
                       const MatchSetup& setup, uint64_t seed, const std::string& out_dir = "",
                       const std::function<void(const TimelineEntry&)>& progress = {});

}  // namespace slamo::autonomy
