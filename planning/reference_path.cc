#include "planning/reference_path.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <utility>

namespace slamo::planning {
namespace {

// Midpoint rounds in Shorten(): each lets the path hug a curved obstacle more closely.
constexpr int kSubdivisions = 3;

}  // namespace

std::optional<std::vector<Eigen::Vector2d>> ReferencePath(const Planner& planner,
                                                          const Eigen::Vector2d& start,
                                                          const Eigen::Vector2d& goal) {
  const mapping::OccupancyGrid2D& grid = planner.grid();
  if (grid.cells.empty()) throw std::invalid_argument("ReferencePath: no map set");
  if (!planner.IsClear(start) || !planner.IsClear(goal)) return std::nullopt;
  if (planner.SegmentIsClear(start, goal)) return std::vector<Eigen::Vector2d>{start, goal};

  const size_t start_index = *grid.IndexOf(start), goal_index = *grid.IndexOf(goal);
  // A node is a cell; it stands at the cell's centre, the start and goal cells at the exact
  // start and goal.
  auto position = [&](size_t index) -> Eigen::Vector2d {
    if (index == start_index) return start;
    if (index == goal_index) return goal;
    const int col = static_cast<int>(index % grid.width),
              row = static_cast<int>(index / grid.width);
    return grid.origin_m + Eigen::Vector2d(col + 0.5, row + 0.5) * grid.cell_m;
  };
  const size_t cells = grid.cells.size();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr size_t kNone = std::numeric_limits<size_t>::max();
  std::vector<double> cost(cells, kInf);
  std::vector<size_t> parent(cells, kNone);
  std::vector<std::uint8_t> closed(cells, 0);
  using Entry = std::pair<double, size_t>;  // cost + heuristic, node
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  cost[start_index] = 0.0;
  parent[start_index] = start_index;
  open.emplace((goal - start).norm(), start_index);

  while (!open.empty()) {
    const size_t s = open.top().second;
    open.pop();
    if (closed[s]) continue;
    closed[s] = 1;
    if (s == goal_index) break;
    const Eigen::Vector2d ps = position(s);
    const int col = static_cast<int>(s % grid.width), row = static_cast<int>(s / grid.width);
    const size_t ancestor = parent[s];
    const Eigen::Vector2d pa = position(ancestor);
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dc = -1; dc <= 1; ++dc) {
        if (dr == 0 && dc == 0) continue;
        const int c = col + dc, r = row + dr;
        if (c < 0 || r < 0 || c >= grid.width || r >= grid.height) continue;
        const size_t n = static_cast<size_t>(r) * grid.width + c;
        if (closed[n] || planner.blocked()[n]) continue;
        const Eigen::Vector2d pn = position(n);
        // Theta*: through the grandparent when it sees the neighbour, else through s.
        double through_m = kInf;
        size_t via = kNone;
        if (ancestor != s && planner.SegmentIsClear(pa, pn)) {
          through_m = cost[ancestor] + (pn - pa).norm();
          via = ancestor;
        } else if (planner.SegmentIsClear(ps, pn)) {
          through_m = cost[s] + (pn - ps).norm();
          via = s;
        }
        if (via != kNone && through_m < cost[n] - 1e-12) {
          cost[n] = through_m;
          parent[n] = via;
          open.emplace(through_m + (goal - pn).norm(), n);
        }
      }
    }
  }
  if (!closed[goal_index]) return std::nullopt;

  std::vector<Eigen::Vector2d> path;
  for (size_t n = goal_index; n != start_index; n = parent[n]) path.push_back(position(n));
  path.push_back(start);
  std::reverse(path.begin(), path.end());
  return planner.Shorten(std::move(path), kSubdivisions);
}

}  // namespace slamo::planning
