// Pure geometry of the field as a season config describes it: where structures block robots,
// what a goal's footprint holds, where the surveyed markers are and where the robot starts. No
// simulator state: strategy, the match loop and the simulator all ask the same questions here.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "field_configs/season_config.h"
#include "platform/drive_base.h"

namespace slamo::platform {

// Distance from point p to a structure's footprint in the plane (0 inside).
double DistanceToStructure(const field::Structure& s, const Eigen::Vector2d& p);

// True when a robot `height_m` tall cannot be where structure s stands: s blocks robots, or
// it is raised (a barrier robots pass under) and its underside is not above the robot's top.
bool BlocksRobot(const field::Structure& s, double height_m);

// True when a rectangle footprint at `pose` (length along the heading) of a robot `height_m`
// tall is inside the perimeter and clear of every structure that blocks it (BlocksRobot).
bool FootprintIsFree(const field::SeasonConfig& season, const Pose2D& pose, double length_m,
                     double width_m, double height_m);

// True when the point lies on a structure that blocks a robot `height_m` tall (BlocksRobot).
bool PointInBlockingStructure(const field::SeasonConfig& season, const Eigen::Vector2d& p,
                              double clearance_m, double height_m);

// True when an object (footprint radius, height) centred at p would overlap a structure it
// cannot pass: one that blocks robots, or a raised one (a barrier robots pass under) whose
// underside is lower than the object's top. Floor-level structures robots drive over (bumps,
// pipes) do not stop objects.
bool PointBlocksObject(const field::SeasonConfig& season, const Eigen::Vector2d& p, double radius_m,
                       double object_height_m);

// True when the point lies inside a goal's footprint (box with yaw, cylinder or triangle).
bool GoalContains(const field::Goal& goal, const Eigen::Vector2d& p);

// The mouths of a goal structure: where an object goes in, and the direction into the goal
// there. A goal with entry kEnds has one at the centre of each end face of its long axis; any
// other goal one at its centre (direction zero: any side).
struct GoalMouth {
  Eigen::Vector2d point_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d inward = Eigen::Vector2d::Zero();
};
std::vector<GoalMouth> GoalMouths(const field::Goal& goal);

// Whether an object released at `drop` by a robot heading `heading_rad` goes into the goal
// structure: inside its footprint and, for an entry-kEnds tube, from a robot facing into one
// of its ends (within kEntryAngle_deg of the axis) with the drop within one object size of it.
inline constexpr double kEntryAngle_deg = 30.0;
bool GoalTakes(const field::Goal& goal, const Eigen::Vector2d& drop, double heading_rad,
               double object_size_m);

// Half a goal's footprint: a cylinder's radius, a box's narrower half-size.
double GoalHalfSize(const field::Goal& goal);

// Whether structure s is goal g's own (its frame): the structure's centre within
// GoalHalfSize of the goal's.
bool IsGoalStructure(const field::Goal& goal, const field::Structure& s);

// Whether a goal structure is raised off the floor, objects lower than its underside passing
// in under it (Over Under's nets, Push Back's upper centre goal): the structure of the goal's
// name, else (a frame named apart) its own structures, when one is raised and none blocks the
// robot. A stake on an object is not.
bool GoalIsRaised(const field::SeasonConfig& season, const field::Goal& goal);

// The goal an object on the floor counts in when pushed to p (not released there): a raised
// goal (GoalIsRaised) entered from any side (not a tube), p inside its footprint; -1 for none.
// (Whether the object fits under is PointBlocksObject's question, asked before it moves.)
int GoalPushedInto(const field::SeasonConfig& season, const Eigen::Vector2d& p);

// The radius of the object a goal stands on (Goal::on_object; 0 for a fixed goal).
double CarrierRadius(const field::SeasonConfig& season, const field::Goal& goal);

// Where a landmark is drawn: discs and squares as plates on the inner face of the nearest wall
// (centre 5 mm off it), cylinders and spheres where the season puts them.
Eigen::Vector3d LandmarkCentre(const field::SeasonConfig& season, const field::Landmark& landmark);

// The surveyed perimeter markers' centres: where the renderer draws them (a plate's centre
// sits just off its wall), which is where a team's tape measure puts them.
std::vector<Eigen::Vector2d> SurveyedMarkers(const field::SeasonConfig& field);
// Each marker's id in the filter: its index when no other marker shares its colour, else -1
// (associated by position).
std::vector<int> MarkerIds(const field::SeasonConfig& field);

// The pose of the alliance's start_index-th starting tile (throws std::invalid_argument when
// there is none).
Pose2D StartPose(const field::SeasonConfig& season, field::Alliance alliance, int start_index);

}  // namespace slamo::platform
