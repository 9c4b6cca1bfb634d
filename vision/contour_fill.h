// Filled outlines, as cv::drawContours(..., cv::FILLED, cv::LINE_8) draws them, for the
// 8-connected outlines cv::findContours traces (CHAIN_APPROX_NONE): each outline point set,
// and between each row's edge crossings taken in pairs, without OpenCV's line per outline
// step and its edge list. Anything else (longer steps, points outside the image) is drawn by
// cv::drawContours itself.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace slamo::vision {

// Fills every outline (each shifted by `offset`) with 255 into `image` (CV_8UC1), together,
// as cv::drawContours(*image, outlines, -1, 255, cv::FILLED, cv::LINE_8, noArray(), 0,
// offset) does: the same pixels.
void FillOutlines(const std::vector<std::vector<cv::Point>>& outlines, cv::Point offset,
                  cv::Mat* image);

// One outline, as FillOutlines({outline}, offset, image).
void FillOutline(const std::vector<cv::Point>& outline, cv::Point offset, cv::Mat* image);

}  // namespace slamo::vision
