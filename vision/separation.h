// Separation of touching round objects in a binary mask (thesis 5.2.3): the thesis's cut
// along concave-defect pairs, repeated in passes for three or more objects, and the
// distance-transform watershed it compares against. Pure functions of the mask.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace slamo::vision {

enum class SeparationMethod { kNone, kConcaveDefects, kWatershed };

struct SeparationOptions {
  double min_defect_depth_ratio = 0.12;  // a defect counts when deeper than this x the blob's
                                         // equivalent radius sqrt(area / pi)
  int max_passes = 4;                    // repeated passes for three or more objects (the
                                         // thesis's flag loop)
  double min_piece_area_ratio = 0.08;    // pieces smaller than this x their blob's area are
                                         // dropped (kConcaveDefects)
  double watershed_peak_ratio = 0.6;     // watershed markers: distance transform above this x
                                         // its maximum within the blob
};

struct SeparationResult {
  std::vector<std::vector<cv::Point>> pieces;  // one external contour per object
  int passes = 0;                              // passes that cut something (kConcaveDefects);
                                               // 1 for kWatershed, 0 for kNone
  int cuts = 0;                                // cut lines drawn (kConcaveDefects only)
};

// Splits a binary mask (CV_8UC1, non-zero = object) holding one or more connected blobs of
// touching round objects into one contour per object. Throws std::invalid_argument on an
// empty, multi-channel or non-8-bit mask; an all-zero mask gives an empty result.
SeparationResult SeparateTouching(const cv::Mat& mask, SeparationMethod method,
                                  const SeparationOptions& options = {});

// "defects" | "watershed" | "none"; std::invalid_argument otherwise.
SeparationMethod ParseSeparationMethod(const std::string& name);

}  // namespace slamo::vision
