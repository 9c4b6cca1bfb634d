#include "strategy/strategy.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <Eigen/Eigenvalues>

#include "field_configs/summary.h"
#include "platform/camera_geometry.h"
#include "platform/field_geometry.h"

namespace slamo::strategy {
namespace {

using platform::kPi;
// A staging pose within this distance counts as reached.
constexpr double kAtStage_m = 0.25;
// Position errors of the target and its neighbours the pick corridor allows for.
constexpr double kCorridorSlack_m = 0.05;
// Sequences less likely than this to end before the deadline are not considered.
constexpr double kMinInTime = 0.02;
// A staging pose for a tube's end counts as reached only this near the tube's axis.
constexpr double kTubeAcross_m = 0.05;

double Wrap(double a) {
  const double w = std::remainder(a, 2.0 * kPi);
  return w <= -kPi ? w + 2.0 * kPi : w;
}

double ObjectRadius(const field::SeasonConfig& season, const std::string& kind) {
  const field::ObjectType* type = season.FindObjectType(kind);
  return type ? type->size_m / 2.0 : 0.1;
}

bool InGoalStructure(const field::SeasonConfig& season, const Eigen::Vector2d& p) {
  for (const field::Goal& g : season.goals) {
    if (g.kind == field::GoalKind::kGoal && platform::GoalContains(g, p)) return true;
  }
  return false;
}

// One pick-and-score cycle (or only the score, for the held object), timed and valued.
struct Cycle {
  const ObjectBelief* object = nullptr;  // nullptr: the held object
  Eigen::Vector3d pick_stage = Eigen::Vector3d::Zero();
  int goal = -1;
  Eigen::Vector3d score_stage = Eigen::Vector3d::Zero();
  double seconds = 0.0;
  double gain = 0.0;         // points after - points before
  double probability = 0.0;  // of the pick and the release both succeeding
  int frames = 0;            // observed first
  // A knock: drive to pick_stage, push straight on to push_end and back to pick_stage
  // (score_stage, where the next cycle starts); the object drops into goal (a zone). Nothing is
  // held before or after.
  bool knock = false;
  Eigen::Vector3d push_end = Eigen::Vector3d::Zero();
  // A knock of an object on the floor pushed along it into a zone (FloorPushCycles), and the
  // seconds of its push and back-off.
  bool along_floor = false;
  double push_s = 0.0;
  double Value() const { return probability * gain; }
};

// What all the perceiving strategies share: candidate cycles, their timing and success
// probabilities, feedback on failures and the exploratory look.
class Base : public Strategy {
 public:
  explicit Base(const StrategyOptions& options) : options_(options) {}

  Action Next(const Belief& b, const StrategyContext& c) final {
    LearnDuration(b);
    // The planner's map may have changed since the last decision.
    score_stages_.clear();
    knock_ways_.clear();
    // Goals standing on movable objects (mobile goals) where those objects are seen.
    field::SeasonConfig believed = *c.season;
    MoveCarriedGoals(b, &believed);
    StrategyContext here = c;
    here.season = &believed;
    Action a = Choose(b, here);
    pending_ = a;
    pending_start_s_ = b.now_s;
    return a;
  }

  // Each goal standing on an object (Goal::on_object) moves to the tracked object of that type
  // nearest its spot in the file, within kCarrierMatch_m, each object taken once, nearest
  // pairs first; unseen, it stays where the file puts it.
  static void MoveCarriedGoals(const Belief& b, field::SeasonConfig* season) {
    constexpr double kCarrierMatch_m = 0.9;
    std::vector<std::tuple<double, size_t, size_t>> pairs;
    for (size_t g = 0; g < season->goals.size(); ++g) {
      const field::Goal& goal = season->goals[g];
      if (goal.on_object.empty()) continue;
      for (size_t k = 0; k < b.objects.size(); ++k) {
        if (b.objects[k].kind != goal.on_object) continue;
        const double d =
            (b.objects[k].position_m - Eigen::Vector2d(goal.center_m.x, goal.center_m.y)).norm();
        if (d < kCarrierMatch_m) pairs.emplace_back(d, g, k);
      }
    }
    std::sort(pairs.begin(), pairs.end());
    std::set<size_t> goals, objects;
    for (const auto& [d, g, k] : pairs) {
      if (goals.count(g) || objects.count(k)) continue;
      goals.insert(g), objects.insert(k);
      season->goals[g].center_m =
          field::Vec2{b.objects[k].position_m.x(), b.objects[k].position_m.y()};
    }
  }

  void Feedback(const Action& action, bool succeeded) override {
    // A push is not repeated: the object either came down or is not where it was believed.
    if (action.kind == ActionKind::kNavigate && action.push) knocked_.insert(action.object_id);
    if (succeeded) return;
    if (action.kind == ActionKind::kPick && action.object_id >= 0)
      ++failed_objects_[action.object_id];
    if (action.kind == ActionKind::kScore) ++failed_goals_[action.goal_index];
    if (action.kind == ActionKind::kNavigate) ++failed_targets_[Key(action.target)];
  }

 protected:
  virtual Action Choose(const Belief& b, const StrategyContext& c) = 0;

  // How long drives, picks and releases really take against the estimates (turns, stops to
  // look, arrival fixes, backing off a goal are not all in them), learned during the match:
  // the mean ratio of the time taken to the estimate, with a prior of 1 worth
  // kDurationPriorWeight actions. Cycles are timed with the estimates scaled by it, so that a
  // robot slower than its model does not start sequences it cannot finish.
  enum DurationClass { kDrive = 0, kPickClass = 1, kReleaseClass = 2 };
  static constexpr double kDurationPriorWeight = 2.0;
  double Scale(DurationClass k) const {
    if (!options_.learn_durations) return 1.0;
    return (kDurationPriorWeight + ratio_sum_[k]) / (kDurationPriorWeight + ratio_count_[k]);
  }
  void LearnDuration(const Belief& b) {
    if (!pending_) return;
    const Action a = *pending_;
    pending_.reset();
    // Cut short by the deadline, refused (no time passed), or too short to say anything: not
    // learned from.
    if (a.expected_s < 0.5 || b.now_s >= b.deadline_s - 1e-6 || b.now_s <= pending_start_s_ + 1e-6)
      return;
    int k = -1;
    if (a.kind == ActionKind::kNavigate) k = kDrive;
    if (a.kind == ActionKind::kPick) k = kPickClass;
    if (a.kind == ActionKind::kScore) k = kReleaseClass;
    if (k < 0) return;
    ratio_sum_[k] += std::clamp((b.now_s - pending_start_s_) / a.expected_s, 0.5, 3.0);
    ratio_count_[k] += 1.0;
  }

  // A look is not repeated towards the same 30-degree sector from the same half-metre cell.
  static long LookKey(const Eigen::Vector3d& pose, double heading) {
    return (std::lround(pose.x() * 2.0) * 100 + std::lround(pose.y() * 2.0)) * 100 +
           std::lround(heading / (kPi / 6.0));
  }
  static long Key(const Eigen::Vector3d& p) {
    return std::lround(p.x() * 20.0) * 100000 + std::lround(p.y() * 20.0);
  }

  // Whether a robot at `pose` starts the pick (of `object`) or the release (into goal
  // `goal_index`, object nullptr) from where it stands, without driving to `stage` first: the
  // pick and the release turn to their target and drive the rest. A pick also needs the object
  // no nearer than where the intake takes it: closer, the turn to it would sweep it with the
  // robot's corners (after a drop, the robot stands beside it). A tube takes an object only
  // from a robot driving into one of its ends along the axis (platform::GoalTakes): from
  // beside its stage the release would come in at an angle and miss, so there the robot must
  // stand on the axis's line, not past the stage.
  static bool AtStage(const StrategyContext& c, const Eigen::Vector3d& pose,
                      const Eigen::Vector3d& stage, const ObjectBelief* object, bool knock,
                      int goal_index) {
    if ((pose.head<2>() - stage.head<2>()).norm() >= kAtStage_m) return false;
    if (object && !knock) {
      const double r = ObjectRadius(*c.season, object->kind);
      return (object->position_m - pose.head<2>()).norm() >=
             PickDistance(*c.robot, r) - kAtStage_m / 10.0;
    }
    if (object || goal_index < 0) return true;
    const field::Goal& goal = c.season->goals[goal_index];
    if (goal.kind != field::GoalKind::kGoal || goal.entry != field::Goal::Entry::kEnds) return true;
    const Eigen::Vector2d axis(std::cos(stage.z()), std::sin(stage.z()));
    const Eigen::Vector2d rel = pose.head<2>() - stage.head<2>();
    const double across = std::abs(rel.x() * axis.y() - rel.y() * axis.x());
    return across <= kTubeAcross_m && rel.dot(axis) <= kTubeAcross_m;
  }

  // Seconds to drive from `from` to a cycle's first stage. When `from` is where the robot
  // stands (the belief's pose) and the pick, release or push starts from there (AtStage), only
  // the turn to the stage's heading: the action turns and drives the rest itself, within its
  // own estimate, while the travel field charges three settles even for the stage itself (and,
  // before 501be41, a turn round and back for a stage 3 cm behind: 2 s on Push Back, after
  // which the cycle no longer fitted). Not while the scripted route plans (plans_route_): it
  // drives to every stage it planned.
  std::optional<double> StageTravel(const Belief& b, const StrategyContext& c,
                                    const Eigen::Vector3d& from, const Eigen::Vector3d& stage,
                                    const ObjectBelief* object, bool knock, int goal) const {
    if (!plans_route_ && from == b.pose && AtStage(c, from, stage, object, knock, goal)) {
      return std::abs(Wrap(stage.z() - from.z())) * 180.0 / kPi / c.robot->drive.turn_rate_dps;
    }
    return c.travel_time_s(from, stage);
  }
  bool plans_route_ = false;

  // Seconds for the final straight approach of margin_m and the settling around it.
  double ApproachSeconds(const StrategyContext& c) const {
    return ApproachSeconds(c, options_.approach_margin_m);
  }
  static double ApproachSeconds(const StrategyContext& c, double margin_m) {
    return margin_m / c.robot->drive.cruise_speed_mps + 0.5;
  }
  // A pick's staging margin: approach_margin_m, or (StrategyOptions::pick_in_view) further out
  // where the camera sees the object whole, so that the look on arrival checks it is still
  // there (a camera that looks down loses near objects below its view), by the error an
  // arrival leaves on top (MatchSetup::arrival_slack_m's default, half approach_margin_m).
  double PickMargin(const StrategyContext& c, const std::string& kind) const {
    const field::ObjectType* type = c.season->FindObjectType(kind);
    if (!options_.pick_in_view || !perceives() || !type) return options_.approach_margin_m;
    auto it = pick_margins_.find(kind);
    if (it == pick_margins_.end()) {
      const double r = type->size_m / 2.0;
      const double in_view =
          platform::NearestWholeInView(c.robot->camera, type->size_m, type->height_m,
                                       options_.view_margin_rad, PickDistance(*c.robot, r) + 1.0);
      const double slack = 0.5 * options_.approach_margin_m;
      it = pick_margins_
               .emplace(kind, std::max(options_.approach_margin_m,
                                       in_view + slack - PickDistance(*c.robot, r)))
               .first;
    }
    return it->second;
  }
  mutable std::map<std::string, double> pick_margins_;  // PickMargin per kind (one robot)

  // Position variance (worst axis) after n more frames, by the iterated-frame model.
  double PoseVarianceAfter(const Belief& b, int frames) const {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(
        b.pose_covariance.topLeftCorner<2, 2>());
    const double v0 = std::max(eig.eigenvalues().maxCoeff(), 1e-8);
    if (frames <= 0) return v0;
    const double w = options_.frame_white_sigma_m, bias = options_.frame_bias_sigma_m;
    const double vobs = w * w / frames + bias * bias;
    return 1.0 / (1.0 / v0 + 1.0 / vobs);
  }

  // Heading error adds lateral error growing with the distance driven; approximated at the
  // approach distance.
  // With a learned model: at the stage, facing the target, range_m from it.
  double PickProbability(const Belief& b, const ObjectBelief& o, int frames, double range_m) const {
    const double pose_var = PoseVarianceAfter(b, frames);
    if (options_.learned_success) {
      if (const std::optional<double> p =
              options_.learned_success("PICK", o.kind, range_m, 0.0, std::sqrt(pose_var)))
        return *p * o.confidence;
    }
    const double heading_var = b.pose_covariance(2, 2);
    Eigen::Matrix2d cov =
        o.covariance + Eigen::Matrix2d::Identity() * (pose_var + heading_var * 0.25);
    return SuccessProbability(cov, options_.pick_tolerance_m) * o.confidence;
  }

  double ScoreProbability(const Belief& b, const StrategyContext& c, int goal, int frames,
                          const std::string& kind, const Eigen::Vector3d& stage) const {
    const field::Goal& g = c.season->goals[goal];
    if (options_.learned_success) {
      const double range = std::hypot(g.center_m.x - stage.x(), g.center_m.y - stage.y());
      if (const std::optional<double> p = options_.learned_success(
              "SCORE", kind, range, 0.0, std::sqrt(PoseVarianceAfter(b, frames))))
        return *p;
    }
    // A goal structure forgives its half-width across the way in less the drop's offset (a
    // box's radius_m is 0: its narrower half-size); a zone forgives more.
    const double half = platform::GoalHalfSize(g);
    const double tolerance = g.kind == field::GoalKind::kGoal ? std::max(0.03, 0.6 * half) : 0.3;
    const Eigen::Matrix2d cov = Eigen::Matrix2d::Identity() *
                                (PoseVarianceAfter(b, frames) + b.pose_covariance(2, 2) * 0.25);
    return SuccessProbability(cov, tolerance);
  }

  // Half the goal structure's extent across an approach heading `heading_rad`: a box's
  // footprint projected on the approach's sideways axis, a cylinder's radius, a stake's
  // carrier.
  static double GoalHalfAcross(const field::SeasonConfig& season, const field::Goal& g,
                               double heading_rad) {
    if (!g.on_object.empty()) return platform::CarrierRadius(season, g);
    if (g.shape == field::SolidShape::kCylinder) return g.radius_m;
    const double rel = heading_rad - g.yaw_deg * kPi / 180.0;
    return 0.5 * (g.size_m.x * std::abs(std::sin(rel)) + g.size_m.y * std::abs(std::cos(rel)));
  }

  // Whether a goal is a structure raised off the floor (objects lower than it pass under).
  static bool RaisedGoal(const field::SeasonConfig& season, const field::Goal* goal) {
    return goal && platform::GoalIsRaised(season, *goal);
  }

  // Whether the final straight approach from `stage` over `length_m` is free of known
  // objects (other than `except`, and those smaller than min_size_m): an object pinned between
  // the bumper and a goal stops the robot short, so such approaches are not offered.
  // Into a goal structure, only an object the bumper pushes against the structure stops the
  // robot: one further to the side than the structure's half-width across the approach (plus
  // its own radius) is pushed along beside the structure, and the release still goes in; one
  // straight ahead is pushed under the structure when it is raised above the object (Push
  // Back's upper centre goal, 0.30 m up, over 0.08 m blocks), and does not stop the robot
  // either.
  static bool CorridorFree(const Belief& b, const StrategyContext& c, const Eigen::Vector3d& stage,
                           double length_m, int except, double min_size_m = 0.0,
                           const field::Goal* goal = nullptr,
                           const std::function<bool(const ObjectBelief&)>& passes = {}) {
    const Eigen::Vector2d dir(std::cos(stage.z()), std::sin(stage.z()));
    const double goal_half_across = goal && goal->kind == field::GoalKind::kGoal
                                        ? GoalHalfAcross(*c.season, *goal, stage.z())
                                        : std::numeric_limits<double>::infinity();
    for (const ObjectBelief& o : b.objects) {
      if (o.id == except || (passes && passes(o))) continue;
      // The object the goal stands on is what the robot releases onto.
      if (goal && !goal->on_object.empty() && o.kind == goal->on_object &&
          (o.position_m - Eigen::Vector2d(goal->center_m.x, goal->center_m.y)).norm() <
              platform::CarrierRadius(*c.season, *goal)) {
        continue;
      }
      const double r = ObjectRadius(*c.season, o.kind);
      if (2.0 * r < min_size_m) continue;
      const Eigen::Vector2d rel = o.position_m - stage.head<2>();
      const double along = rel.dot(dir);
      const double side = std::abs(rel.x() * dir.y() - rel.y() * dir.x());
      if (along <= -r || along >= length_m + c.robot->length_m / 2.0 + r ||
          side >= c.robot->width_m / 2.0 + r) {
        continue;
      }
      // Beside the structure (or ahead, under a raised one): pushed along only where there is
      // room past the bumper's last position (not against a wall, as at the High Stakes wall
      // stakes, nor against a structure the object does not pass under).
      if (side >= goal_half_across + r || RaisedGoal(*c.season, goal)) {
        const double sign = rel.x() * dir.y() - rel.y() * dir.x() < 0.0 ? 1.0 : -1.0;
        const Eigen::Vector2d left(-dir.y(), dir.x());
        const Eigen::Vector2d pushed = stage.head<2>() +
                                       (length_m + c.robot->length_m / 2.0 + 2.0 * r) * dir +
                                       sign * side * left;
        const double half = c.season->HalfSize() - r;
        const field::ObjectType* type = c.season->FindObjectType(o.kind);
        if (std::abs(pushed.x()) < half && std::abs(pushed.y()) < half &&
            !platform::PointBlocksObject(*c.season, pushed, r, type ? type->height_m : 0.0)) {
          continue;
        }
      }
      return false;
    }
    return true;
  }

  // The final approach of a pick from `stage`, as far as the intake still takes the object
  // (the bumper its reach short of the object's near edge), overlaps nothing fixed: the
  // perimeter, a goal's end beside the object. A robot that meets a structure sooner stops
  // short, its wheels slipping, and the intake takes nothing (Push Back's blocks beside a long
  // goal's end); from another side the approach may be free.
  bool ApproachIsFree(const StrategyContext& c, const Eigen::Vector3d& stage) const {
    return ApproachIsFree(c, stage, options_.approach_margin_m);
  }
  bool ApproachIsFree(const StrategyContext& c, const Eigen::Vector3d& stage,
                      double margin_m) const {
    const double to_go_m = margin_m - c.robot->intake.reach_m / 2.0;
    const Eigen::Vector2d dir(std::cos(stage.z()), std::sin(stage.z()));
    const Eigen::Vector2d mid = stage.head<2>() + 0.5 * to_go_m * dir;
    return platform::FootprintIsFree(*c.season, platform::Pose2D{mid.x(), mid.y(), stage.z()},
                                     c.robot->length_m + to_go_m, c.robot->width_m,
                                     c.robot->height_m);
  }

  // ScoreStages for goal g and an object of radius r. They depend only on the season, the robot
  // and the planner's map, none of which changes during a decision, while a decision asks for
  // them for every candidate cycle: computed once per decision (Next() forgets them).
  const std::vector<Eigen::Vector3d>& StagesFor(const StrategyContext& c, int g, double r) const {
    const auto key = std::make_pair(g, r);
    auto it = score_stages_.find(key);
    if (it == score_stages_.end())
      it = score_stages_.emplace(key, ScoreStages(c, g, r, options_.approach_margin_m)).first;
    return it->second;
  }

  // The goals an object scores in, with their best staging pose from `from` and the time to
  // get there and release (from the robot's own pose, a stage it releases from without driving
  // there first costs only the turn to its heading: StageTravel).
  struct GoalChoice {
    int goal = -1;
    Eigen::Vector3d stage;
    double seconds = 0.0;
    int points = 0;
  };
  std::vector<GoalChoice> GoalChoices(const Belief& b, const StrategyContext& c,
                                      const std::string& kind, const std::string& colour,
                                      const Eigen::Vector3d& from, int except) const {
    std::vector<GoalChoice> out;
    const double r = ObjectRadius(*c.season, kind);
    for (int g = 0; g < static_cast<int>(c.season->goals.size()); ++g) {
      const int points = GoalPoints(*c.season, g, kind, colour, c.alliance);
      if (points <= 0) continue;
      auto failed = failed_goals_.find(g);
      if (failed != failed_goals_.end() && failed->second >= 2) continue;
      GoalChoice best;
      // Into a floor zone, an object narrower than the robot on the way is pushed along and the
      // release still lands in the zone: only wider ones block the approach.
      const double blocking =
          c.season->goals[g].kind == field::GoalKind::kZone ? c.robot->width_m : 0.0;
      for (const Eigen::Vector3d& stage : StagesFor(c, g, r)) {
        if (failed_targets_.count(Key(stage))) continue;
        if (!CorridorFree(b, c, stage, options_.approach_margin_m + r, except, blocking,
                          &c.season->goals[g])) {
          continue;
        }
        const std::optional<double> t = StageTravel(b, c, from, stage, nullptr, false, g);
        if (!t) continue;
        const double seconds =
            *t * Scale(kDrive) +
            (ApproachSeconds(c) + c.robot->intake.release_s) * Scale(kReleaseClass);
        if (best.goal < 0 || seconds < best.seconds) best = {g, stage, seconds, points};
      }
      if (best.goal >= 0) out.push_back(best);
    }
    return out;
  }

  // Points our objects lose when the robot drives straight from `from` to `to`: an object
  // it may push (not an obstacle on the planner's map) earning us points where it lies, met
  // within half the robot's width of its line, is carried to the bumper's end of the drive;
  // what it earns there is subtracted. (The planner's path is the straight line unless an
  // obstacle bends it.)
  // Whether the straight drive from `from` to `to` pushes object o (one it may push, not an
  // obstacle on the planner's map, met within half the robot's width of its line).
  static bool OnTheWay(const StrategyContext& c, const Eigen::Vector3d& from,
                       const Eigen::Vector3d& to, const ObjectBelief& o) {
    const Eigen::Vector2d d = to.head<2>() - from.head<2>();
    const double length = d.norm();
    if (length < 0.05 || !c.is_clear(o.position_m)) return false;
    const Eigen::Vector2d dir = d / length;
    const double r = ObjectRadius(*c.season, o.kind);
    const Eigen::Vector2d rel = o.position_m - from.head<2>();
    const double along = rel.dot(dir);
    const double side = std::abs(rel.x() * dir.y() - rel.y() * dir.x());
    return along > 0.0 && along < length + c.robot->length_m / 2.0 &&
           side < c.robot->width_m / 2.0 + r;
  }

  double PushLoss(const Belief& b, const StrategyContext& c, const Eigen::Vector3d& from,
                  const Eigen::Vector3d& to) const {
    const Eigen::Vector2d d = to.head<2>() - from.head<2>();
    const double length = d.norm();
    if (length < 0.05) return 0.0;
    const Eigen::Vector2d dir = d / length;
    double loss = 0.0;
    for (const ObjectBelief& o : b.objects) {
      if (!OnTheWay(c, from, to, o)) continue;
      const int now = FloorPoints(*c.season, o.position_m, o.kind, o.colour, c.alliance);
      if (now <= 0) continue;
      const double r = ObjectRadius(*c.season, o.kind);
      const double along = (o.position_m - from.head<2>()).dot(dir);
      const Eigen::Vector2d carried = to.head<2>() + (c.robot->length_m / 2.0 + r) * dir +
                                      (o.position_m - from.head<2>() - along * dir);
      const int then = FloorPoints(*c.season, carried, o.kind, o.colour, c.alliance);
      loss += std::max(0, now - then);
    }
    return loss;
  }

  bool Scores(const StrategyContext& c, const ObjectBelief& o) const {
    if (!field::ScoresFor(*c.season, o.colour, c.alliance)) return false;
    if (InGoalStructure(*c.season, o.position_m)) return false;
    auto failed = failed_objects_.find(o.id);
    return failed == failed_objects_.end() || failed->second < 2;
  }

  // The raised structure (one robots pass under) an object lies on: an object that does not fit
  // under it and whose centre is within its radius of the structure cannot stand on the floor
  // there, so it is on top (a large ball on the Toss Up barrier). nullptr for the others.
  static const field::Structure* RaisedOn(const field::SeasonConfig& season,
                                          const std::string& kind, const Eigen::Vector2d& p) {
    const field::ObjectType* type = season.FindObjectType(kind);
    if (!type) return nullptr;
    for (const field::Structure& s : season.structures) {
      if (s.PassUnder() && type->height_m > s.z_min_m &&
          platform::DistanceToStructure(s, p) < type->size_m / 2.0) {
        return &s;
      }
    }
    return nullptr;
  }

  // A push (a knock, or along the floor) carries the object when the bumper meets it within
  // half its width of its centre.
  double PushProbability(const Belief& b, const StrategyContext& c, const ObjectBelief& o,
                         int frames) const {
    const double pose_var = PoseVarianceAfter(b, frames);
    const Eigen::Matrix2d cov =
        o.covariance + Eigen::Matrix2d::Identity() * (pose_var + b.pose_covariance(2, 2) * 0.25);
    return SuccessProbability(cov, c.robot->width_m / 2.0) * o.confidence;
  }

  // Knocking an object off the raised structure it lies on: for each way across the structure
  // (a box's thin axis), the robot drives straight at it until its bumper is kKnockGap_m short
  // of the structure (or of anything else fixed); its bumper has pushed the object on by its
  // radius, and the object drops where it then stands. (Pressed that close the robot cannot
  // turn in place: the next drive backs out first, MatchWorld::Navigate.)
  std::vector<Cycle> KnockCycles(const Belief& b, const StrategyContext& c, const ObjectBelief& o,
                                 const field::Structure& s, const Eigen::Vector3d& from,
                                 int frames) const {
    std::vector<Cycle> out;
    if (knocked_.count(o.id) || s.shape != field::SolidShape::kBox) return out;
    for (const KnockWay& way : KnockWaysFor(c, o, s)) {
      if (failed_targets_.count(Key(way.stage))) continue;
      const std::optional<double> t = StageTravel(b, c, from, way.stage, &o, true, way.goal);
      if (!t) continue;
      Cycle cycle;
      cycle.object = &o;
      cycle.knock = true;
      cycle.pick_stage = way.stage;
      cycle.push_end = way.push_end;
      cycle.score_stage = way.stage;
      cycle.goal = way.goal;
      cycle.seconds = (*t + PushSeconds(c)) * Scale(kDrive) + frames / c.frame_rate_hz;
      cycle.gain = way.points;  // on top of a structure it lies in no zone
      cycle.probability = PushProbability(b, c, o, frames);
      cycle.frames = frames;
      out.push_back(cycle);
    }
    return out;
  }

  // A way to knock object o off box structure s: the stage to start the run-in from and where
  // the push ends (headings across the structure), the zone the object lands in and its points.
  struct KnockWay {
    Eigen::Vector3d stage, push_end;
    int goal = -1, points = 0;
  };
  // The ways across (at most two), from the season, the robot and the planner's map only: kept
  // for the decision per object and position, since every candidate cycle asks again (Next()
  // forgets them).
  const std::vector<KnockWay>& KnockWaysFor(const StrategyContext& c, const ObjectBelief& o,
                                            const field::Structure& s) const {
    const auto key = std::make_tuple(o.id, o.position_m.x(), o.position_m.y(), &s);
    auto cached = knock_ways_.find(key);
    if (cached != knock_ways_.end()) return cached->second;
    std::vector<KnockWay> ways;
    const double r = ObjectRadius(*c.season, o.kind);
    const double yaw = s.yaw_deg * kPi / 180.0 + (s.size_m.x <= s.size_m.y ? 0.0 : kPi / 2.0);
    const double half = c.season->HalfSize();
    constexpr double kKnockGap_m = 0.02;
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector2d dir = sign * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
      const double heading_rad = std::atan2(dir.y(), dir.x());
      const double reach = std::hypot(c.robot->length_m, c.robot->width_m) / 2.0 + kKnockGap_m;
      std::optional<Eigen::Vector2d> end;
      for (double back = 0.0; back <= 1.0 && !end; back += 0.01) {
        const Eigen::Vector2d p = o.position_m - back * dir;
        if (std::abs(p.x()) < half - reach && std::abs(p.y()) < half - reach &&
            platform::FootprintIsFree(*c.season, platform::Pose2D{p.x(), p.y(), heading_rad},
                                      c.robot->length_m + 2.0 * kKnockGap_m,
                                      c.robot->width_m + 2.0 * kKnockGap_m, c.robot->height_m)) {
          end = p;
        }
      }
      if (!end) continue;
      const Eigen::Vector2d front = *end + dir * (c.robot->length_m / 2.0);
      if ((front - o.position_m).dot(dir) < -r) continue;  // the bumper would not reach it
      Eigen::Vector2d land = front + dir * (r + 0.01);
      if (platform::DistanceToStructure(s, land) <= 0.0) continue;  // still on top
      // Off the top, it rolls on over the edge to rest on the floor clear of the structure.
      const double height = c.season->FindObjectType(o.kind)->height_m;
      for (int k = 0; k < 50 && platform::PointBlocksObject(*c.season, land, r, height); ++k)
        land += 0.01 * dir;
      if (std::abs(land.x()) > half - r || std::abs(land.y()) > half - r) continue;
      int goal = -1, points = 0;
      for (int g = 0; g < static_cast<int>(c.season->goals.size()); ++g) {
        if (c.season->goals[g].kind != field::GoalKind::kZone) continue;
        if (!platform::GoalContains(c.season->goals[g], land)) continue;
        const int p = GoalPoints(*c.season, g, o.kind, o.colour, c.alliance);
        if (p > points) goal = g, points = p;
      }
      if (goal < 0) continue;
      const double heading = heading_rad;
      const Eigen::Vector2d stage = *end - options_.push_run_in_m * dir;
      if (!c.is_clear(stage)) continue;
      ways.push_back({Eigen::Vector3d(stage.x(), stage.y(), heading),
                      Eigen::Vector3d(end->x(), end->y(), heading), goal, points});
    }
    return knock_ways_.emplace(key, std::move(ways)).first->second;
  }

  // Pushing object o along the floor into a zone that pays more for it: for each such box
  // zone, the robot lines up behind o on the line to the nearest point kPushInside_m inside
  // the zone (beyond the object's radius), drives straight until the object's centre is there
  // (or until something fixed stops the robot, if the object is then still inside), and backs
  // out kFloorPushBackOff_m (the knock's push navigation). The bumper carries a ball met within
  // half the robot's width of its centre (the simulator's push, SimField), so the success model
  // is the knock's. Not offered when something fixed stops the object on the way, or a known
  // object of the other alliance's lies in the robot's way (it would be pushed in too).
  std::vector<Cycle> FloorPushCycles(const Belief& b, const StrategyContext& c,
                                     const ObjectBelief& o, const Eigen::Vector3d& from,
                                     int frames) const {
    constexpr double kPushInside_m = 0.05;
    std::vector<Cycle> out;
    if (knocked_.count(o.id)) return out;  // a push is not repeated
    const field::ObjectType* type = c.season->FindObjectType(o.kind);
    if (!type) return out;
    const double r = type->size_m / 2.0;
    const double before = FloorPoints(*c.season, o.position_m, o.kind, o.colour, c.alliance);
    const double half = c.season->HalfSize();
    const double reach = c.robot->length_m / 2.0 + r;  // robot centre to object centre, touching
    for (int g = 0; g < static_cast<int>(c.season->goals.size()); ++g) {
      // Into a floor zone, or in under a raised goal's frame (the simulator's SimField::PushOut
      // counts it scored there).
      const field::Goal& zone = c.season->goals[g];
      if (zone.shape != field::SolidShape::kBox) continue;
      if (zone.kind != field::GoalKind::kZone &&
          (zone.entry == field::Goal::Entry::kEnds || !platform::GoalIsRaised(*c.season, zone))) {
        continue;
      }
      const int points = GoalPoints(*c.season, g, o.kind, o.colour, c.alliance);
      if (points <= before) continue;
      // The nearest point of the zone shrunk by the object's radius and kPushInside_m.
      const double yaw = zone.yaw_deg * kPi / 180.0;
      const Eigen::Vector2d centre(zone.center_m.x, zone.center_m.y);
      const Eigen::Vector2d ax(std::cos(yaw), std::sin(yaw)), ay(-std::sin(yaw), std::cos(yaw));
      const Eigen::Vector2d rel = o.position_m - centre;
      const double hx = zone.size_m.x / 2.0 - r - kPushInside_m;
      const double hy = zone.size_m.y / 2.0 - r - kPushInside_m;
      if (hx <= 0.0 || hy <= 0.0) continue;
      const Eigen::Vector2d land =
          centre + std::clamp(rel.dot(ax), -hx, hx) * ax + std::clamp(rel.dot(ay), -hy, hy) * ay;
      const double length = (land - o.position_m).norm();
      if (length < 0.01 || length > options_.max_floor_push_m) continue;
      if (std::abs(land.x()) > half - r || std::abs(land.y()) > half - r) continue;
      const Eigen::Vector2d dir = (land - o.position_m) / length;
      const double heading = std::atan2(dir.y(), dir.x());
      const Eigen::Vector2d contact = o.position_m - reach * dir;
      const Eigen::Vector2d stage = contact - options_.push_run_in_m * dir;
      if (!c.is_clear(stage)) continue;
      // The robot drives from the stage on while its footprint meets nothing fixed, up to
      // where the object would reach the landing point; something it does not pass under (the
      // Toss Up barrier, for a robot taller than its clearance) ends the push short, and the
      // object, pushed kPushGap_m ahead of the bumper, must then still lie in the zone.
      constexpr double kPushGap_m = 0.01, kStep_m = 0.01, kLandMargin_m = 0.02;
      const double wanted = (land - reach * dir - stage).norm();
      double run = -1.0;
      for (double d = 0.0; d <= wanted + 1e-9; d += kStep_m) {
        const Eigen::Vector2d p = stage + d * dir;
        if (!platform::FootprintIsFree(*c.season, platform::Pose2D{p.x(), p.y(), heading},
                                       c.robot->length_m, c.robot->width_m, c.robot->height_m)) {
          break;
        }
        run = d;
      }
      const double pushed_m = run - options_.push_run_in_m;  // how far the object goes
      if (pushed_m <= 0.0) continue;
      const Eigen::Vector2d end = stage + run * dir;
      const Eigen::Vector2d lands = o.position_m + (pushed_m + kPushGap_m) * dir;
      if (!platform::GoalContains(zone, lands - kLandMargin_m * dir)) continue;
      // The object's own way: nothing fixed stops it (a large ball does not pass under the
      // barrier).
      bool free = true;
      for (double d = 0.0; free && d <= pushed_m + 1e-9; d += 0.02) {
        free = !platform::PointBlocksObject(*c.season, o.position_m + d * dir, r, type->height_m);
      }
      if (!free) continue;
      const Eigen::Vector3d stage_pose(stage.x(), stage.y(), heading);
      if (failed_targets_.count(Key(stage_pose))) continue;
      // Known objects the bumper would meet on the way are pushed along too: ours may be (they
      // earn more beyond as well); the other alliance's must not be (it would score them).
      bool clear = true;
      for (const ObjectBelief& other : b.objects) {
        if (other.id == o.id || field::ScoresFor(*c.season, other.colour, c.alliance)) continue;
        const double ro = ObjectRadius(*c.season, other.kind);
        const Eigen::Vector2d rel_o = other.position_m - stage;
        const double along = rel_o.dot(dir);
        const double side = std::abs(rel_o.x() * dir.y() - rel_o.y() * dir.x());
        if (along > -ro && along < run + c.robot->length_m / 2.0 + ro &&
            side < c.robot->width_m / 2.0 + ro) {
          clear = false;
          break;
        }
      }
      if (!clear) continue;
      const std::optional<double> t = StageTravel(b, c, from, stage_pose, &o, true, g);
      if (!t) continue;
      Cycle cycle;
      cycle.object = &o;
      cycle.knock = true;
      cycle.along_floor = true;
      cycle.pick_stage = stage_pose;
      cycle.push_end = Eigen::Vector3d(end.x(), end.y(), heading);
      const Eigen::Vector2d after = end - kFloorPushBackOff_m * dir;  // where the next begins
      cycle.score_stage = Eigen::Vector3d(after.x(), after.y(), heading);
      cycle.goal = g;
      cycle.push_s = (run + kFloorPushBackOff_m) / c.robot->drive.cruise_speed_mps + 1.0;
      cycle.seconds = (*t + cycle.push_s) * Scale(kDrive) + frames / c.frame_rate_hz;
      cycle.gain = points - before;
      cycle.probability = PushProbability(b, c, o, frames);
      cycle.frames = frames;
      out.push_back(cycle);
    }
    return out;
  }

  // The run-in, and back out the same way (pressed against the structure the robot could not
  // turn, and the way it came is clear).
  double PushSeconds(const StrategyContext& c) const {
    return 2.0 * options_.push_run_in_m / c.robot->drive.cruise_speed_mps + 1.0;
  }

  // Cycles for one object from `from`: pick it, then each goal that takes it; or knock it off
  // the raised structure it lies on.
  std::vector<Cycle> ObjectCycles(const Belief& b, const StrategyContext& c, const ObjectBelief& o,
                                  const Eigen::Vector3d& from, int frames) const {
    std::vector<Cycle> out;
    if (!Scores(c, o)) return out;
    if (const field::Structure* raised = RaisedOn(*c.season, o.kind, o.position_m))
      return KnockCycles(b, c, o, *raised, from, frames);
    if (options_.floor_pushes) out = FloorPushCycles(b, c, o, from, frames);
    const double r = ObjectRadius(*c.season, o.kind);
    // The intake takes the object whose near edge is nearest the bumper across the robot's
    // width: approach from a side where nothing else lies between the stage and the target,
    // nor beside the target with its near edge as near (kCorridorSlack_m for the errors of
    // both positions). Objects of the target's kind and colour do not close the approach:
    // whichever of them the intake meets first scores the same, and the cycle targets that one
    // (Push Back's blocks lie in touching groups, every approach to one passing another).
    const auto same = [&](const ObjectBelief& x) {
      return x.kind == o.kind && x.colour == o.colour && Scores(c, x);
    };
    const double margin = PickMargin(c, o.kind);
    const double corridor = margin + c.robot->intake.reach_m / 2.0 + kCorridorSlack_m;
    std::optional<Eigen::Vector3d> stage =
        PickStage(c, o.position_m, r, from.head<2>(), margin, [&](const Eigen::Vector3d& s) {
          return ApproachIsFree(c, s, margin) &&
                 CorridorFree(b, c, s, corridor, o.id, 0.0, nullptr, same);
        });
    if (!stage) return out;
    const Eigen::Vector2d dir(std::cos(stage->z()), std::sin(stage->z()));
    const ObjectBelief* target = &o;
    double nearest = (o.position_m - stage->head<2>()).dot(dir);
    for (const ObjectBelief& x : b.objects) {
      if (x.id == o.id || !same(x)) continue;
      const Eigen::Vector2d rel = x.position_m - stage->head<2>();
      const double along = rel.dot(dir);
      const double side = std::abs(rel.x() * dir.y() - rel.y() * dir.x());
      if (along > -r && along < nearest && side < c.robot->width_m / 2.0 + r)
        target = &x, nearest = along;
    }
    const ObjectBelief& t_o = *target;
    if (target != &o) {
      // The stage moves back along the same heading to the one nearest the bumper, whose
      // corridor must be free in turn.
      const Eigen::Vector2d at = t_o.position_m - (PickDistance(*c.robot, r) + margin) * dir;
      stage = Eigen::Vector3d(at.x(), at.y(), stage->z());
      if (!c.is_clear(at) || !ApproachIsFree(c, *stage, margin) ||
          !CorridorFree(b, c, *stage, corridor, t_o.id, 0.0, nullptr, same))
        return out;
    }
    if (failed_targets_.count(Key(*stage))) return out;
    const std::optional<double> t = StageTravel(b, c, from, *stage, &t_o, false, -1);
    if (!t) return out;
    const double pick_s = *t * Scale(kDrive) +
                          (ApproachSeconds(c, margin) + c.robot->intake.pick_s) * Scale(kPickClass);
    const double before = FloorPoints(*c.season, t_o.position_m, t_o.kind, t_o.colour, c.alliance);
    const Eigen::Vector3d picked_at(t_o.position_m.x() - dir.x() * PickDistance(*c.robot, r),
                                    t_o.position_m.y() - dir.y() * PickDistance(*c.robot, r),
                                    stage->z());
    for (const GoalChoice& g : GoalChoices(b, c, t_o.kind, t_o.colour, picked_at, t_o.id)) {
      Cycle cycle;
      cycle.object = &t_o;
      cycle.pick_stage = *stage;
      cycle.goal = g.goal;
      cycle.score_stage = g.stage;
      cycle.seconds = pick_s + g.seconds + frames / c.frame_rate_hz;
      cycle.gain = g.points - before;
      cycle.probability =
          PickProbability(b, t_o, frames, (t_o.position_m - stage->head<2>()).norm()) *
          ScoreProbability(b, c, g.goal, frames, t_o.kind, g.stage);
      cycle.frames = frames;
      out.push_back(cycle);
    }
    return out;
  }

  std::vector<Cycle> HeldCycles(const Belief& b, const StrategyContext& c, int frames) const {
    std::vector<Cycle> out;
    for (const GoalChoice& g : GoalChoices(b, c, b.held->kind, b.held->colour, b.pose, -1)) {
      Cycle cycle;
      cycle.goal = g.goal;
      cycle.score_stage = g.stage;
      cycle.seconds = g.seconds + frames / c.frame_rate_hz;
      cycle.gain = g.points;  // a held object counts nothing until released
      cycle.probability = ScoreProbability(b, c, g.goal, frames, b.held->kind, g.stage);
      cycle.frames = frames;
      out.push_back(cycle);
    }
    return out;
  }

  // The first action of a cycle, given where the robot is.
  Action FirstAction(const Belief& b, const StrategyContext& c, const Cycle& cycle,
                     double expected_points) const {
    Action a;
    a.expected_points = expected_points;
    if (cycle.frames > 0) {
      a.kind = ActionKind::kObserve;
      a.frames = cycle.frames;
      a.expected_s = cycle.frames / c.frame_rate_hz;
      a.why = "pose sigma " + std::to_string(std::sqrt(PoseVarianceAfter(b, 0))).substr(0, 5) +
              " m: observe before the cycle";
      return a;
    }
    const Eigen::Vector3d stage = cycle.object ? cycle.pick_stage : cycle.score_stage;
    const bool at_stage = AtStage(c, b.pose, stage, cycle.object, cycle.knock, cycle.goal);
    if (cycle.knock) {
      a.kind = ActionKind::kNavigate;
      a.object_id = cycle.object->id;
      a.object_kind = cycle.object->kind;
      a.object_colour = cycle.object->colour;
      a.object_m = cycle.object->position_m;
      a.goal_index = cycle.goal;
      a.along_floor = cycle.along_floor;
      const std::string what =
          cycle.object->colour + " " + cycle.object->kind + " #" + std::to_string(cycle.object->id);
      if (!at_stage) {
        a.target = stage;
        a.expected_s = c.travel_time_s(b.pose, stage).value_or(0.0);
        a.why = cycle.along_floor ? "to push " + what : "to knock " + what + " off";
      } else {
        a.push = true;
        a.target = cycle.push_end;
        a.expected_s = cycle.along_floor ? cycle.push_s : PushSeconds(c);
        a.why = (cycle.along_floor ? "push " : "knock ") + what + " into " +
                c.season->goals[cycle.goal].name;
      }
      return a;
    }
    if (!at_stage) {
      a.kind = ActionKind::kNavigate;
      a.target = stage;
      a.expected_s = c.travel_time_s(b.pose, stage).value_or(0.0);
      a.why = cycle.object ? "to pick " + cycle.object->colour + " " + cycle.object->kind + " #" +
                                 std::to_string(cycle.object->id)
                           : "to score in " + c.season->goals[cycle.goal].name;
      a.object_id = cycle.object ? cycle.object->id : -1;
      a.goal_index = cycle.goal;
      return a;
    }
    if (cycle.object) {
      a.kind = ActionKind::kPick;
      a.object_id = cycle.object->id;
      a.object_kind = cycle.object->kind;
      a.object_colour = cycle.object->colour;
      a.target =
          Eigen::Vector3d(cycle.object->position_m.x(), cycle.object->position_m.y(), stage.z());
      a.frames = 0;
      a.expected_s = ApproachSeconds(c, PickMargin(c, cycle.object->kind)) + c.robot->intake.pick_s;
      a.why =
          cycle.object->colour + " " + cycle.object->kind + " #" + std::to_string(cycle.object->id);
    } else {
      a.kind = ActionKind::kScore;
      a.goal_index = cycle.goal;
      a.goal_m = Eigen::Vector2d(c.season->goals[cycle.goal].center_m.x,
                                 c.season->goals[cycle.goal].center_m.y);
      a.target = stage;
      a.expected_s = ApproachSeconds(c) + c.robot->intake.release_s;
      a.why = "into " + c.season->goals[cycle.goal].name;
    }
    return a;
  }

  // A held object that scores in no goal for us (the intake took another object than the one
  // aimed at; the intake says what it holds) blocks every pick for the rest of the match:
  // release it where the robot stands.
  std::optional<Action> DropUseless(const Belief& b, const StrategyContext& c) const {
    if (!b.held) return std::nullopt;
    for (int g = 0; g < static_cast<int>(c.season->goals.size()); ++g) {
      if (GoalPoints(*c.season, g, b.held->kind, b.held->colour, c.alliance) > 0) {
        return std::nullopt;
      }
    }
    // Turned aside first: dropped straight ahead it would lie where the intake just took it,
    // in front of the object the pick was aimed at. To the side whose drop point is clear
    // and farthest from the objects of ours.
    const double r = ObjectRadius(*c.season, b.held->kind);
    const double reach = ReleaseDistance(*c.robot, r);
    double best_heading = b.pose.z() + kPi / 2.0, best_room = -1.0;
    for (const double turn : {kPi / 2.0, -kPi / 2.0, kPi}) {
      const double heading = Wrap(b.pose.z() + turn);
      const Eigen::Vector2d drop =
          b.pose.head<2>() + reach * Eigen::Vector2d(std::cos(heading), std::sin(heading));
      if (!c.is_clear(drop)) continue;
      double room = 10.0;
      for (const ObjectBelief& o : b.objects) {
        if (Scores(c, o)) room = std::min(room, (o.position_m - drop).norm());
      }
      if (room > best_room + 1e-9) best_room = room, best_heading = heading;
    }
    Action a;
    a.kind = ActionKind::kDrop;
    a.target = Eigen::Vector3d(b.pose.x(), b.pose.y(), best_heading);
    const double turn_deg = std::abs(Wrap(best_heading - b.pose.z())) * 180.0 / kPi;
    a.expected_s = turn_deg / c.robot->drive.turn_rate_dps + c.robot->intake.release_s;
    a.why = b.held->colour + " " + b.held->kind + " scores nothing for us: free the intake";
    return a;
  }

  // Turn to look where the season places objects of our colour and none is tracked yet.
  std::optional<Action> Look(const Belief& b, const StrategyContext& c) {
    std::vector<Eigen::Vector2d> prior;
    for (const field::ObjectPlacement& p : c.season->objects) {
      if (!field::ScoresFor(*c.season, p.colour, c.alliance)) continue;
      if (p.position_m) {
        prior.emplace_back(p.position_m->x, p.position_m->y);
      } else if (p.region) {
        for (double fx = 0.125; fx < 1.0; fx += 0.25) {
          for (double fy = 0.125; fy < 1.0; fy += 0.25) {
            prior.emplace_back(p.region->min_m.x + fx * (p.region->max_m.x - p.region->min_m.x),
                               p.region->min_m.y + fy * (p.region->max_m.y - p.region->min_m.y));
          }
        }
      }
    }
    const double half_fov = std::atan(c.robot->camera.width_px / 2.0 / c.robot->camera.fx) - 0.05;
    double best_heading = 0.0;
    int best_count = 0;
    for (int k = 0; k < 12; ++k) {
      const double heading = k * kPi / 6.0;
      if (looked_.count(LookKey(b.pose, heading))) continue;
      int count = 0;
      for (const Eigen::Vector2d& p : prior) {
        const Eigen::Vector2d d = p - b.pose.head<2>();
        const double range = d.norm();
        if (range < 0.8 || range > 3.5) continue;
        if (std::abs(Wrap(std::atan2(d.y(), d.x()) - heading)) > half_fov) continue;
        const bool known =
            std::any_of(b.objects.begin(), b.objects.end(),
                        [&](const ObjectBelief& o) { return (o.position_m - p).norm() < 0.3; });
        if (!known) ++count;
      }
      // Prefer small turns: a turn costs seconds like anything else.
      if (count > best_count) best_count = count, best_heading = heading;
    }
    if (best_count == 0) return std::nullopt;
    const double turn_s =
        std::abs(Wrap(best_heading - b.pose.z())) * 180.0 / kPi / c.robot->drive.turn_rate_dps;
    if (turn_s + options_.look_frames / c.frame_rate_hz > b.deadline_s - b.now_s)
      return std::nullopt;
    looked_[LookKey(b.pose, best_heading)] = 1;
    Action a;
    a.kind = ActionKind::kObserve;
    a.look_heading = true;
    a.target = Eigen::Vector3d(b.pose.x(), b.pose.y(), best_heading);
    a.frames = options_.look_frames;
    const double turn_deg = std::abs(Wrap(best_heading - b.pose.z())) * 180.0 / kPi;
    a.expected_s = turn_deg / c.robot->drive.turn_rate_dps + options_.look_frames / c.frame_rate_hz;
    a.why = "look where " + std::to_string(best_count) + " prior positions are unseen";
    return a;
  }

  // The belief with the season's raised objects added: an object the season file places on a
  // raised structure (a large ball on the Toss Up barrier) stays there until something knocks
  // it off, so its spot is known to the placement accuracy without seeing it, and a knock
  // forgives half the robot's width. Seen from the floor such an object is often believed
  // tenths of a metre off its spot (then off the structure, and offered as a pick the intake
  // cannot make): a tracked object of the same kind and colour within kPriorMatch_m of an
  // unknocked spot is that object and gives way to it. Ids -1000 - k (k: the placement's
  // index), never a tracked object's.
  std::vector<ObjectBelief> WithRaisedPriors(const Belief& b, const StrategyContext& c) const {
    constexpr double kPriorMatch_m = 0.5;
    std::vector<ObjectBelief> priors;
    for (size_t k = 0; k < c.season->objects.size(); ++k) {
      const field::ObjectPlacement& p = c.season->objects[k];
      if (!p.position_m || p.z_m <= 0.0 || p.stack_level > 0) continue;
      const Eigen::Vector2d at(p.position_m->x, p.position_m->y);
      if (!RaisedOn(*c.season, p.type, at)) continue;
      ObjectBelief o;
      o.id = -1000 - static_cast<int>(k);
      o.kind = p.type;
      o.colour = p.colour;
      o.position_m = at;
      o.covariance = Eigen::Matrix2d::Identity() * options_.prior_sigma_m * options_.prior_sigma_m;
      priors.push_back(o);
    }
    // A spot already knocked: what is still believed on the structure near it is the same
    // object (a push is not repeated); what is believed on the floor may be picked.
    std::vector<ObjectBelief> out;
    for (const ObjectBelief& o : b.objects) {
      const bool seen_prior = std::any_of(priors.begin(), priors.end(), [&](const ObjectBelief& p) {
        return p.kind == o.kind && p.colour == o.colour &&
               (p.position_m - o.position_m).norm() < kPriorMatch_m &&
               (!knocked_.count(p.id) || RaisedOn(*c.season, o.kind, o.position_m));
      });
      if (!seen_prior) out.push_back(o);
    }
    for (const ObjectBelief& p : priors) {
      if (!knocked_.count(p.id)) out.push_back(p);
    }
    return out;
  }

  StrategyOptions options_;
  std::map<int, int> failed_objects_;
  std::map<int, int> failed_goals_;
  std::map<long, int> failed_targets_;
  std::map<long, int> looked_;
  std::set<int> knocked_;
  mutable std::map<std::pair<int, double>, std::vector<Eigen::Vector3d>> score_stages_;
  mutable std::map<std::tuple<int, double, double, const field::Structure*>, std::vector<KnockWay>>
      knock_ways_;
  bool surveyed_ = false;
  std::optional<Action> pending_;  // the last action chosen, and when
  double pending_start_s_ = 0.0;
  double ratio_sum_[3] = {0.0, 0.0, 0.0};
  double ratio_count_[3] = {0.0, 0.0, 0.0};
};

// Our method: the receding-horizon search described in strategy.h.
class PlannerStrategy : public Base {
 public:
  using Base::Base;
  std::string name() const override { return "planner"; }

  Action Choose(const Belief& observed, const StrategyContext& c) override {
    Belief b = observed;
    if (options_.raised_priors) b.objects = WithRaisedPriors(observed, c);
    const double left = b.deadline_s - b.now_s;
    if (!surveyed_) {  // the initial survey: nothing is known before the first frames
      surveyed_ = true;
      Action a;
      a.kind = ActionKind::kObserve;
      a.frames = options_.look_frames;
      a.expected_s = a.frames / c.frame_rate_hz;
      a.why = "initial survey";
      return a;
    }
    if (std::optional<Action> drop = DropUseless(b, c)) {
      just_observed_ = false;
      return *drop;
    }
    Cycle best;
    double best_j = 0.0, best_rate = 0.0;
    // The probability that a sequence estimated at `seconds` ends before the deadline: its
    // duration about the estimate is normal with a standard deviation of duration_spread x the
    // estimate (0: certain, and a sequence either fits or is not considered).
    const auto in_time = [&](double seconds) {
      if (options_.duration_spread <= 0.0) return seconds > left ? 0.0 : 1.0;
      return 0.5 *
             std::erfc((seconds - left) / (options_.duration_spread * seconds * std::sqrt(2.0)));
    };
    double unlooked_rate = 0.0;  // the best points per second of a sequence without a look
    double look_cost = 0.0;      // what the look of the frames being searched is charged
    const auto consider = [&](const Cycle& first, double j, double seconds) {
      if (in_time(seconds) < kMinInTime) return;
      if (first.frames == 0) {
        unlooked_rate = std::max(unlooked_rate, j / std::max(seconds, 1e-3));
      } else {
        j -= look_cost;
      }
      // The executive refuses an action whose own estimate exceeds the time left: a sequence
      // that may still end in time must at least start in time.
      if (seconds > left && FirstAction(b, c, first, j).expected_s > left) return;
      const double rate = j / std::max(seconds, 1e-3);
      if (j > best_j + 1e-9 || (std::abs(j - best_j) <= 1e-9 && rate > best_rate)) {
        best = first, best_j = j, best_rate = rate;
      }
    };
    // Without a look first, so that the looks are charged at the best rate without one.
    std::vector<int> frame_choices = options_.frame_choices;
    std::stable_sort(frame_choices.begin(), frame_choices.end());
    for (int frames : frame_choices) {
      if (frames > 0 && just_observed_) continue;  // observing twice in a row gains little
      look_cost = options_.look_charge * unlooked_rate * frames / c.frame_rate_hz;
      std::vector<Cycle> firsts = b.held ? HeldCycles(b, c, frames) : std::vector<Cycle>{};
      // Held: its goals, floor zones included (releasing it on the floor frees the intake).
      if (!b.held) {
        for (const ObjectBelief& o : b.objects) {
          for (const Cycle& cycle : ObjectCycles(b, c, o, b.pose, frames)) firsts.push_back(cycle);
        }
      }
      for (const Cycle& first : firsts) {
        // What the drive to the cycle's first stage pushes out of our zones is lost whatever
        // the cycle then earns.
        const double loss =
            options_.count_push_loss
                ? PushLoss(b, c, b.pose, first.object ? first.pick_stage : first.score_stage)
                : 0.0;
        consider(first, first.Value() * in_time(first.seconds) - loss, first.seconds);
        if (options_.horizon < 2) continue;
        // The second cycle from where the first ends, with no extra observation; its travel
        // from the first's goal is the planner's, like the first's.
        const Eigen::Vector3d& first_stage = first.object ? first.pick_stage : first.score_stage;
        for (const ObjectBelief& o : b.objects) {
          if (first.object && o.id == first.object->id) continue;
          // What the first drive pushes on is no longer where the second would find it.
          if (options_.count_push_loss && OnTheWay(c, b.pose, first_stage, o)) continue;
          for (const Cycle& second : ObjectCycles(b, c, o, first.score_stage, 0)) {
            if (first.object && second.object && second.object->id == first.object->id) continue;
            consider(first,
                     first.Value() * in_time(first.seconds) +
                         second.Value() * in_time(first.seconds + second.seconds) - loss,
                     first.seconds + second.seconds);
          }
        }
      }
    }
    if (best.goal >= 0 && best_j >= options_.min_gain) {
      Action a = FirstAction(b, c, best, best_j);
      // Check the arrival with as many frames as a look: a pick or release from a wrong
      // pose wastes the whole cycle.
      if (a.kind == ActionKind::kNavigate) a.frames = options_.arrival_frames;
      just_observed_ = a.kind == ActionKind::kObserve;
      return a;
    }
    just_observed_ = false;
    if (std::optional<Action> look = Look(b, c)) {
      just_observed_ = true;
      return *look;
    }
    Action idle;
    idle.why = "nothing worth doing fits in " + std::to_string(left).substr(0, 4) + " s";
    return idle;
  }

 private:
  bool just_observed_ = false;
};

// Nearest known object of ours (by the planner's travel time), the best-paying goal for it.
class GreedyStrategy : public Base {
 public:
  GreedyStrategy(const StrategyOptions& options, std::string name, double spacing, int frames)
      : Base(options), name_(std::move(name)), spacing_(spacing), frames_(frames) {}
  std::string name() const override { return name_; }

  Action Choose(const Belief& b, const StrategyContext& c) override {
    if (!surveyed_) {
      surveyed_ = true;
      Action a;
      a.kind = ActionKind::kObserve;
      a.frames = frames_ > 0 ? frames_ : options_.look_frames;
      a.expected_s = a.frames / c.frame_rate_hz;
      a.why = "initial survey";
      return a;
    }
    if (std::optional<Action> drop = DropUseless(b, c)) return *drop;
    std::optional<Cycle> chosen;
    const double left = b.deadline_s - b.now_s;
    if (b.held) {
      for (const Cycle& cycle : HeldCycles(b, c, 0)) {
        if (cycle.seconds > left) continue;
        if (!chosen || cycle.gain > chosen->gain ||
            (cycle.gain == chosen->gain && cycle.seconds < chosen->seconds)) {
          chosen = cycle;
        }
      }
    } else {
      double nearest = std::numeric_limits<double>::infinity();
      for (const ObjectBelief& o : b.objects) {
        std::optional<Cycle> best_goal;
        for (const Cycle& cycle : ObjectCycles(b, c, o, b.pose, 0)) {
          if (cycle.gain <= 0 || cycle.seconds > left) continue;
          if (!best_goal || cycle.gain > best_goal->gain) best_goal = cycle;
        }
        if (!best_goal) continue;
        const double d = (o.position_m - b.pose.head<2>()).norm();
        if (d < nearest) nearest = d, chosen = best_goal;
      }
    }
    if (chosen) {
      Action a = FirstAction(b, c, *chosen, chosen->gain);
      if (a.kind == ActionKind::kNavigate) {
        a.stop_spacing_m = spacing_;
        a.frames = frames_;
      }
      return a;
    }
    if (std::optional<Action> look = Look(b, c)) return *look;
    Action idle;
    idle.why = "no known object of ours";
    return idle;
  }

 private:
  std::string name_;
  double spacing_;
  int frames_;
};

StrategyOptions WithoutFloorPushes(StrategyOptions options) {
  options.floor_pushes = false;
  return options;
}

// A fixed route from the season's nominal positions, planned once before the match, driven
// blind: what a team's scripted autonomous does. A team authors the route that scores most in
// the period on the field as drawn; here that is a beam search over sequences of cycles (the
// preload's release, picks and releases, knocks off raised structures), each timed with the
// planner's travel times like every strategy's, keeping the sequence with the most points that
// finishes by the deadline. No floor pushes: planned at the nominal spots, where the search
// takes them for certain, they made the route worse (Toss Up, 200 seeds: gained 8.80 with them
// against 10.72 without; 80 of 200 scored), and a team keeps the route that scores more.
class ScriptedStrategy : public Base {
 public:
  explicit ScriptedStrategy(const StrategyOptions& options) : Base(WithoutFloorPushes(options)) {}
  std::string name() const override { return "scripted"; }
  bool perceives() const override { return false; }

  Action Choose(const Belief& b, const StrategyContext& c) override {
    if (!planned_) Plan(b, c);
    if (next_ >= route_.size()) {
      Action idle;
      idle.why = "end of the script";
      return idle;
    }
    return route_[next_++];
  }

 private:
  static constexpr int kBeamWidth = 24;

  // A route in the making: its cycles (with the nominal object each takes, -1 for the held
  // object), where it leaves the robot, and its points and seconds so far.
  struct Partial {
    std::vector<std::pair<Cycle, int>> cycles;
    Eigen::Vector3d pose = Eigen::Vector3d::Zero();
    std::optional<ObjectBelief> held;
    std::vector<bool> used;
    double t = 0.0;
    double points = 0.0;
  };

  void Plan(const Belief& b, const StrategyContext& c) {
    planned_ = true;
    plans_route_ = true;  // every planned stage is driven to (Emit)
    // The nominal objects: fixed positions from the season file (regions are unknown).
    nominal_.clear();
    int id = -1;
    for (const field::ObjectPlacement& p : c.season->objects) {
      if (!p.position_m) continue;
      const Eigen::Vector2d at(p.position_m->x, p.position_m->y);
      // Raised: knocked off a structure; stacked on other objects: left alone.
      if (p.z_m > 0.0 && !RaisedOn(*c.season, p.type, at)) continue;
      ObjectBelief o;
      o.id = id--;
      o.kind = p.type;
      o.colour = p.colour;
      o.position_m = at;
      o.covariance = Eigen::Matrix2d::Identity() * 1e-6;
      if ((o.position_m - b.pose.head<2>()).norm() < 0.3) continue;  // the preload
      nominal_.push_back(o);
    }
    Partial root;
    root.pose = b.pose;
    root.held = b.held;
    root.used.assign(nominal_.size(), false);
    root.t = b.now_s;
    Partial best = root;
    const auto better = [](const Partial& x, const Partial& y) {
      return x.points > y.points + 1e-9 || (std::abs(x.points - y.points) <= 1e-9 && x.t < y.t);
    };
    std::vector<Partial> beam = {root};
    while (!beam.empty()) {
      std::vector<Partial> next;
      for (const Partial& p : beam) {
        Belief plan = b;
        plan.objects.clear();
        plan.pose = p.pose;
        plan.held = p.held;
        const auto extend = [&](const Cycle& cycle, int index) {
          if (cycle.gain <= 0 || p.t + cycle.seconds > b.deadline_s) return;
          Partial child = p;
          child.cycles.emplace_back(cycle, index);
          child.t += cycle.seconds;
          child.points += cycle.gain;
          child.held.reset();
          if (index >= 0) child.used[index] = true;
          child.pose = cycle.score_stage;
          next.push_back(child);
        };
        if (p.held) {
          for (const Cycle& cycle : HeldCycles(plan, c, 0)) extend(cycle, -1);
          continue;
        }
        for (size_t i = 0; i < nominal_.size(); ++i) {
          if (p.used[i]) continue;
          for (const Cycle& cycle : ObjectCycles(plan, c, nominal_[i], p.pose, 0))
            extend(cycle, static_cast<int>(i));
        }
      }
      std::sort(next.begin(), next.end(), better);
      if (next.size() > kBeamWidth) next.resize(kBeamWidth);
      if (!next.empty() && better(next.front(), best)) best = next.front();
      beam = std::move(next);
    }
    Eigen::Vector3d from = b.pose;
    for (const auto& [cycle, index] : best.cycles) {
      Emit(c, cycle, index, from);
      from = cycle.score_stage;
    }
    plans_route_ = false;
  }

  // The actions of one planned cycle, starting from `from`.
  void Emit(const StrategyContext& c, const Cycle& cycle, int index, const Eigen::Vector3d& from) {
    Action nav;
    nav.kind = ActionKind::kNavigate;
    Eigen::Vector3d at = from;
    if (index >= 0) nav.expected_s = c.travel_time_s(from, cycle.pick_stage).value_or(0.0);
    if (cycle.knock) {
      const ObjectBelief& o = nominal_[index];
      nav.target = cycle.pick_stage;
      nav.object_id = o.id;
      nav.object_kind = o.kind;
      nav.object_colour = o.colour;
      nav.object_m = o.position_m;
      nav.why = "script: to knock nominal " + o.colour + " " + o.kind + " off";
      route_.push_back(nav);
      Action push = nav;
      push.push = true;
      push.target = cycle.push_end;
      push.goal_index = cycle.goal;
      push.expected_s = PushSeconds(c);
      push.why = "script: knock it into " + c.season->goals[cycle.goal].name;
      route_.push_back(push);
      return;
    }
    if (index >= 0) {
      const ObjectBelief& o = nominal_[index];
      nav.target = cycle.pick_stage;
      nav.object_id = o.id;
      nav.why = "script: to nominal " + o.colour + " " + o.kind;
      route_.push_back(nav);
      Action pick;
      pick.kind = ActionKind::kPick;
      pick.object_id = o.id;
      pick.object_kind = o.kind;
      pick.object_colour = o.colour;
      pick.target = Eigen::Vector3d(o.position_m.x(), o.position_m.y(), cycle.pick_stage.z());
      pick.expected_s = ApproachSeconds(c) + c.robot->intake.pick_s;
      pick.why = "script: pick";
      route_.push_back(pick);
      const double r = ObjectRadius(*c.season, o.kind);
      const Eigen::Vector2d dir(std::cos(cycle.pick_stage.z()), std::sin(cycle.pick_stage.z()));
      at = Eigen::Vector3d(o.position_m.x() - dir.x() * PickDistance(*c.robot, r),
                           o.position_m.y() - dir.y() * PickDistance(*c.robot, r),
                           cycle.pick_stage.z());
    }
    nav.expected_s = c.travel_time_s(at, cycle.score_stage).value_or(0.0);
    nav.target = cycle.score_stage;
    nav.object_id = -1;
    nav.goal_index = cycle.goal;
    nav.why = "script: to " + c.season->goals[cycle.goal].name;
    route_.push_back(nav);
    Action score;
    score.kind = ActionKind::kScore;
    score.goal_index = cycle.goal;
    score.goal_m = Eigen::Vector2d(c.season->goals[cycle.goal].center_m.x,
                                   c.season->goals[cycle.goal].center_m.y);
    score.target = cycle.score_stage;
    score.expected_s = ApproachSeconds(c) + c.robot->intake.release_s;
    score.why = "script: release";
    route_.push_back(score);
  }

  std::vector<ObjectBelief> nominal_;
  bool planned_ = false;
  std::vector<Action> route_;
  size_t next_ = 0;
};

}  // namespace

const char* ActionName(ActionKind kind) {
  switch (kind) {
    case ActionKind::kObserve:
      return "OBSERVE";
    case ActionKind::kNavigate:
      return "NAVIGATE";
    case ActionKind::kPick:
      return "PICK";
    case ActionKind::kScore:
      return "SCORE";
    case ActionKind::kDrop:
      return "DROP";
    case ActionKind::kIdle:
      return "IDLE";
  }
  return "?";
}

const std::vector<std::string>& StrategyNames() {
  static const std::vector<std::string> names = {"planner", "greedy", "scripted", "thesis"};
  return names;
}

std::unique_ptr<Strategy> MakeStrategy(const std::string& name, const StrategyOptions& options) {
  if (name == "planner") return std::make_unique<PlannerStrategy>(options);
  if (name == "greedy") return std::make_unique<GreedyStrategy>(options, "greedy", 0.0, 10);
  if (name == "thesis") {
    return std::make_unique<GreedyStrategy>(options, "thesis", options.thesis_spacing_m,
                                            options.thesis_frames);
  }
  if (name == "scripted") return std::make_unique<ScriptedStrategy>(options);
  throw std::invalid_argument("unknown strategy \"" + name +
                              "\" (planner, greedy, scripted, thesis)");
}

int GoalPoints(const field::SeasonConfig& season, int goal_index, const std::string& kind,
               const std::string& colour, field::Alliance alliance) {
  if (goal_index < 0 || goal_index >= static_cast<int>(season.goals.size())) return 0;
  if (!field::ScoresFor(season, colour, alliance)) return 0;
  const field::Goal& g = season.goals[goal_index];
  if (g.alliance != field::Alliance::kNone && g.alliance != alliance) return 0;
  const auto it = g.points.find(kind);
  return it == g.points.end() ? 0 : it->second;
}

int FloorPoints(const field::SeasonConfig& season, const Eigen::Vector2d& position_m,
                const std::string& kind, const std::string& colour, field::Alliance alliance) {
  int best = 0;
  for (int g = 0; g < static_cast<int>(season.goals.size()); ++g) {
    if (season.goals[g].kind != field::GoalKind::kZone) continue;
    if (!platform::GoalContains(season.goals[g], position_m)) continue;
    best = std::max(best, GoalPoints(season, g, kind, colour, alliance));
  }
  return best;
}

double PickDistance(const field::RobotConfig& robot, double object_radius_m) {
  return robot.length_m / 2.0 + object_radius_m + robot.intake.reach_m / 2.0;
}

double ReleaseDistance(const field::RobotConfig& robot, double object_radius_m) {
  return robot.length_m / 2.0 + object_radius_m + 0.01;
}

std::optional<Eigen::Vector3d> PickStage(
    const StrategyContext& context, const Eigen::Vector2d& object, double object_radius_m,
    const Eigen::Vector2d& from, double margin_m,
    const std::function<bool(const Eigen::Vector3d&)>& accept) {
  const double d = PickDistance(*context.robot, object_radius_m) + margin_m;
  Eigen::Vector2d u = object - from;
  const double base = u.norm() > 1e-6 ? std::atan2(u.y(), u.x()) : 0.0;
  for (double offset_deg :
       {0.0, 30.0, -30.0, 60.0, -60.0, 90.0, -90.0, 120.0, -120.0, 150.0, -150.0, 180.0}) {
    const double heading = base + offset_deg * kPi / 180.0;
    const Eigen::Vector2d stage =
        object - d * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    const Eigen::Vector3d pose(stage.x(), stage.y(), Wrap(heading));
    if (context.is_clear(stage) && (!accept || accept(pose))) return pose;
  }
  return std::nullopt;
}

std::vector<Eigen::Vector3d> ScoreStages(const StrategyContext& context, int goal_index,
                                         double object_radius_m, double margin_m) {
  const field::Goal& g = context.season->goals[goal_index];
  const field::RobotConfig& robot = *context.robot;
  std::vector<Eigen::Vector3d> out;
  const Eigen::Vector2d centre(g.center_m.x, g.center_m.y);
  // A goal's staging pose is kept when its spot is clear in the map and the robot at the
  // release, facing `heading`, overlaps nothing fixed in `season`.
  const auto keep = [&](const Eigen::Vector2d& stage, const Eigen::Vector2d& release,
                        double heading, const field::SeasonConfig& season) {
    if (!context.is_clear(stage)) return;
    if (!platform::FootprintIsFree(season, platform::Pose2D{release.x(), release.y(), heading},
                                   robot.length_m, robot.width_m, robot.height_m)) {
      return;
    }
    out.emplace_back(stage.x(), stage.y(), Wrap(heading));
  };
  if (g.kind == field::GoalKind::kGoal && g.entry == field::Goal::Entry::kEnds) {
    // A tube: facing into one of its ends along the axis, the bumper just short of the mouth;
    // the drop lands inside, past the mouth by the object's radius less the gap (the
    // simulator takes it within one object size of the mouth, platform::GoalTakes).
    const double reach = robot.length_m / 2.0 + 0.015;
    const double inside = ReleaseDistance(robot, object_radius_m) - reach;
    if (inside <= 0.0 || inside > 2.0 * object_radius_m) return out;
    for (const platform::GoalMouth& m : platform::GoalMouths(g)) {
      const double heading = std::atan2(m.inward.y(), m.inward.x());
      const Eigen::Vector2d stage = m.point_m - (reach + margin_m) * m.inward;
      const Eigen::Vector2d release = m.point_m - (reach + 0.01) * m.inward;
      keep(stage, release, heading, *context.season);
    }
    return out;
  }
  if (g.kind == field::GoalKind::kGoal && !g.on_object.empty()) {
    // A stake on an object (a mobile goal): the bumper just short of the object's edge, the
    // intake places the object onto the stake (the simulator's rule, SimField::Release).
    const double reach = platform::CarrierRadius(*context.season, g) + robot.length_m / 2.0 + 0.015;
    for (int k = 0; k < 12; ++k) {
      const double heading = k * kPi / 6.0;
      const Eigen::Vector2d dir(std::cos(heading), std::sin(heading));
      const Eigen::Vector2d stage = centre - (reach + margin_m) * dir;
      keep(stage, centre - reach * dir, heading, *context.season);
    }
    return out;
  }
  if (g.kind == field::GoalKind::kGoal) {
    // Bumper just short of the goal's edge; the drop then lands inside it.
    const double half = platform::GoalHalfSize(g);
    const double reach = half + robot.length_m / 2.0 + 0.015;
    if (std::abs(reach - ReleaseDistance(robot, object_radius_m)) > half) return out;
    // The robot at the release must not overlap anything but the goal's own structure (a goal
    // against a barrier is reached from its open side only).
    field::SeasonConfig others = *context.season;
    others.structures.erase(std::remove_if(others.structures.begin(), others.structures.end(),
                                           [&](const field::Structure& st) {
                                             return platform::IsGoalStructure(g, st);
                                           }),
                            others.structures.end());
    for (int k = 0; k < 12; ++k) {
      const double heading = k * kPi / 6.0;
      const Eigen::Vector2d dir(std::cos(heading), std::sin(heading));
      const Eigen::Vector2d stage = centre - (reach + margin_m) * dir;
      keep(stage, centre - (reach + 0.01) * dir, heading, others);
    }
    return out;
  }
  // A floor zone: drop points on a grid inside it, approached along the four axes.
  const double inset = object_radius_m + 0.05;
  const double yaw = g.yaw_deg * kPi / 180.0;
  const double hx =
      g.shape == field::SolidShape::kCylinder ? g.radius_m / std::sqrt(2.0) : g.size_m.x / 2.0;
  const double hy =
      g.shape == field::SolidShape::kCylinder ? g.radius_m / std::sqrt(2.0) : g.size_m.y / 2.0;
  for (double lx = -hx + inset; lx <= hx - inset + 1e-9;
       lx += std::max(0.3, (2 * hx - 2 * inset) / 4.0)) {
    for (double ly = -hy + inset; ly <= hy - inset + 1e-9;
         ly += std::max(0.3, (2 * hy - 2 * inset) / 6.0)) {
      const Eigen::Vector2d drop =
          centre + Eigen::Vector2d(std::cos(yaw) * lx - std::sin(yaw) * ly,
                                   std::sin(yaw) * lx + std::cos(yaw) * ly);
      // A triangle zone: the grid covers its bounding box; keep the drops inside it.
      if (g.shape == field::SolidShape::kTriangle && !platform::GoalContains(g, drop)) continue;
      for (int k = 0; k < 4; ++k) {
        const double heading = k * kPi / 2.0;
        const Eigen::Vector2d dir(std::cos(heading), std::sin(heading));
        const Eigen::Vector2d stage =
            drop - (ReleaseDistance(robot, object_radius_m) + margin_m) * dir;
        const Eigen::Vector2d release = drop - ReleaseDistance(robot, object_radius_m) * dir;
        if (!context.is_clear(stage)) continue;
        // Nothing fixed between the robot and the drop (a zone behind a barrier is reached
        // round it, not over it).
        if (!platform::FootprintIsFree(*context.season,
                                       platform::Pose2D{release.x(), release.y(), heading},
                                       robot.length_m, robot.width_m, robot.height_m)) {
          continue;
        }
        bool blocked = false;
        for (double f = 0.0; f <= 1.0 && !blocked; f += 0.05) {
          blocked = platform::PointInBlockingStructure(*context.season, stage + f * (drop - stage),
                                                       0.02, robot.height_m);
        }
        if (!blocked) out.emplace_back(stage.x(), stage.y(), Wrap(heading));
      }
    }
  }
  return out;
}

Eigen::Vector2d DropTarget(const field::SeasonConfig& season, const field::RobotConfig& robot,
                           int goal_index, const Eigen::Vector3d& stage, double object_radius_m,
                           double margin_m) {
  const field::Goal& g = season.goals[goal_index];
  const Eigen::Vector2d dir(std::cos(stage.z()), std::sin(stage.z()));
  if (g.kind == field::GoalKind::kGoal) {
    // The mouth the stage faces (a goal without ends has one, at its centre).
    const std::vector<platform::GoalMouth> mouths = platform::GoalMouths(g);
    const auto best =
        std::max_element(mouths.begin(), mouths.end(),
                         [&](const platform::GoalMouth& a, const platform::GoalMouth& b) {
                           return a.inward.dot(dir) < b.inward.dot(dir);
                         });
    return best->point_m;
  }
  return stage.head<2>() + (ReleaseDistance(robot, object_radius_m) + margin_m) * dir;
}

double SuccessProbability(const Eigen::Matrix2d& cov, double tolerance_m) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  const double sigma = std::sqrt(std::max(eig.eigenvalues().maxCoeff(), 1e-12));
  return std::erf(tolerance_m / (sigma * std::sqrt(2.0)));
}

}  // namespace slamo::strategy
