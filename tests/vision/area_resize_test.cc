// ResizeAreaLike gives what cv::resize(INTER_AREA) gives, byte for byte, and ShrinkMaskLike
// what cv::resize(INTER_AREA) and cv::threshold at 127 give.
#include "vision/area_resize.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace slamo::vision {
namespace {

void ExpectSameAsOpenCv(const cv::Mat& src, double scale, const std::string& what) {
  cv::Mat expected, shrunk;
  try {
    cv::resize(src, expected, cv::Size(), scale, scale, cv::INTER_AREA);
  } catch (const cv::Exception&) {  // nothing left at this scale: the same error
    EXPECT_THROW(ResizeAreaLike(src, scale, &shrunk), cv::Exception) << what;
    return;
  }
  ResizeAreaLike(src, scale, &shrunk);
  ASSERT_EQ(shrunk.size(), expected.size()) << what;
  ASSERT_EQ(shrunk.type(), expected.type()) << what;
  ASSERT_EQ(cv::norm(shrunk, expected, cv::NORM_INF), 0.0) << what;
}

void ExpectShrinkSameAsOpenCv(const cv::Mat& src, double scale, const std::string& what) {
  cv::Mat expected, shrunk;
  try {
    cv::resize(src, expected, cv::Size(), scale, scale, cv::INTER_AREA);
  } catch (const cv::Exception&) {
    EXPECT_THROW(ShrinkMaskLike(src, scale, &shrunk), cv::Exception) << what;
    return;
  }
  cv::threshold(expected, expected, 127, 255, cv::THRESH_BINARY);
  ShrinkMaskLike(src, scale, &shrunk);
  ASSERT_EQ(shrunk.size(), expected.size()) << what;
  ASSERT_EQ(shrunk.type(), expected.type()) << what;
  ASSERT_EQ(cv::norm(shrunk, expected, cv::NORM_INF), 0.0) << what;
}

// A random test image and a scale below one to shrink it by: a mask as the detector shrinks
// them (filled blobs in a window, background around, scaled to 6000 pixels), a grey image of
// any values, or (with `stripes`) stripes of every width and phase, whose cells are half
// covered; every fifth a view into a larger image whose frame holds `frame`.
std::pair<cv::Mat, double> RandomImage(std::mt19937& rng, int trial, bool stripes, uint8_t frame) {
  const int w = 2 + static_cast<int>(rng() % 260), h = 2 + static_cast<int>(rng() % 260);
  cv::Mat image = cv::Mat::zeros(h, w, CV_8UC1);
  const int kinds = stripes ? 4 : 3;
  if (trial % kinds == 0) {
    cv::randu(image, 0, 256);
  } else if (stripes && trial % kinds == 1) {
    const int period = 2 + static_cast<int>(rng() % 9), on = 1 + static_cast<int>(rng() % period);
    const bool rows = rng() % 2 == 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if ((rows ? y : x) % period < on) image.at<uint8_t>(y, x) = 255;
      }
    }
  } else {
    for (int s = 0; s < 1 + static_cast<int>(rng() % 5); ++s) {
      cv::ellipse(image, cv::Point(static_cast<int>(rng() % w), static_cast<int>(rng() % h)),
                  cv::Size(1 + static_cast<int>(rng() % 80), 1 + static_cast<int>(rng() % 80)),
                  static_cast<double>(rng() % 180), 0, 360, cv::Scalar(255), cv::FILLED);
    }
  }
  if (trial % 5 == 0) {
    cv::Mat big(h + 3, w + 5, CV_8UC1, cv::Scalar(frame));
    image.copyTo(big(cv::Rect(2, 1, w, h)));
    image = big(cv::Rect(2, 1, w, h));
  }
  const double detector_scale = std::sqrt(6000.0 / static_cast<double>(w * h));
  const double scale = trial % 2 == 0 && detector_scale < 1.0
                           ? detector_scale
                           : std::uniform_real_distribution<double>(0.05, 1.0)(rng);
  return {image, scale};
}

TEST(AreaResizeTest, SameAsOpenCv) {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 3000; ++trial) {
    const auto [image, scale] = RandomImage(rng, trial, /*stripes=*/false, /*frame=*/9);
    ExpectSameAsOpenCv(image, scale, "trial " + std::to_string(trial));
  }
}

// The shrink and threshold on the same kinds of images, stripes too: there the sums decide
// cells at the threshold by a last bit.
TEST(AreaResizeTest, ShrinkMaskSameAsOpenCv) {
  std::mt19937 rng(37);
  int mixed = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const auto [image, scale] = RandomImage(rng, trial, /*stripes=*/true, /*frame=*/255);
    ExpectShrinkSameAsOpenCv(image, scale, "trial " + std::to_string(trial));
    cv::Mat resized;
    if (cv::saturate_cast<int>(image.cols * scale) > 0 &&
        cv::saturate_cast<int>(image.rows * scale) > 0) {
      cv::resize(image, resized, cv::Size(), scale, scale, cv::INTER_AREA);
      mixed += cv::countNonZero((resized > 100) & (resized < 155));
    }
  }
  EXPECT_GT(mixed, 1000);  // the cases near the threshold were there to be decided
  cv::Mat mask = cv::Mat::zeros(60, 80, CV_8UC1);
  cv::circle(mask, cv::Point(40, 30), 20, cv::Scalar(255), cv::FILLED);
  ExpectShrinkSameAsOpenCv(mask, 0.5, "a whole step of 2");
  ExpectShrinkSameAsOpenCv(mask, 1.0, "the same size");
  ExpectShrinkSameAsOpenCv(mask, 1.7, "growing");
  ExpectShrinkSameAsOpenCv(cv::Mat::zeros(40, 40, CV_8UC1), 0.37, "all background");
  ExpectShrinkSameAsOpenCv(cv::Mat(40, 40, CV_8UC1, cv::Scalar(255)), 0.37, "all foreground");
  ExpectShrinkSameAsOpenCv(mask, 0.001, "nothing left");
}

// Whole steps, growing, the same size and other types go to OpenCV itself: still the same.
TEST(AreaResizeTest, HandsTheRestToOpenCv) {
  cv::Mat mask = cv::Mat::zeros(60, 80, CV_8UC1);
  cv::circle(mask, cv::Point(40, 30), 20, cv::Scalar(255), cv::FILLED);
  ExpectSameAsOpenCv(mask, 0.5, "a whole step of 2");
  ExpectSameAsOpenCv(mask, 0.25, "a whole step of 4");
  ExpectSameAsOpenCv(mask, 1.0, "the same size");
  ExpectSameAsOpenCv(mask, 1.7, "growing");
  cv::Mat colour;
  cv::cvtColor(mask, colour, cv::COLOR_GRAY2BGR);
  ExpectSameAsOpenCv(colour, 0.37, "three channels");
  ExpectSameAsOpenCv(cv::Mat::zeros(40, 40, CV_8UC1), 0.37, "all background");
  ExpectSameAsOpenCv(mask, 0.001, "nothing left");
}

}  // namespace
}  // namespace slamo::vision
