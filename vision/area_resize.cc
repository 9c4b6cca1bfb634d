#include "vision/area_resize.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

// The sums below must round as OpenCV's do: a multiply, then an add, never fused into one.
// vision/CMakeLists.txt compiles this file with -ffp-contract=off.

namespace slamo::vision {
namespace {

// One source pixel's share in one target pixel of a row (or of a column).
struct Tap {
  int source = 0;
  int target = 0;
  float weight = 0.0f;
};

// Each target pixel t covers the source interval [t * step, (t + 1) * step): the whole source
// pixels inside it weigh 1 / width, the pixels cut by its ends the part inside (below a
// thousandth of a pixel: none), all divided by the cell's width (shorter at the far end when
// the target does not reach it). In order of source pixel, then target pixel, as OpenCV lists
// them; the weights are rounded to float as OpenCV's are.
void AreaTaps(int source_size, int target_size, double step, std::vector<Tap>* taps) {
  taps->clear();
  for (int t = 0; t < target_size; ++t) {
    const double begin = t * step, end = begin + step;
    const double width = std::min(step, source_size - begin);
    int last = std::min(cvFloor(end), source_size - 1);
    const int first = std::min(cvCeil(begin), last);
    if (first - begin > 1e-3) {
      taps->push_back({first - 1, t, static_cast<float>((first - begin) / width)});
    }
    for (int s = first; s < last; ++s) taps->push_back({s, t, static_cast<float>(1.0 / width)});
    if (end - last > 1e-3) {
      taps->push_back(
          {last, t, static_cast<float>(std::min(std::min(end - last, 1.0), width) / width)});
    }
  }
}

// The fallbacks of both functions: shrinking by a scale whose inverse is not a whole number
// is done here, anything else by cv::resize.
bool DoneHere(const cv::Mat& src, const cv::Size& size, double step) {
  const int whole_step = cv::saturate_cast<int>(step);
  return src.type() == CV_8UC1 && !src.empty() && size.width > 0 && size.height > 0 &&
         size != src.size() && step >= 1.0 && std::abs(step - whole_step) >= DBL_EPSILON;
}

cv::Size ShrunkSize(const cv::Mat& src, double scale) {
  return cv::Size(cv::saturate_cast<int>(src.cols * scale),
                  cv::saturate_cast<int>(src.rows * scale));
}

// Per target pixel (of a row or a column), its taps [first, end) in `taps`, which AreaTaps
// lists target by target.
void TapRanges(const std::vector<Tap>& taps, int target_size, std::vector<size_t>* first,
               std::vector<size_t>* end) {
  first->assign(target_size, taps.size());
  end->assign(target_size, taps.size());
  for (size_t k = taps.size(); k-- > 0;) (*first)[taps[k].target] = k;
  for (size_t k = 0; k < taps.size(); ++k) (*end)[taps[k].target] = k + 1;
}

}  // namespace

void ShrinkMaskLike(const cv::Mat& src, double scale, cv::Mat* dst) {
  const cv::Size size = ShrunkSize(src, scale);
  const double step = 1.0 / scale;
  if (!DoneHere(src, size, step)) {
    cv::resize(src, *dst, cv::Size(), scale, scale, cv::INTER_AREA);
    cv::threshold(*dst, *dst, 127, 255, cv::THRESH_BINARY);
    return;
  }
  thread_local std::vector<Tap> column_taps, row_taps;
  thread_local std::vector<size_t> column_first, column_end, row_first, row_end;
  AreaTaps(src.cols, size.width, step, &column_taps);
  AreaTaps(src.rows, size.height, step, &row_taps);
  TapRanges(column_taps, size.width, &column_first, &column_end);
  TapRanges(row_taps, size.height, &row_first, &row_end);
  // Each target column's source columns [x0, x1) and rows [y0, y1): the taps' sources.
  thread_local std::vector<int> column_x0, column_x1;
  column_x0.assign(size.width, 0);
  column_x1.assign(size.width, 0);
  for (int tx = 0; tx < size.width; ++tx) {
    if (column_first[tx] >= column_end[tx]) continue;  // no source (cannot happen shrinking)
    column_x0[tx] = column_taps[column_first[tx]].source;
    column_x1[tx] = column_taps[column_end[tx] - 1].source + 1;
  }
  thread_local cv::Mat sums;  // (rows + 1) x (cols + 1): the sum of the values above and left
  cv::integral(src, sums, CV_32S);
  cv::Mat out(size, CV_8UC1, cv::Scalar(0));
  for (int ty = 0; ty < size.height; ++ty) {
    if (row_first[ty] >= row_end[ty]) continue;
    const int y0 = row_taps[row_first[ty]].source, y1 = row_taps[row_end[ty] - 1].source + 1;
    const int* top = sums.ptr<int>(y0);
    const int* bottom = sums.ptr<int>(y1);
    const int full_per_column = 255 * (y1 - y0);
    uint8_t* d = out.ptr<uint8_t>(ty);
    for (int tx = 0; tx < size.width; ++tx) {
      const int x0 = column_x0[tx], x1 = column_x1[tx];
      const int sum = bottom[x1] - bottom[x0] - top[x1] + top[x0];
      if (sum == 0) continue;  // every source pixel 0: every share is zero
      if (sum == full_per_column * (x1 - x0)) {
        // Every source pixel 255: 255 times the weights, which add up to at least 0.998.
        d[tx] = 255;
        continue;
      }
      // The sums ResizeAreaLike forms for this pixel, in its order (the shares of rows and
      // columns it skips are zeros, which change no sum).
      float total = 0.0f;
      for (size_t r = row_first[ty]; r < row_end[ty]; ++r) {
        const uint8_t* s = src.ptr<uint8_t>(row_taps[r].source);
        float row_sum = 0.0f;
        for (size_t c = column_first[tx]; c < column_end[tx]; ++c) {
          row_sum += static_cast<float>(s[column_taps[c].source]) * column_taps[c].weight;
        }
        total += row_taps[r].weight * row_sum;
      }
      if (cv::saturate_cast<uint8_t>(total) > 127) d[tx] = 255;
    }
  }
  *dst = out;
}

void ResizeAreaLike(const cv::Mat& src, double scale, cv::Mat* dst) {
  const cv::Size size = ShrunkSize(src, scale);
  const double step = 1.0 / scale;  // source pixels per target pixel
  // Whole steps (OpenCV's own block average), growing, empty results and other types: OpenCV.
  if (!DoneHere(src, size, step)) {
    cv::resize(src, *dst, cv::Size(), scale, scale, cv::INTER_AREA);
    return;
  }
  thread_local std::vector<Tap> column_taps, row_taps;
  thread_local std::vector<size_t> first_tap;  // per source column: its first column tap
  thread_local std::vector<float> row_sum, total;
  AreaTaps(src.cols, size.width, step, &column_taps);
  AreaTaps(src.rows, size.height, step, &row_taps);
  first_tap.assign(src.cols + 1, column_taps.size());
  for (size_t k = column_taps.size(); k-- > 0;) first_tap[column_taps[k].source] = k;
  for (int c = src.cols - 1; c >= 0; --c) {  // columns no target reaches: the next one's
    first_tap[c] = std::min(first_tap[c], first_tap[c + 1]);
  }
  row_sum.assign(size.width, 0.0f);
  total.assign(size.width, 0.0f);

  cv::Mat out(size, CV_8UC1);
  int current = row_taps.empty() ? 0 : row_taps.front().target;
  for (const Tap& row_tap : row_taps) {
    if (row_tap.target != current) {  // the target row is complete
      uint8_t* d = out.ptr<uint8_t>(current);
      for (int x = 0; x < size.width; ++x) {
        d[x] = cv::saturate_cast<uint8_t>(total[x]);
        total[x] = 0.0f;  // its first share is added to zero: the same as setting it
      }
      current = row_tap.target;
    }
    // The row's foreground span; background adds nothing to any sum.
    const uint8_t* s = src.ptr<uint8_t>(row_tap.source);
    int x0 = 0, x1 = src.cols - 1;
    while (x0 <= x1 && s[x0] == 0) ++x0;
    if (x0 > x1) continue;
    while (s[x1] == 0) --x1;
    const size_t k0 = first_tap[x0], k1 = first_tap[x1 + 1];
    if (k0 >= k1) continue;
    const int t0 = column_taps[k0].target, t1 = column_taps[k1 - 1].target;
    std::fill(row_sum.begin() + t0, row_sum.begin() + t1 + 1, 0.0f);
    for (size_t k = k0; k < k1; ++k) {
      const Tap& tap = column_taps[k];
      row_sum[tap.target] += static_cast<float>(s[tap.source]) * tap.weight;
    }
    const float beta = row_tap.weight;
    for (int t = t0; t <= t1; ++t) total[t] += beta * row_sum[t];
  }
  uint8_t* d = out.ptr<uint8_t>(current);
  for (int x = 0; x < size.width; ++x) d[x] = cv::saturate_cast<uint8_t>(total[x]);
  *dst = out;
}

}  // namespace slamo::vision
