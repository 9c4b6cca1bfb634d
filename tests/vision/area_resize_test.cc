// ResizeAreaLike gives what cv::resize(INTER_AREA) gives, byte for byte.
#include "vision/area_resize.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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

// Masks as the detector shrinks them (filled blobs in a window, background around, scaled to
// 6000 pixels), and grey images of any values, at any scale below one; views into larger
// images too.
TEST(AreaResizeTest, SameAsOpenCv) {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 3000; ++trial) {
    const int w = 2 + static_cast<int>(rng() % 260), h = 2 + static_cast<int>(rng() % 260);
    cv::Mat image = cv::Mat::zeros(h, w, CV_8UC1);
    if (trial % 3 == 0) {
      cv::randu(image, 0, 256);
    } else {
      for (int s = 0; s < 1 + static_cast<int>(rng() % 5); ++s) {
        cv::ellipse(image, cv::Point(static_cast<int>(rng() % w), static_cast<int>(rng() % h)),
                    cv::Size(1 + static_cast<int>(rng() % 80), 1 + static_cast<int>(rng() % 80)),
                    static_cast<double>(rng() % 180), 0, 360, cv::Scalar(255), cv::FILLED);
      }
    }
    if (trial % 5 == 0) {
      cv::Mat big(h + 3, w + 5, CV_8UC1, cv::Scalar(9));
      image.copyTo(big(cv::Rect(2, 1, w, h)));
      image = big(cv::Rect(2, 1, w, h));
    }
    const double detector_scale = std::sqrt(6000.0 / static_cast<double>(w * h));
    const double scale = trial % 2 == 0 && detector_scale < 1.0
                             ? detector_scale
                             : std::uniform_real_distribution<double>(0.05, 1.0)(rng);
    ExpectSameAsOpenCv(image, scale, "trial " + std::to_string(trial));
  }
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
