// Object and landmark detection on a colour frame (and its registered depth, when there is
// one): per colour class a mask from the HSV threshold or from K-Means colour clustering,
// blobs cleaned at the scale of the object expected at their depth, touching objects split
// (concave defects or watershed), shape and size filtering, and a range-bearing measurement
// for each detection with depth.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "vision/camera_model.h"
#include "vision/colour_classes.h"
#include "vision/measurement.h"
#include "vision/separation.h"
#include "vision/size_split.h"
#include "vision/sphere_split.h"

namespace slamo::vision {

enum class DetectMethod { kThreshold, kKMeans };
DetectMethod ParseDetectMethod(const std::string& name);  // "threshold" | "kmeans"
const char* ToString(DetectMethod method);

struct DetectOptions {
  DetectMethod method = DetectMethod::kThreshold;
  SeparationMethod separation = SeparationMethod::kConcaveDefects;
  SeparationOptions separation_options;
  MeasurementOptions measurement;
  double min_area_px = 25.0;              // blobs below this are noise at any distance
  double single_object_solidity = 0.985;  // blobs filling this much of their hull: not split
  size_t separation_max_pixels = 6000;    // larger blob windows are separated scaled down
  double min_expected_area_ratio = 0.15;  // with depth: blobs below this x the expected area go
  double size_tolerance = 1.8;  // with depth: apparent radius within [1/x, x] of an object's
  // With depth, a piece too small by its area for every kind is a flat kind (thinner than
  // half its width: a ring) seen from the side when its width fits the kind's apparent width
  // (within size_tolerance) and its height is 0.5 to size_tolerance x the kind's apparent
  // thickness, and the image's edge does not cut it: the lower ring of a stack of two
  // colours, whose top the ring on it hides.
  bool flat_side_pieces = true;
  // With depth, a piece split off by the objects' size (or the balls' centres) below this x
  // the smallest kind's apparent area at its depth is a strip of a rim, not an object. 0: off.
  double min_sized_area_ratio = 0.1;
  // With depth, a blob of a colour with no round kind that is at most one object's apparent
  // diagonal wide and tall (plus this, px: the outline's pixel quantisation) is not separated.
  double extent_margin_px = 2.0;
  // With depth, separation by the objects' known size (vision/size_split.h): for colours with
  // no round kind every blob (a ring is never cut, a stack of rings or blocks is split one by
  // one); for round kinds of one size, piles: blobs larger than pile_area_ratio objects
  // (split_piles_by_size).
  bool split_by_size = true;
  bool split_piles_by_size = true;
  double size_tolerance_horizontal = 1.25;  // a group fits one object up to this x its width
  double size_tolerance_vertical = 1.3;     // ... and this x its height
  // With depth, a piece of a kind that is not round, not split off by size, whose points span
  // in height more than size_tolerance_vertical x the tallest the kind stands (its width on its
  // edge, or its tallest stack) is not one (High Stakes' upright blue and red bars taken for
  // rings).
  bool drop_too_tall = true;
  // With depth, when solid kinds of a colour whose heights differ by this factor or more both
  // fit a piece by size, its kind is the one whose height its points span nearest (Starstruck's
  // stars lying flat, 9 cm, against its 25 cm cubes: by size alone most were typed wrong).
  // 0: by size alone.
  double type_height_ratio = 1.5;
  double pile_area_ratio = 4.0;  // x the apparent area of one object
  SizeSplitOptions size_split;
  // With depth, blobs of a colour whose solid round kinds (spheres, triballs) are of one size
  // are split by the balls' centres (vision/sphere_split.h) when two or more are found; one
  // or none leaves the blob to the paths above.
  bool split_spheres = true;
  double sphere_split_min_area = 1.1;  // ... for blobs larger than this x one ball's area
  // ... and, whatever the blob, a piece of the cut that no circle fits is split by the balls'
  // centres in it (two buckyballs one behind another beside Toss Up's large ball).
  bool split_sphere_pieces = true;
  // ... and a blob of a colour with a semi-transparent ball, a piece of whose cut no circle
  // fits (the ball's face shows what lies behind it: its mask is ragged, notched, and the cut
  // takes it apart), is that ball, or two, when its depth lies on the front of balls of the
  // kind's size that explain it and fill their discs in the image; the rest of the blob goes
  // on apart. Tried again on a piece that fits no circle (a ball beside others of its colour).
  bool semi_sphere_pieces = true;
  // ... with K-Means, the method for semi-transparent objects (the thesis's), only; with the
  // HSV threshold too when set. Off by default: the threshold is the speed path (#17's goal,
  // README "Speed"), and on the benchmark's Toss Up view, full of large balls near the camera,
  // the step took it 2.9 -> 4.5 ms (K-Means 7.2 -> 7.4 ms).
  bool semi_sphere_threshold = false;
  double semi_sphere_min_area = 0.3;  // ... for blobs at least this x the ball's whole area
  // ... and whose mask covers at least this share of each ball's disc as the camera sees it
  // (two buckyballs one above another explain the front of a large ball's sphere too).
  double semi_sphere_min_fill = 0.5;
  // The depth's test for them: one ball is enough, and a large ball is placed as well from
  // every third pixel of every third row, 300 of them voting, three failed peaks ending the
  // search (Toss Up's arena views, seed 1: the same balls found as from every pixel; the
  // threshold path's benchmark frame about 1 ms faster, README).
  SphereSplitOptions semi_sphere_split = [] {
    SphereSplitOptions o;
    o.min_objects = 1;
    o.pixel_step = 3;
    o.max_points = 300;
    o.max_rejections = 3;
    return o;
  }();
  SphereSplitOptions sphere_split;
  // Round kinds: a circle fitted to the blob's outline (not the image border or a cut) must
  // fit within this x its radius (rms) and cover at least this much of the circle.
  double max_arc_rms_ratio = 0.1;
  double min_arc_coverage_deg = 120.0;
  double min_arc_inlier_fraction = 0.5;  // share of the outline on the circle
  // For colours with a semi-transparent ball: a blob, before the cut, whose own outline fits
  // a circle (as above, but for the inlier fraction) that it fills to this share (in the
  // image) is that ball, one piece, and the rest of it is separated apart. 0: off.
  double min_disc_fill = 0.8;
  double min_disc_outline = 0.7;  // ... and whose outline runs on it this share of the way round
  // With depth, a detection typed as a round solid kind must curve away from the camera
  // (vision/measurement.h MeasureSurfaceBulge): it is dropped as a flat face (a wall, a
  // robot's bumper) when its rims' bulge, plus 3 sigma of the depth noise, stays under this x
  // the kind's radius. A sphere's is about 0.28; a triball's least, a face turned to the
  // camera (a sphere of its width), about 0.12. 0 turns the test off.
  double min_bulge_ratio = 0.1;
  // ... and must curve in every direction, not only across one (MeasureLeastCurvature): a
  // piece whose curvature nearest zero (signed: below) plus flat_curvature_sigmas of its
  // depth-noise sigma, stays under flat_curvature_ratio / the kind's radius is flat along some
  // direction (a bumper's noodle or a box edge, convex or concave, running any way in the
  // image, which the bulge test's row and column bands miss when it runs diagonally) and is
  // dropped. A sphere gives about 1, a triball's face turned to the camera (a sphere of its
  // width) about 0.5. 0: off.
  double flat_curvature_ratio = 0.3;
  double flat_curvature_sigmas = 2.0;
  // ... signed: the lowest curvature is judged, not the one nearest zero, so a piece curving
  // towards the camera along some direction (a saddle, a hollow) is dropped however strongly
  // it curves. false: the size of the one nearest zero (the detector before, for comparison).
  bool convex_curvature = true;
  // With depth, for colours of solid kinds with flat bases (no round kind: rings, cubes,
  // blocks, goals): the part of a blob held off the floor over nothing is cleared (a robot's
  // bumper, alone or touching an object). A column floats when the farthest of the
  // float_below_rows rows under its lowest pixel lies float_margin_m plus 3 sigma of the depth
  // noise beyond it (a ring's or block's foot stands on the floor in front of it; a ball or a
  // triball shows floor under its curve, so round kinds are not tested); runs of at least
  // float_min_columns floating columns, and at least float_min_run_widths of the largest
  // kind's apparent width at the blob's depth, are cleared (a narrower run may be the
  // overhang of an object on a thin support: a cube on a post).
  // With depth, for round solid kinds: the top of a ball's or triball's outline is an
  // occluding edge (over it the camera sees past the object, or something in front of it;
  // anything touching it from behind lies deeper, by its radius seen level and by r (1 - sin
  // a) / cos a seen down at a), while the top of a piece that is the lower part of a taller
  // body runs on into that body at its own depth (a robot's bumper under its chassis). Per
  // column of a piece, the depth of its top rows against the rows over them (RunsOnAbove in
  // detector.cc); a column is judged unless what lies over it is of a target colour or a
  // shade of the piece's own (a stack), reads nothing, or is the floor (under
  // attach_floor_m). The piece is dropped when at least attach_min_columns, and
  // attach_min_judged of its columns, are judged and their median step plus 2 sigma of it
  // stays under attach_margin_ratio x that least step. Rings, cubes and blocks are not
  // tested: their outline's top is their far edge, which whatever they touch meets at the same
  // depth (the float test judges bumpers there). 0: off.
  double attach_margin_ratio = 0.75;
  double attach_min_judged = 0.25;
  int attach_min_columns = 3;
  int attach_above_rows = 2;     // rows over the top (after one skipped: mixed edge readings)
  double attach_floor_m = 0.03;  // over the top, a point this low is the floor
  // With depth, for colours whose kinds are all solid: the colour mask is cut where the depth
  // of two neighbouring pixels (8-connected) of it jumps by more than depth_cut_min_m,
  // depth_cut_ratio x the nearer one's depth, and depth_cut_sigmas x its depth noise, all
  // three; the farther pixel is cleared. An object seen against a thing of its own colour far
  // behind it (a poster, a shirt, an alliance wall across the field) is then a blob of its
  // own. Colours with a semi-transparent kind are not cut (tried on Toss Up: recall up, but
  // its benchmark view's time nearly doubled; README, Vision). 0: off.
  double depth_cut_min_m = 0.25;
  // ... for colours none of whose kinds is round (cubes, blocks, rings, goals), which the split
  // by size takes apart only when the blob's top is a whole number of their heights: an object
  // touching, in the image, a structure of its colour a little behind it (a goal's base) is
  // cut from it at this step (landmarks' colours too: their kind is not round). 0:
  // depth_cut_min_m for them too; depth_cut_min_m 0 turns both off.
  double depth_cut_min_flat_m = 0.1;
  double depth_cut_ratio = 0.1;
  double depth_cut_sigmas = 4.0;
  bool drop_floating = true;
  double float_margin_m = 0.02;
  int float_below_rows = 2;
  int float_min_columns = 5;
  double float_min_run_widths = 0.5;
  // K-Means (thesis 5.2.2): clustering of the chromatic pixels in Lab a*b*.
  int kmeans_downsample = 0;           // cluster on an image this many times smaller; 0: about
                                       // 256 px wide (2x at 512x424, 8x at 1920x1080)
  int kmeans_extra_clusters = 2;       // k = 2 x (colour classes + distractors) + this
  double kmeans_min_chroma = 10.0;     // pixels greyer than this (a*b* radius) are not clustered
  double kmeans_max_angle_deg = 25.0;  // a cluster joins the class nearest in a*b* hue angle
  int kmeans_iterations = 10;
  size_t kmeans_max_samples = 4000;  // centres are learnt on at most this many pixels
  uint64_t seed = 1;
};

// One kind of thing to find: an object type in one colour, or a landmark.
struct TargetKind {
  std::string name;                  // object type or "landmark"
  std::string colour;                // a class name
  double radius_m = 0.0;             // apparent radius (half the size)
  double surface_to_centre_m = 0.0;  // from the visible surface to the centre
  double centre_height_m = 0.0;      // the centre above the floor, resting on it (0: unknown)
  double min_circularity = 0.6;      // 4 pi A / P^2 of an unoccluded view (flat kinds)
  bool round = true;                 // looks like a disc from anywhere: judged by a circle fit
  bool solid = true;                 // depth reads its surface (not semi-transparent)
  int max_stack = 1;                 // most of them one on top of another (the season's
                                     // tallest stack placed)
  // Heights above the floor, other than 0, where the season file places them (Push Back's
  // blocks on the long goals): they may rest there too. Not for round kinds.
  std::vector<double> rest_heights_m = {};
  int rest_max_stack = 1;  // the tallest stack placed on any of them
};

struct DetectorSetup {
  std::vector<ColourClass> colours;
  // Other colours in the scene (landmarks, structures...): K-Means gives their clusters to
  // them, not to the nearest target colour.
  std::vector<ColourClass> distractors;
  std::vector<TargetKind> kinds;
  std::optional<CameraModel> camera;  // needed for depth; none for photos
};

DetectorSetup ObjectDetectorSetup(const field::SeasonConfig& season,
                                  const field::CameraConfig* camera);
DetectorSetup LandmarkDetectorSetup(const field::SeasonConfig& season,
                                    const field::CameraConfig* camera);
// For photos: colours from a colours file, any round object of those colours.
DetectorSetup PhotoDetectorSetup(std::vector<ColourClass> colours);

struct Detection {
  std::string colour;
  // The best-fitting TargetKind by size at the measured depth or, without a depth image, at
  // the ground-plane range of an object resting on the floor; "" when none fits or no range.
  std::string kind;
  cv::Point2d centre_px;
  double radius_px = 0.0;
  cv::Rect box;
  double area_px = 0.0;
  double circularity = 0.0;
  double score = 0.0;  // circularity x fill of the enclosing circle, 0..1
  std::vector<cv::Point> contour;
  bool split = false;  // came from separating a blob of touching objects
  bool sized = false;  // ... by the objects' known size (size_split.h, sphere_split.h)
  std::optional<Measurement> measurement;
};

struct DetectStats {
  int blobs = 0;
  int pieces = 0;
  int rejected_small = 0;
  int rejected_shape = 0;
  int rejected_size = 0;
  int rejected_flat = 0;      // round solid kinds whose surface does not curve (a bumper's face)
  int split_by_size = 0;      // blobs separated by the objects' known size
  int semi_discs = 0;         // blobs of a colour with a semi-transparent ball whose outline's
                              // circle was taken as one piece before the cut
  int split_spheres = 0;      // blobs (or pieces of the cut no circle fits) separated by the
                              // centres of balls of one size
  int semi_spheres = 0;       // blobs or pieces no circle fits found to be semi-transparent
                              // balls by their depth (DetectOptions::semi_sphere_pieces)
  int rejected_floating = 0;  // blobs with a part held off the floor over nothing (cleared)
  int rejected_attached = 0;  // pieces whose top runs on into a taller body (a bumper's chassis)
  int without_depth = 0;      // kept, but no range: no valid depth on them (or, without a depth
                              // image, no kind resting on the floor fits their size)
};

// Without a depth image but with a camera, each detection's range comes from the ground plane
// (vision/field_gate.h) for the kind whose apparent size fits best there.
// Throws std::invalid_argument for unusable input: an empty or non-BGR colour image, a depth
// image that is not CV_16UC1 or not the colour image's size.
std::vector<Detection> Detect(const cv::Mat& bgr, const cv::Mat& depth_mm,
                              const DetectorSetup& setup, const DetectOptions& options,
                              DetectStats* stats = nullptr);

// The per-class masks before blob analysis (for pictures and the evaluation).
std::vector<cv::Mat> ColourMasks(const cv::Mat& bgr, const DetectorSetup& setup,
                                 const DetectOptions& options);

// The detections drawn over the colour image: contours, centres, labels.
cv::Mat DrawDetections(const cv::Mat& bgr, const std::vector<Detection>& detections);

}  // namespace slamo::vision
