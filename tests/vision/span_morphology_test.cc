// ErodeLike and DilateLike give what cv::erode and cv::dilate give, byte for byte.
#include "vision/span_morphology.h"

#include <gtest/gtest.h>

#include <random>
#include <string>

#include <opencv2/imgproc.hpp>

namespace slamo::vision {
namespace {

void ExpectSameAsOpenCv(const cv::Mat& src, const cv::Mat& kernel, const std::string& what) {
  cv::Mat eroded, dilated, expected_eroded, expected_dilated;
  cv::erode(src, expected_eroded, kernel);
  cv::dilate(src, expected_dilated, kernel);
  ErodeLike(src, kernel, &eroded);
  DilateLike(src, kernel, &dilated);
  ASSERT_EQ(eroded.size(), expected_eroded.size()) << what;
  ASSERT_EQ(cv::norm(eroded, expected_eroded, cv::NORM_INF), 0.0) << "erode, " << what;
  ASSERT_EQ(cv::norm(dilated, expected_dilated, cv::NORM_INF), 0.0) << "dilate, " << what;
  // In place, as the detector calls them.
  cv::Mat in_place = src.clone(), expected_in_place;
  cv::erode(in_place, expected_in_place, kernel);
  ErodeLike(in_place, kernel, &in_place);
  ASSERT_EQ(cv::norm(in_place, expected_in_place, cv::NORM_INF), 0.0) << "in place, " << what;
  in_place = src.clone();
  cv::dilate(in_place, expected_in_place, kernel);
  DilateLike(in_place, kernel, &in_place);
  ASSERT_EQ(cv::norm(in_place, expected_in_place, cv::NORM_INF), 0.0)
      << "dilate in place, " << what;
}

// Masks (blobs, speckle, thin lines, touching the image border) and grey images, under every
// kernel shape the detector uses (ellipses, squares, crosses, OpenCV's default) and others
// that go to OpenCV (even sizes, off-centre runs), including views into larger images.
TEST(SpanMorphologyTest, SameAsOpenCv) {
  std::mt19937 rng(41);
  for (int trial = 0; trial < 1500; ++trial) {
    const int w = 1 + static_cast<int>(rng() % 90), h = 1 + static_cast<int>(rng() % 90);
    cv::Mat image = cv::Mat::zeros(h, w, CV_8UC1);
    if (trial % 4 == 0) {
      cv::randu(image, 0, 256);
    } else {
      for (int s = 0; s < 1 + static_cast<int>(rng() % 4); ++s) {
        cv::ellipse(image, cv::Point(static_cast<int>(rng() % w), static_cast<int>(rng() % h)),
                    cv::Size(1 + static_cast<int>(rng() % 30), 1 + static_cast<int>(rng() % 30)),
                    static_cast<double>(rng() % 180), 0, 360, cv::Scalar(255), cv::FILLED);
      }
      cv::Mat noise(h, w, CV_8UC1);
      cv::randu(noise, 0, 256);
      image.setTo(255, noise > 245);
      image.setTo(0, noise < 10);
    }
    if (trial % 6 == 0) {
      cv::Mat big(h + 4, w + 4, CV_8UC1, cv::Scalar(77));
      image.copyTo(big(cv::Rect(2, 2, w, h)));
      image = big(cv::Rect(2, 2, w, h));
    }
    const int shapes[] = {cv::MORPH_ELLIPSE, cv::MORPH_RECT, cv::MORPH_CROSS};
    const int shape = shapes[trial % 3];
    // Odd widths (the span path) but one kernel in ten: even ones go to OpenCV.
    const int width =
        trial % 10 == 3 ? 2 + 2 * static_cast<int>(rng() % 5) : 1 + 2 * static_cast<int>(rng() % 6);
    const cv::Size size(width, 1 + static_cast<int>(rng() % 11));
    const cv::Mat kernel = trial % 10 == 9 ? cv::Mat() : cv::getStructuringElement(shape, size);
    ExpectSameAsOpenCv(image, kernel, "trial " + std::to_string(trial));
  }
  cv::Mat off_centre = cv::Mat::zeros(3, 5, CV_8UC1);
  off_centre(cv::Rect(0, 1, 3, 1)) = 1;
  cv::Mat mask = cv::Mat::zeros(20, 20, CV_8UC1);
  cv::circle(mask, cv::Point(9, 9), 6, cv::Scalar(255), cv::FILLED);
  ExpectSameAsOpenCv(mask, off_centre, "a run off the centre");
  ExpectSameAsOpenCv(mask, cv::Mat::zeros(3, 3, CV_8UC1), "an empty kernel");
}

}  // namespace
}  // namespace slamo::vision
