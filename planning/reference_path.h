// A reference for the shortest collision-free path on the planner's inflated grid, to judge
// OMPL's path lengths against (the planning benchmark and tests).
//
// Theta* (Nash, Daniel, Koenig and Felner 2007: A* on the 8-connected grid of cell centres
// where a node may take its grandparent as parent when the straight line between them is
// clear), with the start and goal cells at the exact start and goal, then Planner::Shorten()
// with three rounds of subdivision to slide the corners onto the obstacles and bend the path
// round curved ones. Segments are checked with
// Planner::SegmentIsClear(), as OMPL's motions are. The result is any-angle, not bound to
// 45-degree moves; it may still be a little longer than the true shortest path (Theta*
// corners sit near cell centres before Shorten() moves them, and its path may go the other
// way round an obstacle than the true shortest one in rare cases).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "planning/planner.h"

namespace slamo::planning {

// Start to goal, or nullopt when either is not clear or the goal cannot be reached. A clear
// straight line is returned as it is. Throws std::invalid_argument before a map is set.
std::optional<std::vector<Eigen::Vector2d>> ReferencePath(const Planner& planner,
                                                          const Eigen::Vector2d& start,
                                                          const Eigen::Vector2d& goal);

}  // namespace slamo::planning
