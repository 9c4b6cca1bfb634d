// SLAM-O's object layer: each detected game object tracked with a mean and covariance in
// the field frame, its kind and colour, how often and when it was seen, and a confidence.
// Observations are taken into the field frame through the current pose estimate, so their
// covariance includes the pose's (objects are tracked conditioned on the pose, not in the
// EKF state: they move when robots push them, and must not drag the pose). Association is
// Mahalanobis nearest neighbour among same kind and colour; objects expected in view but not
// seen lose confidence and are dropped.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace slamo::mapping {

struct ObjectObservation {
  std::string kind;    // e.g. buckyball
  std::string colour;  // e.g. blue
  double range_m = 0.0;
  double bearing_rad = 0.0;
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity() * 1e-4;  // of (range, bearing)
};

struct TrackedObject {
  int id = 0;
  std::string kind;
  std::string colour;
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
  int times_seen = 0;
  double last_seen_s = 0.0;
  double confidence = 0.5;  // 0..1
};

struct ObjectTrackerOptions {
  double gate_chi2 = 9.21;  // associate within this Mahalanobis distance^2
  double new_chi2 = 16.0;   // create a new object only beyond this from every match
  double seen_confidence_gain = 0.2;
  double missed_confidence_loss = 0.25;  // per frame in which it should have been seen
  double drop_confidence = 0.15;         // below this the object is forgotten
  double motion_sigma_per_s = 0.0;       // objects are static unless pushed (m per sqrt(s))
  int confirm_sightings = 2;             // an object is confirmed (mapped) once seen this often
};

class ObjectTracker {
 public:
  explicit ObjectTracker(const ObjectTrackerOptions& options = {});

  // One frame's observations from the robot at `pose` (with `pose_covariance`), at time t_s.
  // `expected_visible` says whether a tracked object should be visible in this frame (whole
  // in the camera's view, and in range); tracked objects for which it is true and that were
  // not seen lose confidence.
  void Update(const Eigen::Vector3d& pose, const Eigen::Matrix3d& pose_covariance,
              const std::vector<ObjectObservation>& observations, double t_s,
              const std::function<bool(const TrackedObject&)>& expected_visible = {});

  const std::vector<TrackedObject>& objects() const { return objects_; }
  // Forgets the objects for which `gone` is true (e.g. believed where the robot now stands);
  // returns how many.
  int Forget(const std::function<bool(const TrackedObject&)>& gone);
  // Seen at least confirm_sightings times: a single sighting may be a false detection.
  bool Confirmed(const TrackedObject& object) const {
    return object.times_seen >= options_.confirm_sightings;
  }

 private:
  ObjectTrackerOptions options_;
  std::vector<TrackedObject> objects_;
  int next_id_ = 1;
};

}  // namespace slamo::mapping
