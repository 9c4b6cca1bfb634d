// How many frames to take at a stop (thesis 4.4, 5.4.3): a fixed count (Algorithm 1), while
// the robot's covariance is above a threshold (Algorithm 2, with its inverted loop condition
// fixed), or until a Gaussian over the successive pose estimates converges (GMM selection).
// Every rule also stops when the covariance stops improving: a stationary camera cannot
// shrink the pose covariance below what the map supports.
#pragma once

#include <string>

#include <Eigen/Core>

#include "mapping/ekf_slam.h"

namespace slamo::mapping {

enum class FrameRule { kFixed, kCovariance, kGmm };

struct FrameSelectionOptions {
  FrameRule rule = FrameRule::kCovariance;
  int fixed_frames = 20;              // kFixed: i_p
  double covariance_threshold = 0.0;  // kCovariance: trace of the position covariance (m^2);
                                      // <= 0: derived from the motion noise (see below)
  int max_frames = 30;                // every rule
  double min_improvement = 0.01;      // stop when the trace falls by less than this fraction
  int stall_frames = 3;               // ... over this many frames in a row
  int gmm_min_frames = 5;             // kGmm: the thesis's minimum
  int gmm_max_frames = 20;            // kGmm: the thesis's maximum
  double gmm_threshold_m = 0.005;     // kGmm: new estimate this close to the Gaussian's mean
};

// FrameRule from "fixed:N" | "covariance" | "covariance:T" | "gmm"; std::invalid_argument
// otherwise. Fills the rule's fields of `options`.
void ParseFrameRule(const std::string& text, FrameSelectionOptions* options);
std::string Describe(const FrameSelectionOptions& options);

// The default covariance threshold: the position variance one leg between stops adds
// (trace of G Q G^T for a straight leg of `stop_spacing_m`). Observing below it is wasted,
// because the next leg adds it back before the next stop.
double DerivedCovarianceThreshold(const MotionNoise& noise, double stop_spacing_m);

// Decides, frame by frame, whether to keep observing at one stop.
class FrameSelector {
 public:
  explicit FrameSelector(const FrameSelectionOptions& options);

  // A new stop. `pose_covariance` after the prediction, before any frame.
  void Start(const Eigen::Matrix3d& pose_covariance);
  // After each frame's updates: true to take another frame.
  bool Continue(const Eigen::Vector3d& pose, const Eigen::Matrix3d& pose_covariance);
  int frames() const { return frames_; }
  // Why the last stop ended: "count", "threshold", "converged", "stalled" or "max".
  const std::string& reason() const { return reason_; }

 private:
  FrameSelectionOptions options_;
  int frames_ = 0;
  int stalled_ = 0;
  double last_trace_ = 0.0;
  Eigen::Vector3d mean_ = Eigen::Vector3d::Zero();  // GMM: running mean of pose estimates
  std::string reason_;
};

}  // namespace slamo::mapping
