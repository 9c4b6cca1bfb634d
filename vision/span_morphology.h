// Erosion and dilation of 8-bit masks, as cv::erode and cv::dilate do them with their
// defaults (the anchor at the kernel's centre, one iteration, pixels beyond the image taking
// no part): the same bytes. For kernels whose rows are each one run of ones centred on the
// middle column (squares, ellipses, crosses: every kernel the detector uses), done as a few
// row passes, without OpenCV's filter engine set up per call, which cost more than the
// filtering on a blob's small window (#17). Other kernels, other images and views into a
// larger image (whose surrounding pixels OpenCV reads) go to OpenCV.
#pragma once

#include <opencv2/core.hpp>

namespace slamo::vision {

// cv::erode(src, *dst, kernel); `src` may be `*dst`. An empty kernel is OpenCV's 3x3 square.
void ErodeLike(const cv::Mat& src, const cv::Mat& kernel, cv::Mat* dst);

// cv::dilate(src, *dst, kernel); `src` may be `*dst`. An empty kernel is OpenCV's 3x3 square.
void DilateLike(const cv::Mat& src, const cv::Mat& kernel, cv::Mat* dst);

}  // namespace slamo::vision
