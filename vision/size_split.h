// Touching objects of a known size split by that size (issue 16, items 3 and 4): the blob's
// pixels, back-projected with their depth into the robot frame (level with the floor), are
// sorted into stack levels by their height (objects rest on the floor or on one another), and
// each level's footprint on the floor is clustered (k-means) into the fewest groups that each
// fit one object's width. A ring is one group however concave its outline; a stack of N
// rings is N groups, one per band of the ring's thickness; blocks side by side, one behind
// another or on top of each other are one group each; a pile is as many groups as its
// visible objects. Pure function of the mask and depth.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "vision/camera_model.h"

namespace slamo::vision {

// One object's extent, from the season file's object type.
struct ObjectExtent {
  double width_m = 0.0;   // horizontal: a diameter, or a box's edge
  double height_m = 0.0;  // vertical, resting on the floor (a ring's thickness)
  // A group fits one object when the rectangle round its footprint on the floor (turned as
  // it lies) is at most this x width_m on its long side ...
  double horizontal_limit = 1.25;
  double vertical_limit = 1.3;  // a blob is at most max_stack x this x height_m tall
  // A blob taller than this x height_m x vertical_limit is not a stack of these objects (a
  // structure, a robot's bumper standing up): not split (objects 0).
  int max_stack = 1;
  // ... and a blob flatter than this x height_m is not these objects either (floor markings,
  // a low bar of the same colour).
  double min_vertical = 0.7;
  // Heights above the floor where these objects also rest (TargetKind::rest_heights_m): a blob
  // whose bottom lies at one (within floor_tolerance) is split as if that were the floor.
  std::vector<double> rest_heights_m = {};
  int rest_max_stack = 1;  // the tallest stack placed on any of them
};

struct SizeSplitOptions {
  int max_objects = 40;         // a blob is never split into more groups than this
  double cell_size = 0.1;       // footprint cells, x the object's width
  double trim_fraction = 0.03;  // extents are taken between these quantiles (depth outliers
                                // at the rim, where a pixel sees past the object)
  int erode_px = 1;             // the blob's rim is left out of the clustering
  int kmeans_iterations = 12;
  // A point up to this x the object's height above a level's top is still on it (its top
  // face, with depth noise).
  double level_slack = 0.1;
  // The blob's top (its 97th percentile) within this x the object's height of a whole number
  // of heights; each object of the top level at least min_top_depth widths deep on the floor
  // (seen from above, an object shows its top and its front: its whole depth, unless something
  // hides part of it; a robot's bumper, 6 cm thick, shows 0.4 of a 15 cm cube's).
  double top_tolerance = 0.2;
  double min_top_depth = 0.6;
  // The same for round objects, which show only their front half (SplitBySize does not know
  // the shape: the caller passes this as min_top_depth for them).
  double min_top_depth_round = 0.35;
  // A top level with at least this fraction of its groups thinner than min_top_depth is
  // refused; fewer thin groups are slivers (objects hidden behind others, cut by the image's
  // edge) whose pixels go to no piece. 0: a single thin group refuses the blob.
  double sliver_fraction = 1.0 / 3.0;
  // Objects may rest on the supports of ObjectExtent::rest_heights_m (false: the floor only,
  // as before them).
  bool rest_on_supports = true;
  // ... asked only when the top faces can show: for objects resting on a support above the
  // floor (ObjectExtent::rest_heights_m), only when a top face would be at least this many
  // pixels deep seen from the camera's height at the objects' range.
  double min_top_face_px = 2.0;
  // The blob's bottom (its 3rd percentile) at most this x the object's height above the floor:
  // objects rest on it, so a blob raised off it is something else of their colour.
  double floor_tolerance = 0.5;
  // ... unless the blob is flat and lies at a whole number of object heights (within
  // top_tolerance, up to the tallest stack): the top faces of objects whose sides are hidden
  // (some of Push Back's blocks in the arena views show nothing else).
  bool top_faces = true;
  // ... or unless its lower edge is hidden: in at least this fraction of its columns, the
  // pixels under it (up to an object's height) see something standing higher than
  // hidden_min_height x the object's height, nearer the camera by hidden_min_gap x its width
  // (a low bar the objects lie behind; a ring of another colour under a ring is no nearer).
  // Such a blob may show only its objects' upper parts: its bottom must lie below
  // hidden_max_bottom x the object's height (what hides it is lower than the objects; with it
  // at any height, blocks in Push Back's raised long goals, behind the goal's tube, were cut
  // into a stack of six). 0: never.
  double hidden_fraction = 0.5;
  double hidden_min_height = 0.25;
  double hidden_min_gap = 0.25;
  double hidden_max_bottom = 1.0;
  // Each group, grown back over the blob's rim, stops at the pixels given to another group:
  // grown over them, neighbouring pieces overlapped (a second detection on one object, or one
  // spanning two: most of Skyrise's and Push Back's "pieces").
  bool exclusive_growth = true;
  int min_level_points = 4;  // a stack level (or a part of one apart from the rest on the
                             // floor) with fewer footprint cells has no objects of its own
  // Footprint cells within this x the object's width of each other belong to one part of a
  // level; parts further apart on the floor are never one object (objects that overlap in
  // the image, one behind another, but lie apart). 0: a level is one part.
  double link_fraction = 0.5;
};

struct SizeSplitResult {
  std::vector<std::vector<cv::Point>> pieces;  // one external contour per object, mask pixels
  int objects = 0;  // groups found (0: no depth on the blob, or taller than a stack; pieces
                    // then holds nothing)
};

// The blob without its outermost `erode_px` pixels (where depth may read what lies behind
// the object), in a buffer of its own (eroded into a view of `mask`, the caller's blob would
// shrink too); `mask` itself when erode_px is 0 or fewer than `min_pixels` would be left.
// Shared with the split by the balls' centres (sphere_split.h).
cv::Mat RimlessCore(const cv::Mat& mask, int erode_px, int min_pixels);

// `mask`: CV_8UC1, non-zero on the blob; `depth_mm`: CV_16UC1 raw readings of the same size;
// `offset`: where the mask's (0, 0) lies in the full image (for the camera's intrinsics).
// When `depth_mm` is a view into a larger depth image, the rows under it are read too (a
// hidden lower edge, SizeSplitOptions::hidden_fraction); a depth image of the mask's size
// alone never shows one.
SizeSplitResult SplitBySize(const cv::Mat& mask, const cv::Mat& depth_mm, cv::Point offset,
                            const CameraModel& camera, const ObjectExtent& extent,
                            const SizeSplitOptions& options = {});

}  // namespace slamo::vision
