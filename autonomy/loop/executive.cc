// The match loop. Everything the robot does in the autonomous period happens in RunMatch,
// in this order: read what SLAM-O believes (its frames and encoders were taken in by the last
// action), ask the strategy for the next action, refuse it if it cannot finish before the
// deadline, carry it out (plan, drive, observe, pick, release: MatchWorld), tell the strategy
// how it went, and go round again until the deadline.
#include "autonomy/loop/executive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Eigenvalues>

#include "platform/field_geometry.h"
#include "strategy/strategy.h"

namespace slamo::autonomy {
namespace {

using strategy::ActionKind;

// Up on a structure (the Toss Up barrier), not resting on the floor.
bool Raised(const TrueObject& t) { return t.center_m.z() > t.radius_m + 0.05; }

// The robot's true position error and the filter's 3-sigma now, and what `action` aims at
// from where; none without the truth.
std::optional<AttemptCheck> CheckAttempt(const MatchWorld& world, const strategy::Action& action,
                                         const strategy::Belief& belief) {
  const std::optional<platform::Pose2D> truth = world.io().TruePose();
  const std::optional<std::vector<TrueObject>> objects = world.io().TrueObjects();
  if (!truth || !objects) return std::nullopt;
  AttemptCheck c;
  c.t_s = world.now_s();
  c.action = strategy::ActionName(action.kind);
  c.estimate_m = world.slam().pose().head<2>();
  c.truth_m = Eigen::Vector2d(truth->x_m, truth->y_m);
  c.error_m = (c.estimate_m - c.truth_m).norm();
  const Eigen::Matrix2d position = world.slam().pose_covariance().topLeftCorner<2, 2>();
  c.three_sigma_m =
      3.0 *
      std::sqrt(std::max(
          0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(position).eigenvalues().maxCoeff()));

  Eigen::Vector2d aim = action.target.head<2>();
  if (action.kind == ActionKind::kNavigate && action.push) {
    c.action = action.along_floor ? "PUSH" : "KNOCK";
    c.kind = action.object_kind, c.colour = action.object_colour;
    c.goal_index = action.goal_index;
    aim = action.object_m;
    double best = kTargetMatch_m;
    for (const TrueObject& t : *objects) {
      if (t.held || t.in_goal >= 0 || Raised(t) != !action.along_floor) continue;
      if (!c.kind.empty() && (t.kind != c.kind || t.colour != c.colour)) continue;
      const double e = (t.center_m.head<2>() - aim).norm();
      if (e < best) best = e, c.target_truth_id = t.id, c.target_error_m = e;
    }
  } else if (action.kind == ActionKind::kPick) {
    c.kind = action.object_kind, c.colour = action.object_colour;
    for (const strategy::ObjectBelief& o : belief.objects) {
      if (o.id == action.object_id) aim = o.position_m, c.kind = o.kind, c.colour = o.colour;
    }
    double best = kTargetMatch_m;
    for (const TrueObject& t : *objects) {
      if (t.held || t.in_goal >= 0) continue;
      if (!c.kind.empty() && (t.kind != c.kind || t.colour != c.colour)) continue;
      const double e = (t.center_m.head<2>() - aim).norm();
      if (e < best) best = e, c.target_truth_id = t.id, c.target_error_m = e;
    }
  } else {
    c.goal_index = action.goal_index;
    if (belief.held) c.kind = belief.held->kind, c.colour = belief.held->colour;
    const field::SeasonConfig& season = world.field();
    if (action.goal_index >= 0 && action.goal_index < static_cast<int>(season.goals.size())) {
      const field::Goal& goal = season.goals[action.goal_index];
      aim = Eigen::Vector2d(goal.center_m.x, goal.center_m.y);
    }
  }
  c.aim_m = aim;
  const Eigen::Vector3d pose = world.slam().pose();
  const Eigen::Vector2d d = aim - pose.head<2>();
  c.range_m = d.norm();
  c.bearing_rad = platform::WrapAngleRad(std::atan2(d.y(), d.x()) - pose.z());
  return c;
}

// What came of the attempt, from the simulator's objects before and after it.
void JudgeAttempt(const field::SeasonConfig& season, const std::vector<TrueObject>& before,
                  const std::vector<TrueObject>& after, AttemptCheck* c) {
  if (c->action == "KNOCK" || c->action == "PUSH") {
    c->outcome = "nothing";
    for (const TrueObject& a : after) {
      if (a.id != c->target_truth_id || Raised(a)) continue;
      const bool in_zone =
          c->goal_index >= 0 && c->goal_index < static_cast<int>(season.goals.size()) &&
          platform::GoalContains(season.goals[c->goal_index], a.center_m.head<2>());
      c->outcome = in_zone ? "scored" : "off";
    }
    return;
  }
  std::vector<int> taken, released;
  for (const TrueObject& b : before) {
    for (const TrueObject& a : after) {
      if (a.id != b.id) continue;
      if (!b.held && a.held) taken.push_back(a.id);
      if (b.held && !a.held) released.push_back(a.id);
    }
  }
  if (c->action == "PICK") {
    for (const TrueObject& a : after) {
      if (!taken.empty() && a.id == taken.front())
        c->taken_kind = a.kind, c->taken_colour = a.colour;
    }
    if (taken.empty())
      c->outcome = "nothing";
    else
      c->outcome = std::find(taken.begin(), taken.end(), c->target_truth_id) != taken.end()
                       ? "target"
                       : "other";
  } else {
    c->outcome = released.empty() ? "nothing" : c->ok ? "scored" : "missed";
  }
}

// Tracked objects against where the objects really are at the end.
std::vector<ObjectReport> ScoreObjects(const MatchWorld& world) {
  std::vector<ObjectReport> out;
  const std::optional<std::vector<TrueObject>> truth = world.io().TrueObjects();
  for (const mapping::TrackedObject& o : world.slam().tracker().objects()) {
    if (!world.slam().tracker().Confirmed(o)) continue;
    ObjectReport r;
    r.id = o.id;
    r.kind = o.kind;
    r.colour = o.colour;
    r.estimate_m = o.position_m;
    r.covariance = o.covariance;
    double best = 0.5;
    if (!truth) {  // no truth on hardware
      out.push_back(r);
      continue;
    }
    for (const TrueObject& t : *truth) {
      if (t.held || t.kind != o.kind || t.colour != o.colour) continue;
      const double e = (t.center_m.head<2>() - o.position_m).norm();
      if (e < best) best = e, r.matched = true, r.truth_m = t.center_m.head<2>(), r.error_m = e;
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace

const std::vector<std::string>& PickOutcomes() {
  static const std::vector<std::string> names = {"target", "other", "nothing", "skipped"};
  return names;
}
const std::vector<std::string>& ScoreOutcomes() {
  static const std::vector<std::string> names = {"scored", "missed", "nothing"};
  return names;
}
const std::vector<std::string>& KnockOutcomes() {
  static const std::vector<std::string> names = {"scored", "off", "nothing"};
  return names;
}

namespace {

// The thesis baseline is the thesis's rule: a fixed count of frames at every stop, and
// frames only at stops.
MatchSetup SetupFor(const strategy::Strategy& strategy, const MatchSetup& setup) {
  MatchSetup out = setup;
  if (strategy.name() == "thesis") {
    out.frames.rule = mapping::FrameRule::kFixed;
    out.frames.fixed_frames = setup.strategy_options.thesis_frames;
    out.moving_frame_period_s = 0.0;
    out.steer_on_estimate = false;
  }
  return out;
}

MatchResult RunLoop(std::unique_ptr<strategy::Strategy> strategy, MatchWorld& world,
                    const field::SeasonConfig& season, const MatchSetup& match_setup, uint64_t seed,
                    const std::string& out_dir,
                    const std::function<void(const TimelineEntry&)>& progress,
                    std::chrono::steady_clock::time_point wall_start);

}  // namespace

MatchResult RunMatchOn(std::unique_ptr<RobotIo> io, std::unique_ptr<strategy::Strategy> strategy,
                       const field::SeasonConfig& season, const field::RobotConfig& robot,
                       const MatchSetup& setup, uint64_t seed, const std::string& out_dir,
                       const std::function<void(const TimelineEntry&)>& progress) {
  const auto wall_start = std::chrono::steady_clock::now();
  const MatchSetup match_setup = SetupFor(*strategy, setup);
  MatchWorld world(std::move(io), season, robot, match_setup, seed, strategy->perceives());
  return RunLoop(std::move(strategy), world, season, match_setup, seed, out_dir, progress,
                 wall_start);
}

namespace {

MatchResult RunLoop(std::unique_ptr<strategy::Strategy> strategy, MatchWorld& world,
                    const field::SeasonConfig& season, const MatchSetup& match_setup, uint64_t seed,
                    const std::string& out_dir,
                    const std::function<void(const TimelineEntry&)>& progress,
                    std::chrono::steady_clock::time_point wall_start) {
  MatchResult result;
  result.season = season.season;
  result.seed = seed;
  result.strategy = strategy->name();
  result.frames = mapping::Describe(match_setup.frames);
  result.scenario = ScenarioName(match_setup.scenario);
  result.deadline_s = world.deadline_s();
  result.robot_io = world.io().Describe();
  result.truth_known = world.io().TrueObjects().has_value();
  result.points_start = world.Points().value_or(0);

  int idle_actions = 0;  // actions that took no time: a strategy going round in circles
  while (world.time_left_s() > 0.0) {
    // 1. What the robot believes now, and what the strategy makes of it.
    const strategy::Belief belief = world.Belief();
    const strategy::Action action = strategy->Next(belief, world.Context());
    TimelineEntry entry;
    entry.t_s = world.now_s();
    entry.action = strategy::ActionName(action.kind);
    entry.detail = action.why;
    entry.expected_s = action.expected_s;
    if (progress) progress(entry);

    // 2. Nothing worth doing: stand still until the deadline.
    if (action.kind == ActionKind::kIdle) {
      world.IdleToDeadline();
      entry.end_s = world.now_s();
      result.idle_s += entry.end_s - entry.t_s;
      result.timeline.push_back(entry);
      break;
    }

    // 3. The deadline, part one: an action that cannot finish in the time left does not start.
    if (action.expected_s > world.time_left_s()) {
      entry.action = "REFUSED";
      entry.detail = std::string(strategy::ActionName(action.kind)) + " needs " +
                     std::to_string(action.expected_s).substr(0, 4) + " s, " +
                     std::to_string(world.time_left_s()).substr(0, 4) + " s left: " + action.why;
      entry.ok = false;
      entry.end_s = world.now_s();
      result.timeline.push_back(entry);
      ++result.refused;
      strategy->Feedback(action, false);
      if (++idle_actions >= 20) {
        world.IdleToDeadline();
        break;
      }
      continue;
    }

    // 4. Carry it out. The deadline, part two: every motion inside stops when the clock
    //    reaches it (DriveControllerOptions::hard_deadline_s), whatever the action.
    world.set_action_label(entry.action + " " + action.why);
    std::optional<AttemptCheck> attempt;
    std::optional<std::vector<TrueObject>> objects_before;
    if (action.kind == ActionKind::kPick || action.kind == ActionKind::kScore ||
        (action.kind == ActionKind::kNavigate && action.push)) {
      attempt = CheckAttempt(world, action, belief);
      objects_before = world.io().TrueObjects();
    }
    bool ok = false;
    switch (action.kind) {
      case ActionKind::kObserve:
        if (action.look_heading) world.TurnTo(action.target.z());
        ok = world.Observe(action.frames) > 0 || !strategy->perceives();
        break;
      case ActionKind::kNavigate:
        // A drive that takes twice its estimate (and 3 s) is stuck or lost: give it up. (The
        // thesis's stops are not in the estimate: no limit for them.)
        ok = action.push ? world.Push(action.target,
                                      action.along_floor ? strategy::kFloorPushBackOff_m : -1.0)
                         : world.Navigate(
                               action.target, action.stop_spacing_m, action.frames,
                               action.stop_spacing_m > 0.0 ? 0.0 : 2.0 * action.expected_s + 3.0);
        break;
      case ActionKind::kPick:
        ok = world.Pick(action);
        break;
      case ActionKind::kScore:
        ok = world.Score(action);
        break;
      case ActionKind::kDrop:
        ok = world.Drop(action);
        break;
      case ActionKind::kIdle:
        break;
    }

    // 5. Tell the strategy, and account for the time.
    strategy->Feedback(action, ok);
    if (attempt) {
      attempt->ok = ok;
      const std::optional<std::vector<TrueObject>> objects_after = world.io().TrueObjects();
      if (objects_before && objects_after)
        JudgeAttempt(world.field(), *objects_before, *objects_after, &*attempt);
      // Given up before the approach (the look on arrival did not find the target): no pick
      // was tried, whatever the simulator's objects say.
      if (action.kind == ActionKind::kPick && world.pick_skipped()) attempt->outcome = "skipped";
      result.attempts.push_back(*attempt);
    }
    entry.ok = ok;
    entry.end_s = world.now_s();
    const double spent = entry.end_s - entry.t_s;
    switch (action.kind) {
      case ActionKind::kObserve:
        result.observe_s += spent;
        break;
      case ActionKind::kNavigate:
        result.drive_s += spent;
        break;
      default:
        result.score_s += spent;
        break;
    }
    result.timeline.push_back(entry);
    if (spent <= 1e-9 && ++idle_actions >= 20) {
      world.IdleToDeadline();
      break;
    }
  }

  // The report: points, timing, and SLAM-O against the simulator's truth.
  result.points = world.Points().value_or(0);
  result.overrun_s = world.overrun_s();
  result.duration_s = std::min(world.last_motion_s(), world.deadline_s() + result.overrun_s);
  result.pose_ate_m = PoseAte(world.samples());
  result.consistency = PoseConsistencyOf(world.samples());
  result.frames_taken = world.frames();
  result.moving_frames = world.moving_frames();
  result.replans = world.replans();
  result.relocalisations = world.relocalisations();
  result.rejected_frames = world.rejected_frames();
  result.odometry_scale = world.odometry_scale();
  result.objects = ScoreObjects(world);
  result.samples = world.samples();
  result.snapshots = world.snapshots();
  result.paths = world.paths();
  result.landmark_truth = world.landmark_truth();
  result.board = world.io().Status();
  for (int i = 0; i < world.slam().ekf().landmark_count(); ++i) {
    result.landmark_estimates.push_back(world.slam().ekf().landmark(i));
    result.landmark_covariances.push_back(world.slam().ekf().landmark_covariance(i));
  }
  result.field = world.field();
  if (!out_dir.empty()) world.slam().object_map().WriteBinary(out_dir + "/objects.bt");
  result.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace
}  // namespace slamo::autonomy
