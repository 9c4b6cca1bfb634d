#include "strategy/travel_field.h"

#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include "platform/drive_base.h"

namespace slamo::strategy {
namespace {
using platform::kPi;
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

TravelField::TravelField(const field::DriveConfig& drive, double cell_m)
    : drive_(drive), cell_m_(cell_m) {}

void TravelField::SetPlanner(const planning::Planner& planner) {
  const mapping::OccupancyGrid2D& grid = planner.grid();
  const std::vector<std::uint8_t>& fine = planner.blocked();
  const int step = std::max(1, static_cast<int>(std::lround(cell_m_ / grid.cell_m)));
  cell_m_ = step * grid.cell_m;
  width_ = grid.width / step;
  height_ = grid.height / step;
  origin_ = grid.origin_m;
  // The distance fields stay valid while the coarse grid stays the same (the map often
  // changes only where no coarse cell changes state): they are dropped only when it changes.
  std::vector<std::uint8_t> before;
  before.swap(blocked_);
  blocked_.assign(static_cast<size_t>(width_) * height_, 1);
  // A coarse cell is free when any of its fine cells is: narrow passages (a barrier's gap)
  // stay open; the times are estimates, and the executive plans on the fine grid.
  for (int r = 0; r < height_; ++r) {
    for (int c = 0; c < width_; ++c) {
      bool all_blocked = true;
      for (int fr = r * step; fr < (r + 1) * step && all_blocked; ++fr) {
        for (int fc = c * step; fc < (c + 1) * step; ++fc) {
          if (!fine[static_cast<size_t>(fr) * grid.width + fc]) {
            all_blocked = false;
            break;
          }
        }
      }
      blocked_[static_cast<size_t>(r) * width_ + c] = all_blocked ? 1 : 0;
    }
  }
  if (blocked_ != before || width_ != field_width_ || cell_m_ != field_cell_m_ ||
      origin_ != field_origin_) {
    fields_.clear();
  }
  field_width_ = width_;
  field_cell_m_ = cell_m_;
  field_origin_ = origin_;
}

std::optional<int> TravelField::CellOf(const Eigen::Vector2d& p) const {
  const int c = static_cast<int>(std::floor((p.x() - origin_.x()) / cell_m_));
  const int r = static_cast<int>(std::floor((p.y() - origin_.y()) / cell_m_));
  if (c < 0 || r < 0 || c >= width_ || r >= height_) return std::nullopt;
  return r * width_ + c;
}

const std::vector<float>& TravelField::FieldFrom(int cell) {
  auto it = fields_.find(cell);
  if (it != fields_.end()) return it->second;
  std::vector<float> dist(blocked_.size(), kInf);
  using Item = std::pair<float, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  // A blocked start leaves through the nearest free cells (ring search, straight-line cost).
  if (blocked_[cell]) {
    const int sr = cell / width_, sc = cell % width_;
    for (int radius = 1; radius < 15 && open.empty(); ++radius) {
      for (int dr = -radius; dr <= radius; ++dr) {
        for (int dc = -radius; dc <= radius; ++dc) {
          const int r = sr + dr, c = sc + dc;
          if (r < 0 || c < 0 || r >= height_ || c >= width_) continue;
          const int k = r * width_ + c;
          if (blocked_[k]) continue;
          const float d = static_cast<float>(std::hypot(dr, dc) * cell_m_);
          if (d < dist[k]) dist[k] = d, open.push({d, k});
        }
      }
    }
  } else {
    dist[cell] = 0.0f;
    open.push({0.0f, cell});
  }
  const float diagonal = static_cast<float>(cell_m_ * std::sqrt(2.0));
  const float straight = static_cast<float>(cell_m_);
  while (!open.empty()) {
    const auto [d, k] = open.top();
    open.pop();
    if (d > dist[k]) continue;
    const int r = k / width_, c = k % width_;
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dc = -1; dc <= 1; ++dc) {
        if (!dr && !dc) continue;
        const int nr = r + dr, nc = c + dc;
        if (nr < 0 || nc < 0 || nr >= height_ || nc >= width_) continue;
        const int n = nr * width_ + nc;
        if (blocked_[n]) continue;
        // No corner cutting past a blocked cell.
        if (dr && dc && (blocked_[r * width_ + nc] || blocked_[nr * width_ + c])) continue;
        const float nd = d + (dr && dc ? diagonal : straight);
        if (nd < dist[n]) dist[n] = nd, open.push({nd, n});
      }
    }
  }
  return fields_.emplace(cell, std::move(dist)).first->second;
}

std::optional<double> TravelField::DistanceM(const Eigen::Vector2d& from,
                                             const Eigen::Vector2d& to) {
  const std::optional<int> a = CellOf(from), b = CellOf(to);
  if (!a || !b || blocked_[*b]) return std::nullopt;
  const float d = FieldFrom(*a)[*b];
  if (!std::isfinite(d)) return std::nullopt;
  // 8-connected grid paths run up to 8 % longer than the true shortest path: a conservative
  // estimate, which suits a deadline.
  return std::max(static_cast<double>(d), (to - from).norm());
}

std::optional<double> TravelField::TravelTimeS(const Eigen::Vector3d& from,
                                               const Eigen::Vector3d& to) {
  const std::optional<double> d = DistanceM(from.head<2>(), to.head<2>());
  if (!d) return std::nullopt;
  const Eigen::Vector2d delta = to.head<2>() - from.head<2>();
  double turn_rad = 0.0;
  double drive_m = *d;
  if (delta.norm() > std::max(0.02, min_leg_m)) {
    double bearing = std::atan2(delta.y(), delta.x());
    // A short leg behind the robot is driven backwards, facing away from it.
    if (std::abs(std::remainder(bearing - from.z(), 2 * kPi)) > kPi / 2.0 && *d <= reverse_max_m) {
      bearing += kPi;
    }
    turn_rad = std::abs(std::remainder(bearing - from.z(), 2 * kPi)) +
               std::abs(std::remainder(to.z() - bearing, 2 * kPi));
  } else {
    turn_rad = std::abs(std::remainder(to.z() - from.z(), 2 * kPi));
    drive_m = 0.0;
  }
  return turn_rad * 180.0 / kPi / drive_.turn_rate_dps + planning::DriveTime(drive_, drive_m) +
         3 * settle_s;
}

}  // namespace slamo::strategy
