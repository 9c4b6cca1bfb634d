// FindOuterContours gives what cv::findContours(RETR_EXTERNAL, CHAIN_APPROX_NONE) gives: the
// same outlines, in the same order, each from the same start through the same points.
#include "vision/contour_trace.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace slamo::vision {
namespace {

using Outlines = std::vector<std::vector<cv::Point>>;

Outlines OpenCvOutlines(const cv::Mat& mask, cv::Point offset) {
  Outlines outlines;
  cv::findContours(mask, outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, offset);
  return outlines;
}

// Random masks of every kind the detector meets: blobs of ellipses (touching, with holes and
// regions inside the holes), speckle, thin lines, single pixels, regions touching the image
// border; any non-zero value counts; inputs that are views into a larger image.
cv::Mat RandomMask(std::mt19937& rng, int trial) {
  const int w = 1 + static_cast<int>(rng() % 150), h = 1 + static_cast<int>(rng() % 150);
  cv::Mat mask = cv::Mat::zeros(h, w, CV_8UC1);
  const int shapes = static_cast<int>(rng() % 8);
  for (int s = 0; s < shapes; ++s) {
    const cv::Point c(static_cast<int>(rng() % w), static_cast<int>(rng() % h));
    const cv::Size axes(1 + static_cast<int>(rng() % 40), 1 + static_cast<int>(rng() % 30));
    const int value = 1 + static_cast<int>(rng() % 255);
    if (rng() % 4 == 0) {
      cv::ellipse(mask, c, axes, static_cast<double>(rng() % 180), 0, 360, cv::Scalar(value),
                  1 + static_cast<int>(rng() % 4));  // rings: holes, regions inside them
    } else if (rng() % 5 == 0) {
      cv::line(mask, c, c + cv::Point(axes.width, axes.height), cv::Scalar(value), 1);
    } else {
      cv::ellipse(mask, c, axes, static_cast<double>(rng() % 180), 0, 360, cv::Scalar(value),
                  cv::FILLED);
    }
  }
  const int noise_kind = trial % 4;
  if (noise_kind > 0) {
    cv::Mat noise(h, w, CV_8UC1);
    cv::randu(noise, 0, 256);
    if (noise_kind == 1) mask.setTo(0, noise < 40);   // holes and ragged edges
    if (noise_kind == 2) mask.setTo(7, noise > 240);  // speckle, single pixels
    if (noise_kind == 3) mask = noise > 128;          // salt and pepper everywhere
  }
  if (trial % 7 == 0) {  // a view into a larger image: rows not continuous
    cv::Mat big = cv::Mat::zeros(h + 6, w + 9, CV_8UC1);
    cv::randu(big, 0, 256);
    mask.copyTo(big(cv::Rect(4, 3, w, h)));
    return big(cv::Rect(4, 3, w, h));
  }
  return mask;
}

TEST(ContourTraceTest, SameAsFindContours) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 4000; ++trial) {
    const cv::Mat mask = RandomMask(rng, trial);
    const cv::Mat before = mask.clone();
    const cv::Point offset(static_cast<int>(rng() % 7) - 3, static_cast<int>(rng() % 7) - 3);
    Outlines traced = {{cv::Point(99, 99)}};  // replaced, not appended to
    FindOuterContours(mask, &traced, offset);
    ASSERT_EQ(traced, OpenCvOutlines(mask, offset)) << "trial " << trial;
    ASSERT_EQ(cv::norm(before, mask, cv::NORM_INF), 0.0) << "the input is left as it was";
  }
}

TEST(ContourTraceTest, EdgeCases) {
  Outlines traced = {{cv::Point(1, 1)}};  // replaced, not appended to
  // Empty, all background, all foreground, one pixel, one row, one column.
  FindOuterContours(cv::Mat(), &traced);
  EXPECT_TRUE(traced.empty());
  for (const cv::Mat& mask :
       {cv::Mat(cv::Mat::zeros(5, 7, CV_8UC1)), cv::Mat(cv::Mat::ones(5, 7, CV_8UC1) * 255),
        cv::Mat(cv::Mat::ones(1, 1, CV_8UC1)), cv::Mat(cv::Mat::ones(1, 9, CV_8UC1)),
        cv::Mat(cv::Mat::ones(9, 1, CV_8UC1))}) {
    FindOuterContours(mask, &traced);
    EXPECT_EQ(traced, OpenCvOutlines(mask, cv::Point()));
  }
  FindOuterContours(cv::Mat::ones(3, 3, CV_8UC1), &traced);
  ASSERT_EQ(traced.size(), 1u);
  EXPECT_EQ(traced[0].size(), 8u);  // the border of a 3x3 square
}

TEST(ContourTraceTest, RejectsOtherImageTypes) {
  Outlines traced;
  EXPECT_THROW(FindOuterContours(cv::Mat::zeros(4, 4, CV_8UC3), &traced), std::invalid_argument);
  EXPECT_THROW(FindOuterContours(cv::Mat::zeros(4, 4, CV_32SC1), &traced), std::invalid_argument);
}

}  // namespace
}  // namespace slamo::vision
