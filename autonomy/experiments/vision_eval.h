// Vision against the simulator's ground truth: renders random views of a season's field
// (clean, or in the arena: a crowd, posters and lights beyond the perimeter and opponent
// robots on the field), runs every detection method (threshold / K-Means) with every
// separation method (concave defects / watershed / none), drops the detections the field's
// geometry rules out (vision/field_gate.h), and scores them: precision with and without that
// gate, recall (solid and semi-transparent objects apart), count accuracy on groups of
// touching objects (stacks included), centre error in pixels, position error in metres by
// distance band, and per object type precision, recall and typing.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "vision/detector.h"

namespace slamo::autonomy {

struct VisionEvalOptions {
  int frames = 50;
  uint64_t seed = 1;
  bool arena = false;       // render the arena (platform/sim/sim_arena.h)
  int arena_opponents = 2;  // arena: robots placed on the field, one per alliance
  bool depth = true;  // false: the detector gets no depth image (ranges from the ground plane)
  double max_range_m = 3.0;           // objects further from the robot are not expected
  int min_visible_px = 40;            // truth objects with fewer visible pixels are not expected
  double min_visible_fraction = 0.5;  // ... nor those showing less of their disc than this
  double touching_fraction = 0.5;     // share of frames where an object is moved against another
  // Piles: when pile_max > 0, every view gets a heap of pile_min..pile_max touching objects of
  // the season's smallest type, one colour, on the floor 1-2 m in front of the robot
  // (platform::AddPile); each method's count of it is scored.
  int pile_min = 0, pile_max = 0;
  // The field gate's pose: the true pose plus Gaussian error of this sigma (m) in x and y,
  // which the gate is also told.
  double pose_sigma_m = 0.05;
  vision::DetectOptions detect;  // every method's options but its method and separation
  std::string picture_dir;       // when set: annotated views of the worst frames go here
  int picture_frames = 12;
  std::string picture_method = "kmeans+defects";  // whose detections the pictures show
};

struct TypeScore {
  int detected = 0;        // detections the detector typed as this type (after the gate)
  int detected_right = 0;  // ... that are an object of this type
  int expected = 0;        // expected objects of this type
  int found = 0;           // ... matched by a detection
  int typed = 0;           // ... matched by a detection typed (with a range)
  int typed_right = 0;     // ... typed as this type
};

struct VisionMethodScore {
  std::string name;  // e.g. "kmeans+defects"
  vision::DetectMethod method = vision::DetectMethod::kThreshold;
  vision::SeparationMethod separation = vision::SeparationMethod::kConcaveDefects;
  int true_positives = 0;  // after the field gate
  int false_positives = 0;
  // ... of which lie mostly on objects of their colour (a second detection on one, a piece of
  // one, one spanning two), mostly on an opponent robot, or on anything else.
  int false_pieces = 0, false_on_robots = 0, false_other = 0;
  int raw_true_positives = 0;  // without the gate
  int raw_false_positives = 0;
  int rejected_by_geometry = 0;  // detections the gate dropped
  int rejected_objects = 0;      // ... of which were objects (wrongly dropped)
  int rejected_structure = 0;    // ... of which lay inside a structure of their colour
  int expected = 0;  // visible truth objects (enough pixels, mostly unoccluded, in range)
  int found = 0;     // of those, matched
  int expected_hidden = 0, found_hidden = 0;  // enough pixels but mostly hidden
  int expected_solid = 0, found_solid = 0;
  int expected_semi = 0, found_semi = 0;
  int groups = 0;          // groups of touching same-coloured objects in view
  int groups_counted = 0;  // ... with exactly one detection on each member
  // Piles (--pile): views with a pile in sight; its visible members (>= min_visible_px
  // pixels); the method's kept detections of the pile's colour centred on it.
  int piles = 0;
  int piles_within_10pct = 0;               // |detections - visible| <= 10 % of visible
  int pile_visible = 0, pile_detected = 0;  // sums over the piles
  double pile_abs_error_ratio_sum = 0.0;    // |detections - visible| / visible
  double centre_error_px_sum = 0.0;
  int centre_errors = 0;
  // Distance band (0: < 1 m, 1: 1-2 m, 2: 2-3 m, 3: >= 3 m) -> (sum of errors, count).
  std::map<int, std::pair<double, int>> position_error_m;
  std::map<std::string, TypeScore> types;

  double Precision() const;
  double RawPrecision() const;
  double Recall() const;
};

// Progress: called after each frame with (done, total).
std::vector<VisionMethodScore> EvaluateVision(const field::SeasonConfig& season,
                                              const field::RobotConfig& robot,
                                              const VisionEvalOptions& options,
                                              const std::function<void(int, int)>& progress = {});

// The scores as a table, one row per method.
std::string FormatVisionTable(const std::vector<VisionMethodScore>& scores);
// Pile counts per method (empty when no pile was scored).
std::string FormatPileTable(const std::vector<VisionMethodScore>& scores);
// One method's scores per object type.
std::string FormatTypeTable(const VisionMethodScore& score);

}  // namespace slamo::autonomy
