#include "vision/contour_fill.h"

#include <algorithm>
#include <cstdlib>

#include <opencv2/imgproc.hpp>

namespace slamo::vision {
namespace {

// cv::drawContours fills an outline as the closed polygon through its points: it draws a line
// along each step (for an 8-connected outline: the step's two points) and, on each row, fills
// between the edges that cross it taken in pairs by x (OpenCV's FillEdgeCollection). A step
// between rows y and y + 1 is an edge active on row y only, at the x of its upper point; a
// step along a row is no edge. So: every point, then per row the sorted upper x of the steps
// leaving it downwards or arriving at it from below, filled pairwise. Edges of all the outlines
// are paired together, as OpenCV collects them all before filling.
bool FillUnitStepOutlines(const std::vector<const std::vector<cv::Point>*>& outlines,
                          cv::Point offset, cv::Mat* image) {
  const cv::Rect inside(0, 0, image->cols, image->rows);
  int top = image->rows, bottom = -1;
  for (const std::vector<cv::Point>* outline : outlines) {
    const std::vector<cv::Point>& points = *outline;
    for (size_t i = 0; i < points.size(); ++i) {
      const cv::Point p = points[i] + offset;
      const cv::Point& next = points[i + 1 < points.size() ? i + 1 : 0];
      if (!inside.contains(p) || std::abs(next.x - points[i].x) > 1 ||
          std::abs(next.y - points[i].y) > 1) {
        return false;
      }
      top = std::min(top, p.y);
      bottom = std::max(bottom, p.y);
    }
  }
  if (bottom < top) return true;  // no points
  // Crossings per row, bucketed by a count per row.
  thread_local std::vector<int> start, crossings;
  const int rows = bottom - top + 1;
  start.assign(rows + 1, 0);
  for (const std::vector<cv::Point>* outline : outlines) {
    const std::vector<cv::Point>& points = *outline;
    for (size_t i = 0; i < points.size(); ++i) {
      const cv::Point& p = points[i];
      const cv::Point& next = points[i + 1 < points.size() ? i + 1 : 0];
      if (p.y != next.y) ++start[std::min(p.y, next.y) + offset.y - top + 1];
    }
  }
  for (int r = 0; r < rows; ++r) start[r + 1] += start[r];
  crossings.resize(start[rows]);
  thread_local std::vector<int> fill;
  fill.assign(start.begin(), start.end() - 1);
  for (const std::vector<cv::Point>* outline : outlines) {
    const std::vector<cv::Point>& points = *outline;
    for (size_t i = 0; i < points.size(); ++i) {
      const cv::Point& p = points[i];
      const cv::Point& next = points[i + 1 < points.size() ? i + 1 : 0];
      if (p.y == next.y) continue;
      const cv::Point& upper = p.y < next.y ? p : next;
      crossings[fill[upper.y + offset.y - top]++] = upper.x + offset.x;
    }
  }
  for (int r = 0; r < rows; ++r) {
    int* first = crossings.data() + start[r];
    int* last = crossings.data() + start[r + 1];
    std::sort(first, last);
    uint8_t* row = image->ptr<uint8_t>(top + r);
    for (int* x = first; x + 1 < last; x += 2) std::fill(row + x[0], row + x[1] + 1, 255);
  }
  for (const std::vector<cv::Point>* outline : outlines) {
    for (const cv::Point& p : *outline) image->at<uint8_t>(p + offset) = 255;
  }
  return true;
}

}  // namespace

void FillOutlines(const std::vector<std::vector<cv::Point>>& outlines, cv::Point offset,
                  cv::Mat* image) {
  std::vector<const std::vector<cv::Point>*> all;
  all.reserve(outlines.size());
  for (const std::vector<cv::Point>& outline : outlines) all.push_back(&outline);
  if (image->type() == CV_8UC1 && FillUnitStepOutlines(all, offset, image)) return;
  cv::drawContours(*image, outlines, -1, cv::Scalar(255), cv::FILLED, cv::LINE_8, cv::noArray(),
                   INT_MAX, offset);
}

void FillOutline(const std::vector<cv::Point>& outline, cv::Point offset, cv::Mat* image) {
  if (image->type() == CV_8UC1 && FillUnitStepOutlines({&outline}, offset, image)) return;
  cv::drawContours(*image, std::vector<std::vector<cv::Point>>{outline}, 0, cv::Scalar(255),
                   cv::FILLED, cv::LINE_8, cv::noArray(), 0, offset);
}

}  // namespace slamo::vision
