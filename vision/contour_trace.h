// The outer outlines of a binary image's 8-connected regions, as
// cv::findContours(mask, outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, offset) gives them
// (Suzuki and Abe's border following): the same outlines in the same order, each with the same
// points from the same start. Without OpenCV's bordered copy, its memory-storage sequences and
// its byte-at-a-time scan of the background, which made cv::findContours the detector's largest
// single cost (#17).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace slamo::vision {

// Every outer outline of `mask` (CV_8UC1; any non-zero pixel is foreground), each point
// shifted by `offset`, into `outlines` (replaced). Regions inside another region's hole are
// not reported, as with RETR_EXTERNAL. Throws std::invalid_argument on another image type.
void FindOuterContours(const cv::Mat& mask, std::vector<std::vector<cv::Point>>* outlines,
                       cv::Point offset = cv::Point());

}  // namespace slamo::vision
