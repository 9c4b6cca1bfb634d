// The scheduler that spends the autonomous seconds: from what SLAM-O believes (pose and its
// covariance, tracked objects and their confidence), the time left and travel times from the
// planner, it chooses the robot's next action: OBSERVE, NAVIGATE, PICK, SCORE or DROP.
//
// Our method ("planner"): a receding-horizon search. Every time an action ends, it enumerates
// the sequences of up to `horizon` pick-and-score cycles (the held object's scoring first, if
// any) over the known objects and the goals that take them, each timed with the planner's
// travel times and the intake and release times, keeps those that finish before the deadline,
// and scores each by its objective:
//
//     J = sum over cycles of  P(success) * (points after - points before)
//
// the expected points the sequence adds by the deadline; ties go to the higher rate J / T
// (expected points per second). P(success) of a pick or a release is the probability that the
// robot's position error, from the pose covariance and the object's covariance, stays inside
// the intake's (or the goal's) tolerance; an object's confidence multiplies it. Only the first
// action of the best sequence runs; then the search starts again from the new belief.
// Observation is part of the same trade: before a cycle the search also considers observing
// n frames first (n from the frame choices), which costs n / frame rate seconds and shrinks the
// pose covariance as the iterated-frame model predicts, raising P(success). When no cycle is
// worth anything (nothing known), it turns to look where the season says objects of our
// colour may be and nothing is tracked yet.
//
// An object lying on top of a raised structure (a large ball on the Toss Up barrier, which it
// does not fit under) cannot be picked: every strategy may instead knock it off, driving
// straight into it across the structure so that it drops into the zone beyond (a "push"
// navigation), valued like a cycle by the points of the zone it lands in. An object on the
// floor may be pushed the same way into a zone that pays more for it (floor_pushes).
//
// Baselines: "greedy" (nearest known object of ours, the best goal for it, no search), "thesis"
// (greedy targets, driven with a stop every 0.3 m and 20 frames at each, as the thesis did),
// and "scripted" (a fixed route from the season's nominal positions, no perception: what teams
// run today).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"

namespace slamo::strategy {

struct ObjectBelief {
  int id = 0;
  std::string kind;
  std::string colour;
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity() * 1e-4;
  double confidence = 1.0;  // 0..1
};

// What the robot believes when it chooses: SLAM-O's estimate, never the simulator's truth.
struct Belief {
  double now_s = 0.0;
  double deadline_s = 45.0;
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  // x_m, y_m, theta_rad
  Eigen::Matrix3d pose_covariance = Eigen::Matrix3d::Identity() * 1e-6;
  std::optional<ObjectBelief> held;   // in the intake (kind and colour known)
  std::vector<ObjectBelief> objects;  // confirmed objects on the field
};

// kDrop: release the held object where the robot stands, because no goal takes it for our
// alliance (the intake took another object than the one aimed at): it frees the intake.
enum class ActionKind { kObserve, kNavigate, kPick, kScore, kDrop, kIdle };
const char* ActionName(ActionKind kind);

struct Action {
  ActionKind kind = ActionKind::kIdle;
  // kObserve: at most this many frames (the frame rule may stop earlier); kPick: frames to
  // refresh the target before the final approach; kNavigate: frames at every stop.
  int frames = 0;
  // kObserve: turn in place to heading target.z() first when look_heading is set.
  bool look_heading = false;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // x_m, y_m, heading_rad
  double stop_spacing_m = 0.0;                       // kNavigate: observation stops (0: none)
  // kNavigate: a push, driven straight into object_id to knock it off the raised structure it
  // lies on (a large ball off the Toss Up barrier) into the zone beyond.
  bool push = false;
  int object_id = -1;  // kPick; kNavigate with push: the object knocked
  // kNavigate with push: where the object is believed to lie (for the record only).
  Eigen::Vector2d object_m = Eigen::Vector2d::Zero();
  // kNavigate with push: the object lies on the floor and is pushed along it into a zone that
  // pays more (not knocked off a raised structure).
  bool along_floor = false;
  // kPick: the target's kind and colour (also where object_id names no tracked object: the
  // scripted route's nominal objects). For the record only: the executive takes what the
  // intake reports.
  std::string object_kind, object_colour;
  int goal_index = -1;           // kScore: into SeasonConfig::goals
  double expected_s = 0.0;       // the strategy's estimate of the action's duration
  double expected_points = 0.0;  // expected points of the sequence this action starts
  std::string why;               // one line for the timeline
  // kScore: where the strategy believes the goal stands (a goal on a movable object, such as
  // a mobile goal's stake, where it was seen; else the season file's centre).
  Eigen::Vector2d goal_m = Eigen::Vector2d::Zero();
};

// Durations and tolerances the strategy plans with (measured on the simulator or the robot).
struct StrategyOptions {
  int horizon = 2;                  // pick-and-score cycles searched ahead
  double approach_margin_m = 0.15;  // staging pose this far before the final straight approach
  // A strategy that perceives stages a pick further out, where the camera sees the target
  // whole (at least approach_margin_m), and the executive gives the pick up when the look on
  // arrival does not find it (pushed away, or never there). The view's edges less
  // view_margin_rad (as SlamOOptions::fov_margin_rad). Off: it made more picks take their
  // target but scored less (the longer approach costs time; README, #15, "Then: a pick that
  // found nothing forgets its target...").
  bool pick_in_view = false;
  double view_margin_rad = 0.05;
  double push_run_in_m = 0.35;     // knock: straight run-in to the object on a raised structure
  double pick_tolerance_m = 0.12;  // lateral error the intake forgives
  std::vector<int> frame_choices = {0, 5, 10, 20};
  // Planner: a look before a cycle is charged its seconds at the best rate (points per
  // second) of the sequences that start without one, times this: the time it takes is lost
  // to what comes after the search's horizon (0: a look costs only what it pushes out of time).
  double look_charge = 1.0;
  // Pose information one frame of landmarks adds, as position sigmas (m): white per frame,
  // bias per stop (the iterated-frame model: sigma^2 = white^2 / n + bias^2).
  double frame_white_sigma_m = 0.03;
  double frame_bias_sigma_m = 0.01;
  // P(success) of a pick (action "PICK", the target's kind) or a release ("SCORE", the held
  // object's kind) learned from the simulator's outcomes (`slamo tune calibrate`), from the
  // range and bearing of the target when the attempt starts and the pose sigma then; unset,
  // or nothing for that kind: the tolerance model (SuccessProbability).
  std::function<std::optional<double>(const std::string& action, const std::string& kind,
                                      double range_m, double bearing_rad, double sigma_m)>
      learned_success;
  // Planner: objects the season file places on a raised structure (the Toss Up barrier's large
  // balls) are believed at their spot, with this position sigma, until knocked off (see
  // strategy.cc, RaisedPriors). Not measured: the field facts give no placement tolerance.
  bool raised_priors = true;
  // Objects on the floor may be pushed along it, up to max_floor_push_m, into a zone where
  // they earn more (a push navigation, like a knock): a cycle with no pick or release.
  bool floor_pushes = true;
  double max_floor_push_m = 1.0;
  // Planner: a sequence's value loses the points of our objects the drive to its first stage
  // would push out of the zones they earn in (strategy.cc, Base::PushLoss), and its second
  // cycle is not planned on an object that drive pushes on (Base::OnTheWay).
  bool count_push_loss = true;
  // Time cycles with the drive, pick and release estimates scaled by how long those actions
  // took so far in the match (strategy.cc, Base::Scale).
  bool learn_durations = true;
  // Planner: how far a sequence's duration strays from its (scaled) estimate, as a standard
  // deviation relative to the estimate. A sequence is valued by the probability that it ends
  // before the deadline (normal about the estimate); 0: a sequence fits or is not considered.
  // Measured (`scripts/duration-spread` on the planner's and greedy's 24 reports that
  // `scripts/same-results record` writes, commit 09ba787): drives 0.22, releases 0.07, picks
  // 0.23 (2 picks only); a sequence mixes them. Push Back's planner made the same points with
  // 0.1, 0.2 and 0.3 over 30 seeds. Not calibrated per robot yet.
  double duration_spread = 0.2;
  double prior_sigma_m = 0.05;
  double min_gain = 0.25;         // expected points below this are not worth a cycle
  int look_frames = 10;           // frames of an exploratory look
  int arrival_frames = 5;         // planner: frames to check an arrival
  int thesis_frames = 20;         // thesis baseline: frames at every stop
  double thesis_spacing_m = 0.3;  // thesis baseline: stop spacing
};

// What the strategy may ask of the rest of the system.
struct StrategyContext {
  const field::SeasonConfig* season = nullptr;
  const field::RobotConfig* robot = nullptr;
  field::Alliance alliance = field::Alliance::kRed;
  // Seconds to drive from one pose to another (turns included) along the planner's map, or
  // nothing when unreachable.
  std::function<std::optional<double>(const Eigen::Vector3d&, const Eigen::Vector3d&)>
      travel_time_s;
  // Whether the robot may stand at a point (the planner's inflated map).
  std::function<bool(const Eigen::Vector2d&)> is_clear;
  double frame_rate_hz = 30.0;
};

class Strategy {
 public:
  virtual ~Strategy() = default;
  virtual std::string name() const = 0;
  // Whether the executive should run the camera and SLAM-O for this strategy.
  virtual bool perceives() const { return true; }
  // The next action; kIdle when nothing worth doing fits in the time left.
  virtual Action Next(const Belief& belief, const StrategyContext& context) = 0;
  // What came of an action the strategy chose: a target that failed twice is dropped.
  virtual void Feedback(const Action& action, bool succeeded) = 0;
};

// After pushing an object along the floor the robot backs out this far, clear of it.
inline constexpr double kFloorPushBackOff_m = 0.15;

// planner, greedy, thesis, scripted.
const std::vector<std::string>& StrategyNames();
// Throws std::invalid_argument on an unknown name.
std::unique_ptr<Strategy> MakeStrategy(const std::string& name, const StrategyOptions& options);

// ---- Geometry and scoring shared by the strategies and the executive ----

// Points an object of kind/colour earns for `alliance` in goal g (0 when it does not score
// there: wrong kind, colour or alliance).
int GoalPoints(const field::SeasonConfig& season, int goal_index, const std::string& kind,
               const std::string& colour, field::Alliance alliance);
// Points the object earns where it lies on the floor (its best zone).
int FloorPoints(const field::SeasonConfig& season, const Eigen::Vector2d& position_m,
                const std::string& kind, const std::string& colour, field::Alliance alliance);

// Where the robot stands (x, y, heading) to pick an object: the staging pose `margin_m`
// behind the final approach, facing the object, approached from `from` when that side is clear
// (and `accept`, when given, takes the stage: e.g. nothing else in the intake's corridor),
// else from the nearest heading round the object that is.
std::optional<Eigen::Vector3d> PickStage(
    const StrategyContext& context, const Eigen::Vector2d& object, double object_radius_m,
    const Eigen::Vector2d& from, double margin_m,
    const std::function<bool(const Eigen::Vector3d&)>& accept = {});
// Distance from the robot's centre to an object's centre at which the intake takes it.
double PickDistance(const field::RobotConfig& robot, double object_radius_m);

// Staging poses for releasing an object of radius r into goal g: facing the drop point,
// margin_m before the release distance. For a goal structure the drop lands on its centre
// line; for a floor zone the drop lands inside it.
std::vector<Eigen::Vector3d> ScoreStages(const StrategyContext& context, int goal_index,
                                         double object_radius_m, double margin_m);
// Where the released object should land for goal g, seen from the robot at `stage` (a
// staging pose from ScoreStages with the same margin).
Eigen::Vector2d DropTarget(const field::SeasonConfig& season, const field::RobotConfig& robot,
                           int goal_index, const Eigen::Vector3d& stage, double object_radius_m,
                           double margin_m);
// Robot centre to drop-point distance when releasing (the simulator's and the intake's rule).
double ReleaseDistance(const field::RobotConfig& robot, double object_radius_m);

// Probability that a position error with covariance `cov` stays within `tolerance_m` along
// the worst axis (a 1-D Gaussian on the largest eigenvalue).
double SuccessProbability(const Eigen::Matrix2d& cov, double tolerance_m);

}  // namespace slamo::strategy
