#include "mapping/object_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "mapping/ekf_slam.h"

namespace slamo::mapping {

ObjectTracker::ObjectTracker(const ObjectTrackerOptions& options) : options_(options) {}

void ObjectTracker::Update(const Eigen::Vector3d& pose, const Eigen::Matrix3d& pose_covariance,
                           const std::vector<ObjectObservation>& observations, double t_s,
                           const std::function<bool(const TrackedObject&)>& expected_visible) {
  // Objects drift only if the options say so (pushed objects are handled by re-detection).
  for (TrackedObject& o : objects_) {
    const double dt = std::max(0.0, t_s - o.last_seen_s);
    o.covariance += Eigen::Matrix2d::Identity() * options_.motion_sigma_per_s *
                    options_.motion_sigma_per_s * dt;
  }
  std::vector<bool> seen(objects_.size(), false);
  for (const ObjectObservation& z : observations) {
    // Into the field frame through the pose, with the pose's uncertainty.
    Eigen::Matrix<double, 2, 3> g_pose;
    Eigen::Matrix2d g_z;
    const Eigen::Vector2d p =
        EkfSlam::InverseObserve(pose, z.range_m, z.bearing_rad, &g_pose, &g_z);
    const Eigen::Matrix2d r =
        g_pose * pose_covariance * g_pose.transpose() + g_z * z.covariance * g_z.transpose();
    // Nearest same-kind, same-colour object by Mahalanobis distance.
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < objects_.size(); ++i) {
      const TrackedObject& o = objects_[i];
      if (o.kind != z.kind || o.colour != z.colour || seen[i]) continue;
      const Eigen::Vector2d e = p - o.position_m;
      const double d2 = e.dot((o.covariance + r).ldlt().solve(e));
      if (d2 < best_d2) best_d2 = d2, best = static_cast<int>(i);
    }
    if (best >= 0 && best_d2 < options_.gate_chi2) {
      // Kalman update of the object's position with the observed position.
      TrackedObject& o = objects_[best];
      const Eigen::Matrix2d k = o.covariance * (o.covariance + r).inverse();
      o.position_m += k * (p - o.position_m);
      o.covariance = (Eigen::Matrix2d::Identity() - k) * o.covariance;
      o.covariance = 0.5 * (o.covariance + o.covariance.transpose());
      ++o.times_seen;
      o.last_seen_s = t_s;
      o.confidence = std::min(1.0, o.confidence + options_.seen_confidence_gain);
      seen[best] = true;
    } else if (best < 0 || best_d2 > options_.new_chi2) {
      TrackedObject o;
      o.id = next_id_++;
      o.kind = z.kind;
      o.colour = z.colour;
      o.position_m = p;
      o.covariance = r;
      o.times_seen = 1;
      o.last_seen_s = t_s;
      objects_.push_back(o);
      seen.push_back(true);
    }
  }
  // Expected but not seen: robots move objects; lose confidence, and forget at the floor.
  if (expected_visible) {
    for (size_t i = 0; i < objects_.size(); ++i) {
      if (!seen[i] && expected_visible(objects_[i])) {
        objects_[i].confidence -= options_.missed_confidence_loss;
      }
    }
    objects_.erase(std::remove_if(objects_.begin(), objects_.end(),
                                  [&](const TrackedObject& o) {
                                    return o.confidence < options_.drop_confidence;
                                  }),
                   objects_.end());
  }
}

int ObjectTracker::Forget(const std::function<bool(const TrackedObject&)>& gone) {
  const size_t before = objects_.size();
  objects_.erase(std::remove_if(objects_.begin(), objects_.end(), gone), objects_.end());
  return static_cast<int>(before - objects_.size());
}

}  // namespace slamo::mapping
