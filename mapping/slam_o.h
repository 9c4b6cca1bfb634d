// SLAM-O's front end, the thesis's pipeline in one place: a camera frame goes in, and what the
// robot believes comes out. Read top to bottom, the public steps are the pipeline:
//
//   Predict       odometry since the last frame moves the EKF's pose
//   BeginStop     the robot stands: the frame rule starts, and the stop's frames share a bias
//   UpdateLandmarks  frame -> marker detections -> range-bearing measurements (iterated-frame
//                 covariance) -> EKF update of the whole frame -> plausibility gate ->
//                 relocalisation when markers are in view and none fits
//   TrackObjects  frame -> object detections -> the object tracker, placed through the pose
//   UpdateMaps    confirmed objects -> the OctoMap object map and the planner's obstacle map
//
// `Process` runs all of them for one frame, for callers with nothing to do between the steps
// (a recording). The match loop, recording replay and the thesis experiments all go through
// this class; none of them calls the detector or the EKF's updates itself.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "mapping/ekf_slam.h"
#include "mapping/frame_selection.h"
#include "mapping/object_map.h"
#include "mapping/object_tracker.h"
#include "platform/drive_base.h"
#include "platform/rgbd.h"
#include "vision/detector.h"
#include "vision/field_gate.h"

namespace slamo::mapping {

struct SlamOOptions {
  EkfOptions ekf;
  // A per-stop measurement bias (range m^2, bearing rad^2) shared by a stop's frames, so that
  // iterating frames does not shrink the covariance below what the camera's bias allows
  // (IteratedFrameCovariance). The matches take it from the robot file
  // (CameraConfig::stop_bias_*); this default is the thesis robot's.
  Eigen::Matrix2d stop_bias_covariance = Eigen::Vector2d(0.01 * 0.01, 0.005 * 0.005).asDiagonal();
  // Per-frame (white) covariance of a marker measurement; zero: vision's own estimate for
  // each detection.
  Eigen::Matrix2d white_covariance = Eigen::Matrix2d::Zero();
  bool iterate_frames = true;  // false: every frame weighs as the first of its stop
  // Drop a frame whose update throws the pose off the field or further than the belief allows
  // (3 sigma, at least gate_min_jump_m): it paired wrongly.
  bool plausibility_gate = true;
  double gate_min_jump_m = 0.3;
  // Once per stop, when markers are in view and none pairs: widen the pose belief and pair
  // again (the encoders cannot tell when the wheels spun against something that did not move).
  bool relocalise = false;
  // Drop object detections the field's geometry rules out (outside the perimeter, above
  // where objects can be), seen from the pose estimate with its uncertainty.
  bool field_gate = true;
  // Objects are expected to be seen (and lose confidence when they are not) within this range
  // and the camera's field of view less fov_margin_rad, whole: from the camera's mount and the
  // season's object sizes (SlamO::WholeInView; near objects leave the view below).
  double object_min_range_m = 0.0;
  double object_max_range_m = 3.5;
  double fov_margin_rad = 0.05;
};

// Which mapped objects the planner avoids, and how large it takes them.
struct ObstacleRule {
  // Objects narrower than this are pushed aside by the robot: mapped, not planned round.
  double min_size_m = 0.0;
  // An obstacle's radius is its own less shrink_m plus grow_m (at least 2 cm): the planner's
  // clearance margin taken off and half the robot's width put on.
  double shrink_m = 0.0;
  double grow_m = 0.0;
};

// What one frame did to the landmark part of the estimate.
struct LandmarkFrame {
  std::vector<RangeBearing> measurements;  // the frame's marker measurements, as used
  std::vector<UpdateOutcome> outcomes;     // one per measurement (all kRejected when gated)
  bool gated = false;                      // the plausibility gate dropped the frame
  bool relocalised = false;                // a widened belief paired this frame
  bool more_frames = false;                // the frame rule wants another frame at this stop
};

// What one frame's object detection saw, each detection with what became of it (for a picture
// of what the robot saw; the tracker has taken the used ones).
enum class DetectionUse {
  kTracked,   // given to the object tracker
  kOffField,  // dropped by the field gate (vision/field_gate.h)
  kNoRange,   // on the field as far as known, but without a range: not tracked
};
struct ObjectFrame {
  struct Seen {
    vision::Detection detection;
    DetectionUse use = DetectionUse::kTracked;
  };
  std::vector<Seen> detections;  // in the detector's order
};

// Where the filter starts, and what it is told of the field.
struct SlamOPrior {
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity() * 1e-6;
  // The season's markers as known landmarks (their surveyed centres, one per season landmark
  // in order), each known to marker_sigma_m; empty: the markers are found as the robot goes.
  std::vector<Eigen::Vector2d> surveyed_markers;
  double marker_sigma_m = 1e-3;
};

// The odometry increment from one dead-reckoned pose to the next, in the frame of the first.
OdometryStep OdometryIncrement(const platform::Pose2D& from, const platform::Pose2D& to);

class SlamO {
 public:
  // The filter starts from `prior`; markers and objects are detected with the season's
  // colours through `camera`. A marker colour shared by several markers is associated by
  // position (JCBB), a unique one by its colour.
  SlamO(const field::SeasonConfig& season, const field::CameraConfig& camera,
        const SlamOPrior& prior, const SlamOOptions& options = {});
  // The object maps refer to the season kept here: neither copied nor moved.
  SlamO(const SlamO&) = delete;
  SlamO& operator=(const SlamO&) = delete;

  // 1. Odometry since the last frame.
  void Predict(const OdometryStep& u);
  // 2. A stop begins: frames from here on are the stop's (the frame rule counts them).
  void BeginStop(const FrameSelectionOptions& rule = {});
  // 3. One frame's markers into the EKF.
  LandmarkFrame UpdateLandmarks(const platform::RgbdFrame& frame);
  // 4. One frame's objects into the tracker at t_s; returns every detection and its use.
  ObjectFrame TrackObjects(const platform::RgbdFrame& frame, double t_s);
  // 5. The confirmed objects, less those taken off the field, into the object map and, by
  // `obstacles` when given, the planner's obstacle map.
  void UpdateMaps(const std::vector<int>& taken_ids = {},
                  const std::optional<ObstacleRule>& obstacles = std::nullopt);

  // Steps 1-4 for one frame: predict by `u`, a new stop when the robot moved (its frames
  // then count from one again), the markers, and the objects when track_objects (at the
  // frame's time). The maps are the caller's to update when it wants them.
  LandmarkFrame Process(const platform::RgbdFrame& frame, const OdometryStep& u,
                        bool track_objects);

  // 6. The robot of `length_m` x `width_m` stands at the estimated pose: objects on the floor
  // believed under it are not there (it pushed them aside, or they never were), and are
  // forgotten. Under means the object's centre inside the footprint shrunk by two standard
  // deviations of the pose's and the object's position errors; objects within a goal's or a
  // structure's footprint that the robot does not drive over are kept (they may be up on it).
  // Returns how many were forgotten. With `from`, the estimated pose where the drive that
  // ended here began: objects the footprint swept on the way straight from there are not
  // where they were believed either (the bumper pushed them along).
  // With `mouth_m`, the intake's mouth too, that far beyond the front bumper (to the
  // object's near edge), after a pick that took nothing there.
  int ForgetObjectsUnderRobot(double length_m, double width_m,
                              const std::optional<Eigen::Vector3d>& from = std::nullopt,
                              double mouth_m = 0.0);

  // Whether an object at its tracked position would be seen whole by the camera from `pose`
  // (an upright box of its kind's size and height on the floor).
  bool WholeInView(const Eigen::Vector3d& pose, const TrackedObject& object) const;

  // What it believes.
  const EkfSlam& ekf() const { return ekf_; }
  Eigen::Vector3d pose() const { return ekf_.pose(); }
  Eigen::Matrix3d pose_covariance() const { return ekf_.pose_covariance(); }
  const ObjectTracker& tracker() const { return tracker_; }
  // Confirmed objects (seen often enough), less `taken_ids`, in the tracker's order.
  std::vector<TrackedObject> ConfirmedObjects(const std::vector<int>& taken_ids = {}) const;
  // Forgets one tracked object (e.g. a pick's target not seen where it should have been);
  // whether it was tracked.
  bool ForgetObject(int id);
  const ObjectMap& object_map() const { return object_map_; }
  const ObjectMap& obstacle_map() const { return obstacle_map_; }
  const FrameSelector& frame_selector() const { return selector_; }

  // Counters over the run.
  int frames() const { return frames_; }
  int gated_frames() const { return gated_frames_; }
  int relocalisations() const { return relocalisations_; }
  int rejected_by_geometry() const { return rejected_by_geometry_; }
  int forgotten_under_robot() const { return forgotten_under_robot_; }

 private:
  std::vector<RangeBearing> MarkerMeasurements(const platform::RgbdFrame& frame) const;
  bool Plausible(const EkfSlam& prior) const;
  bool Relocalise(const std::vector<RangeBearing>& measurements);

  field::SeasonConfig season_;
  field::CameraConfig camera_;
  SlamOOptions options_;
  vision::DetectorSetup landmark_detector_;
  vision::DetectorSetup object_detector_;
  vision::FieldBounds field_bounds_;
  std::vector<int> marker_id_;  // per season landmark: its id in the filter, -1: by position
  EkfSlam ekf_;
  FrameSelector selector_;
  ObjectTracker tracker_;
  ObjectMap object_map_;    // every confirmed object: the map SLAM-O keeps
  ObjectMap obstacle_map_;  // what the planner avoids
  int frame_in_stop_ = 0;
  bool relocalised_in_stop_ = false;
  int frames_ = 0;
  int gated_frames_ = 0;
  int relocalisations_ = 0;
  int rejected_by_geometry_ = 0;
  int forgotten_under_robot_ = 0;
};

}  // namespace slamo::mapping
