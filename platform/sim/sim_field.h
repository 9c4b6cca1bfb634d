// The whole simulated field of a dry run: the world (objects, opponents, lighting), the
// robot's simulated drive base, and the contact rules between them. The robot and opponent
// robots push the objects they drive into (a pinned object blocks them), opponents follow
// their scripted paths, the intake picks an object within reach in front, and a released
// object scores in the goal it lands in. Time advances only through Step().
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "platform/sim/sim_drive.h"
#include "platform/sim/sim_world.h"

namespace slamo::platform {

struct SimFieldOptions {
  double push_gap_m = 0.002;  // a pushed object ends this far from the pusher
  // The match's preload: the object of a colour that scores for the robot's alliance nearest
  // the robot's centre and under its footprint at the start goes into the intake, as loaded
  // by hand before the match (other objects there are pushed clear).
  bool preload = false;
};

// What a release did: the object, and the goal it landed in with its points (none: floor).
struct ReleaseResult {
  int object_id = 0;
  std::optional<int> goal_index;
  int points = 0;  // for the robot's alliance, by the season's rules
};

class SimField {
 public:
  SimField(const field::SeasonConfig& season, const field::RobotConfig& robot,
           field::Alliance alliance, uint64_t seed, const Pose2D& start,
           const SimDriveOptions& drive_options = {}, const SimFieldOptions& options = {});

  SimField(const SimField&) = delete;  // the drive's collision check points back at this
  SimField& operator=(const SimField&) = delete;

  // Advances the drive, the opponents and the contacts by dt_s (>= 0).
  void Step(double dt_s);

  SimDriveBase& drive() { return drive_; }
  const SimDriveBase& drive() const { return drive_; }
  const SimWorld& world() const { return world_; }
  const Pose2D& robot_pose() const { return drive_.true_pose(); }
  double time_s() const { return time_s_; }

  // Picks the nearest object on the floor whose near edge is within intake.reach_m of the
  // front bumper and inside the robot's width; nothing when none is, or the intake is full.
  std::optional<int> Pick();
  // Releases the oldest held object just in front of the bumper. Into a goal structure when
  // the drop point is over one; on the floor otherwise; nothing when nothing is held or the
  // drop point is inside a wall or structure (the object stays held).
  std::optional<ReleaseResult> Release();
  int HeldCount() const;
  // Ids of the held objects, oldest first.
  const std::vector<int>& held() const { return held_; }

  // Points the alliance has now: each object in its best goal or zone by the season's rules.
  int Score(field::Alliance alliance) const;
  // The points one object earns for `alliance` where it is now.
  int ObjectPoints(const SimObject& object, field::Alliance alliance) const;

 private:
  bool RobotPoseIsFree(const Pose2D& pose) const;
  bool OpponentPoseIsFree(size_t index, const Pose2D& pose) const;
  // Moves the objects overlapping a rectangle `height_m` tall out of it: those on the floor,
  // and those resting on a structure's top below height_m (a ball knocked off a raised
  // barrier, which then drops); false (and nothing moved) when one cannot go anywhere free.
  bool CanPushOut(const Pose2D& pose, double length_m, double width_m, double height_m) const;
  void PushOut(const Pose2D& pose, double length_m, double width_m, double height_m);
  // Objects whose support went (the object below a stack picked or pushed away) drop onto
  // what is now under them: another object, a structure's top, or the floor.
  void Settle();
  std::optional<Eigen::Vector2d> PushedPosition(const SimObject& object, const Pose2D& pose,
                                                double length_m, double width_m) const;
  void StepOpponent(size_t index, double dt_s);
  void Preload();

  // Goals standing on an object (Goal::on_object) follow it: goal index -> object id.
  void FollowCarriers();
  std::vector<std::pair<size_t, int>> carriers_;

  field::SeasonConfig season_;
  field::RobotConfig robot_;
  field::Alliance alliance_;
  SimFieldOptions options_;
  SimWorld world_;
  SimDriveBase drive_;
  std::vector<int> held_;  // object ids, oldest first
  double time_s_ = 0.0;
};

}  // namespace slamo::platform
