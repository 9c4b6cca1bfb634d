// What the field's geometry says about a detection. An object resting on the floor and seen
// without depth gets its range from where the ray through its centre meets the plane of its
// centre (the camera's mount is known), and its type from its apparent size at that range.
// A detection that cannot be an object on this field is dropped: with a position (depth or
// the ground plane), one outside the perimeter or above anything the season places; without
// one, one whose lowest pixel's ray never comes down into the field's box (it looks over the
// perimeter wall at the stands). The field's size and height come from the season file.
// With depth, a detection whose centre lies inside a fixed structure of its own colour (a red
// stash), or whose measured surface lies on one (an alliance-coloured post or bar), is that
// structure, not an object, and is dropped too.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "field_configs/season_config.h"
#include "vision/camera_model.h"
#include "vision/measurement.h"

namespace slamo::vision {

struct Detection;

// Where objects can be: inside the perimeter's inner faces, from the floor up to the tallest
// object resting on it (at least the perimeter wall's top), and higher only over the places
// the season raises them: goals objects go into (up to the opening plus the tallest object)
// and objects placed above the floor (stacks, objects on structures).
struct FieldBounds {
  double half_size_m = 0.0;  // the perimeter's inner faces at x, y = +-half_size_m
  double floor_top_m = 0.0;  // max(wall top, tallest object type)
  struct Column {
    Eigen::Vector2d min_m = Eigen::Vector2d::Zero(), max_m = Eigen::Vector2d::Zero();
    double top_m = 0.0;
  };
  std::vector<Column> raised;
  // The season's coloured structures an object cannot lie inside: a detection of the same
  // colour whose centre is in one, or whose surface is on one, is the structure. Left out: those
  // objects thread onto (a goal scoring a ring) or enter (a goal entered through its ends), and
  // those an object starts on or in below their top.
  struct Solid {
    std::string colour;
    bool cylinder = false;
    Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
    Eigen::Vector2d half_size_m = Eigen::Vector2d::Zero();  // a box, along its own axes
    double radius_m = 0.0;                                  // a cylinder
    double yaw_rad = 0.0;
    double z_min_m = 0.0, z_max_m = 0.0;
    // How far (m) the point p (world, x y) is outside the solid's footprint; 0 inside.
    double DistanceOutside(const Eigen::Vector2d& p) const;
  };
  std::vector<Solid> solids;
};
FieldBounds FieldBoundsOf(const field::SeasonConfig& season);

struct FieldGateOptions {
  // How far outside the bounds a detection may be, in standard deviations of its position
  // (its measurement covariance and the pose's), before it is dropped.
  double sigmas = 3.0;
  double pose_sigma_m = 0.0;  // 1 sigma of the robot's position estimate
};

// The measurement of an object resting on the floor (its centre centre_height_m above the
// floor) seen at centre_px, without depth: the ray through the centre meets the plane
// z = centre_height_m in the robot frame. nullopt when the ray does not come down to it.
// The covariance propagates the pixel uncertainty (options.pixel_sigma_px plus
// options.pixel_sigma_ratio x radius_px) through that intersection.
std::optional<Measurement> GroundPlaneMeasurement(const CameraModel& camera,
                                                  const cv::Point2d& centre_px, double radius_px,
                                                  double centre_height_m,
                                                  const MeasurementOptions& options = {});

// What the gate makes of a detection seen by `camera` from the robot at `robot_pose` (x_m,
// y_m, heading_rad; the estimate): an object on the field, something off it (beyond the
// perimeter, above where objects can be), or a structure of the detection's own colour.
enum class GateVerdict { kOnField, kOffField, kStructure };
GateVerdict Judge(const Detection& detection, const CameraModel& camera,
                  const Eigen::Vector3d& robot_pose, const FieldBounds& bounds,
                  const FieldGateOptions& options = {},
                  const MeasurementOptions& measurement_options = {});

// Whether a detection can be an object on the field: Judge(...) == GateVerdict::kOnField.
bool OnField(const Detection& detection, const CameraModel& camera,
             const Eigen::Vector3d& robot_pose, const FieldBounds& bounds,
             const FieldGateOptions& options = {},
             const MeasurementOptions& measurement_options = {});

// The detections OnField keeps, in order; *rejected (when given) counts the others.
std::vector<Detection> RejectOffField(const std::vector<Detection>& detections,
                                      const CameraModel& camera, const Eigen::Vector3d& robot_pose,
                                      const FieldBounds& bounds,
                                      const FieldGateOptions& options = {},
                                      const MeasurementOptions& measurement_options = {},
                                      int* rejected = nullptr);

}  // namespace slamo::vision
