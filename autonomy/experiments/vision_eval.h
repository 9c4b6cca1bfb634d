// Vision against the simulator's ground truth: renders random views of a season's field,
// runs every detection method (threshold / K-Means) with every separation method (concave
// defects / watershed / none), and scores them: precision, recall (solid and semi-transparent
// objects apart), count accuracy on groups of touching objects, centre error in pixels and
// position error in metres by distance band.
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
  int min_visible_px = 40;            // truth objects with fewer visible pixels are not expected
  double min_visible_fraction = 0.5;  // ... nor those showing less of their disc than this
  double touching_fraction = 0.5;     // share of frames where a ball is moved against another
  std::string picture_dir;            // when set: annotated views of the first frames go here
  int picture_frames = 12;
  std::string picture_method = "kmeans+defects";  // whose detections the pictures show
};

struct VisionMethodScore {
  std::string name;  // e.g. "kmeans+defects"
  vision::DetectMethod method = vision::DetectMethod::kThreshold;
  vision::SeparationMethod separation = vision::SeparationMethod::kConcaveDefects;
  int true_positives = 0;
  int false_positives = 0;
  int expected = 0;  // visible truth objects (enough pixels, mostly unoccluded)
  int found = 0;     // of those, matched
  int expected_hidden = 0, found_hidden = 0;  // enough pixels but mostly hidden
  int expected_solid = 0, found_solid = 0;
  int expected_semi = 0, found_semi = 0;
  int groups = 0;          // groups of touching same-coloured objects in view
  int groups_counted = 0;  // ... whose every member was found
  double centre_error_px_sum = 0.0;
  int centre_errors = 0;
  // Distance band (0: < 1 m, 1: 1-2 m, 2: 2-3 m, 3: >= 3 m) -> (sum of errors, count).
  std::map<int, std::pair<double, int>> position_error_m;

  double Precision() const;
  double Recall() const;
};

// Progress: called after each frame with (done, total).
std::vector<VisionMethodScore> EvaluateVision(const field::SeasonConfig& season,
                                              const field::RobotConfig& robot,
                                              const VisionEvalOptions& options,
                                              const std::function<void(int, int)>& progress = {});

// The scores as a table, one row per method.
std::string FormatVisionTable(const std::vector<VisionMethodScore>& scores);

}  // namespace slamo::autonomy
