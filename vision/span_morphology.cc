#include "vision/span_morphology.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace slamo::vision {
namespace {

// Morphology of an 8-bit mask with a kernel whose rows are each one run of ones centred on
// the anchor column (an ellipse), exactly as cv::dilate / cv::erode with their default
// border (pixels beyond the image take no part): each kernel row is a horizontal max (min)
// over its half-width, and the rows are combined by a vertical max (min). The same maxima
// (minima) of the same pixels, with a few passes per row instead of one per kernel element.
// False (nothing done) for any other kernel.
template <bool kDilate>
bool SpanMorphology(const cv::Mat& src, const cv::Mat& kernel, cv::Mat* dst) {
  // A view into a larger image: OpenCV reads the pixels around it.
  if (src.empty() || src.isSubmatrix() || src.type() != CV_8UC1 || kernel.type() != CV_8UC1 ||
      kernel.cols % 2 == 0) {
    return false;
  }
  const int centre = kernel.cols / 2, anchor_row = kernel.rows / 2;
  std::vector<int> half(kernel.rows, -1);  // per kernel row: half-width, -1 if empty
  for (int i = 0; i < kernel.rows; ++i) {
    const uint8_t* k = kernel.ptr<uint8_t>(i);
    int first = -1, last = -1;
    for (int j = 0; j < kernel.cols; ++j) {
      if (k[j]) {
        if (first < 0) first = j;
        if (last >= 0 && last != j - 1) return false;  // not one run
        last = j;
      }
    }
    if (first < 0) continue;
    if (centre - first != last - centre) return false;  // not centred
    half[i] = centre - first;
  }
  const int rows = src.rows, cols = src.cols;
  const auto op = [](uint8_t a, uint8_t b) -> uint8_t {
    return kDilate ? std::max(a, b) : std::min(a, b);
  };
  const int widest = *std::max_element(half.begin(), half.end());
  if (widest < 0) return false;  // an empty kernel
  // horizontal[w]: each row's max (min) over [x - w, x + w] (within the row).
  thread_local std::vector<std::vector<uint8_t>> horizontal;
  if (static_cast<int>(horizontal.size()) < widest + 1) horizontal.resize(widest + 1);
  for (int w = 0; w <= widest; ++w) horizontal[w].resize(static_cast<size_t>(rows) * cols);
  for (int y = 0; y < rows; ++y) std::copy_n(src.ptr<uint8_t>(y), cols, &horizontal[0][y * cols]);
  for (int w = 1; w <= widest; ++w) {
    for (int y = 0; y < rows; ++y) {
      const uint8_t* in = &horizontal[w - 1][y * cols];
      uint8_t* out = &horizontal[w][y * cols];
      if (cols == 1) {
        out[0] = in[0];
        continue;
      }
      out[0] = op(in[0], in[1]);
      for (int x = 1; x + 1 < cols; ++x) out[x] = op(op(in[x - 1], in[x]), in[x + 1]);
      out[cols - 1] = op(in[cols - 2], in[cols - 1]);
    }
  }
  cv::Mat out(rows, cols, CV_8UC1, cv::Scalar(kDilate ? 0 : 255));
  for (int y = 0; y < rows; ++y) {
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int i = 0; i < kernel.rows; ++i) {
      const int from = y + i - anchor_row;
      if (half[i] < 0 || from < 0 || from >= rows) continue;
      const uint8_t* in = &horizontal[half[i]][from * cols];
      for (int x = 0; x < cols; ++x) o[x] = op(o[x], in[x]);
    }
  }
  *dst = out;
  return true;
}

// OpenCV's default kernel: 3x3, all ones.
const cv::Mat& KernelOrDefault(const cv::Mat& kernel) {
  static const cv::Mat square = cv::Mat::ones(3, 3, CV_8UC1);
  return kernel.empty() ? square : kernel;
}

}  // namespace

void ErodeLike(const cv::Mat& src, const cv::Mat& kernel, cv::Mat* dst) {
  if (!SpanMorphology<false>(src, KernelOrDefault(kernel), dst)) cv::erode(src, *dst, kernel);
}

void DilateLike(const cv::Mat& src, const cv::Mat& kernel, cv::Mat* dst) {
  if (!SpanMorphology<true>(src, KernelOrDefault(kernel), dst)) cv::dilate(src, *dst, kernel);
}

}  // namespace slamo::vision
