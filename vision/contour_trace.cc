#include "vision/contour_trace.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace slamo::vision {
namespace {

// Border-following marks, as Suzuki and Abe's algorithm (and OpenCV's 8-bit scanner) leave
// them in the working copy: a traced pixel whose right neighbour was found to be background
// (the region's right edge there), and any other traced pixel.
constexpr int8_t kRightEdgeMark = static_cast<int8_t>(2 | 0x80);
constexpr int8_t kTracedMark = 2;
// The chain code's steps: 0 = right, then anticlockwise on screen (y down), 45 deg each.
constexpr int kStepX[8] = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr int kStepY[8] = {0, -1, -1, -1, 0, 1, 1, 1};

// Bytes past a row's last pixel that the word-at-a-time scan may read.
constexpr int kScanSlack = 8;

// The first x in [x, end) of `row` whose byte differs from `value`; `end` when none does.
// Reads whole 8-byte words, which the working copy's slack allows.
int SkipEqual(const int8_t* row, int x, int end, int8_t value) {
  const uint64_t broadcast = 0x0101010101010101ULL * static_cast<uint8_t>(value);
  while (x < end) {
    uint64_t word;
    std::memcpy(&word, row + x, sizeof(word));
    const uint64_t differs = word ^ broadcast;
    if (differs != 0) return std::min(end, x + (__builtin_ctzll(differs) >> 3));
    x += 8;
  }
  return end;
}

// Follows the outer border starting at `start` (the first foreground pixel of its region in
// raster order, background to its left), marking it, and appends its points (the first at
// `point`) to `outline`. `delta[s]` is the offset in the working copy of a step in direction s;
// directions repeat once (16 entries) so that a search may run past 7.
void FollowOuterBorder(int8_t* start, const int* delta, cv::Point point,
                       std::vector<cv::Point>* outline) {
  // The first foreground neighbour clockwise from the left (directions 3, 2, ..., 5; the left
  // neighbour, direction 4, is background).
  int s = 4;
  int8_t* first = nullptr;
  do {
    s = (s - 1) & 7;
    first = start + delta[s];
  } while (*first == 0 && s != 4);
  if (s == 4) {  // a pixel alone
    *start = kRightEdgeMark;
    outline->push_back(point);
    return;
  }
  int8_t* here = start;
  for (;;) {
    // Anticlockwise from the direction of the pixel we came from, the next foreground one.
    const int came_from = s;
    int8_t* next = here;
    for (int k = s + 1; k <= s + 8; ++k) {
      next = here + delta[k];
      if (*next != 0) {
        s = k;
        break;
      }
    }
    s &= 7;
    // Passing direction 0 (the right neighbour) unvisited means it is background.
    if (static_cast<unsigned>(s - 1) < static_cast<unsigned>(came_from)) {
      *here = kRightEdgeMark;
    } else if (*here == 1) {
      *here = kTracedMark;
    }
    outline->push_back(point);
    point.x += kStepX[s];
    point.y += kStepY[s];
    if (next == start && here == first) break;
    here = next;
    s = (s + 4) & 7;
  }
}

}  // namespace

void FindOuterContours(const cv::Mat& mask, std::vector<std::vector<cv::Point>>* outlines,
                       cv::Point offset) {
  if (mask.type() != CV_8UC1) {
    throw std::invalid_argument("FindOuterContours: the mask has OpenCV type " +
                                std::to_string(mask.type()) + "; expected CV_8UC1");
  }
  outlines->clear();
  const int width = mask.cols, height = mask.rows;
  if (width == 0 || height == 0) return;
  // The working copy: 0 / 1, a background frame of one pixel, slack after each row.
  const int stride = width + 2 + kScanSlack;
  thread_local std::vector<int8_t> copy;
  copy.assign(static_cast<size_t>(stride) * (height + 2), 0);
  for (int y = 0; y < height; ++y) {
    const uint8_t* in = mask.ptr<uint8_t>(y);
    int8_t* out = copy.data() + static_cast<size_t>(stride) * (y + 1) + 1;
    for (int x = 0; x < width; ++x) out[x] = in[x] != 0 ? 1 : 0;
  }
  int delta[16];
  for (int s = 0; s < 16; ++s) delta[s] = kStepX[s & 7] + stride * kStepY[s & 7];

  // Raster scan (the frame's columns and rows excluded). `last_border`: the column of the
  // last border met on this row, whose mark says whether the scan is inside a traced region
  // (positive: its left side was met, not yet its right).
  const int end = width + 1;
  for (int y = 1; y <= height; ++y) {
    int8_t* row = copy.data() + static_cast<size_t>(stride) * y;
    int last_border = 0;
    int8_t prev = 0;
    for (int x = SkipEqual(row, 1, end, prev); x < end; x = SkipEqual(row, x, end, prev)) {
      const int8_t p = row[x];
      if (prev == 0 && p == 1) {
        if (row[last_border] <= 0) {  // an outer border not inside another region
          outlines->emplace_back();
          FollowOuterBorder(row + x, delta, cv::Point(x - 1, y - 1) + offset, &outlines->back());
          last_border = x;
          prev = row[x];
          ++x;
          continue;
        }
      } else if (p == 0 && prev >= 1 && (prev & -2) != 0) {
        last_border = x - 1;  // the right side of a hole's border: not traced here
      }
      prev = p;
      if ((p & -2) != 0) last_border = x;
      ++x;
    }
  }
  // OpenCV links each new outline in front of the ones before it.
  std::reverse(outlines->begin(), outlines->end());
}

}  // namespace slamo::vision
