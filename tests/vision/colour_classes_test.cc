#include "vision/colour_classes.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "field_configs/loader.h"

namespace slamo::vision {
namespace {

// Every 8-bit BGR colour once: pixel (u, v) is colour v * 4096 + u, blue in the low byte.
cv::Mat EveryColour() {
  cv::Mat bgr(4096, 4096, CV_8UC3);
  for (int v = 0; v < bgr.rows; ++v) {
    cv::Vec3b* p = bgr.ptr<cv::Vec3b>(v);
    for (int u = 0; u < bgr.cols; ++u) {
      const int colour = v * 4096 + u;
      p[u] = cv::Vec3b(colour & 255, colour >> 8 & 255, colour >> 16);
    }
  }
  return bgr;
}

std::vector<cv::Mat> HsvPath(const cv::Mat& bgr, const std::vector<ColourClass>& colours) {
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  return ThresholdHsv(hsv, colours);
}

void ExpectSameMasks(const std::vector<cv::Mat>& expected, const std::vector<cv::Mat>& actual,
                     const std::vector<ColourClass>& colours) {
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t j = 0; j < expected.size(); ++j) {
    SCOPED_TRACE(colours[j].name);
    ASSERT_EQ(actual[j].type(), CV_8UC1);
    ASSERT_EQ(actual[j].size(), expected[j].size());
    EXPECT_EQ(cv::countNonZero(actual[j] != expected[j]), 0);
  }
}

// The seasons' object and landmark classes, as the detector builds them: the masks from BGR
// are those of the HSV path for each of the 2^24 colours. On a 4096-wide image every pixel
// takes the 16-pixel vector path, on a one-pixel-wide one the one-by-one path that finishes a
// row (on a processor without AVX2, ThresholdBgr is the HSV path itself).
TEST(ColourClassesTest, ThresholdBgrMatchesHsvOnEveryColour) {
  const cv::Mat bgr = EveryColour();
  const cv::Mat column = bgr.reshape(3, bgr.rows * bgr.cols);
  for (const std::string& name : field::ListSeasons()) {
    const field::SeasonConfig season = field::LoadSeasonConfig(name);
    for (const bool objects : {true, false}) {
      SCOPED_TRACE(name + (objects ? " objects" : " landmarks"));
      const std::vector<ColourClass> colours =
          objects ? ObjectColourClasses(season) : LandmarkColourClasses(season);
      if (colours.empty()) continue;
      const std::vector<cv::Mat> expected = HsvPath(bgr, colours);
      ExpectSameMasks(expected, ThresholdBgr(bgr, colours), colours);
      std::vector<cv::Mat> expected_column;
      for (const cv::Mat& m : expected) expected_column.push_back(m.reshape(1, m.rows * m.cols));
      ExpectSameMasks(expected_column, ThresholdBgr(column, colours), colours);
    }
  }
}

// One pixel at a time (InColourClass, which the detector asks of the rows over a piece), the
// same answers as the HSV path's masks: one season's object classes, with and without their
// saturation and value gates halved (the detector's shades), on 2^20 colours spread over the
// cube (every fourth value of each channel).
TEST(ColourClassesTest, OnePixelMatchesTheMasks) {
  cv::Mat bgr(1024, 1024, CV_8UC3);
  for (int v = 0; v < bgr.rows; ++v) {
    for (int u = 0; u < bgr.cols; ++u) {
      const int colour = v * 1024 + u;
      bgr.at<cv::Vec3b>(v, u) =
          cv::Vec3b(4 * (colour & 63), 4 * (colour >> 6 & 63), 4 * (colour >> 12 & 63) + 3);
    }
  }
  std::vector<ColourClass> colours = ObjectColourClasses(field::LoadSeasonConfig("toss_up"));
  for (ColourClass c : std::vector<ColourClass>(colours)) {
    c.min_saturation /= 2;
    c.min_value /= 2;
    colours.push_back(c);
  }
  const std::vector<cv::Mat> masks = HsvPath(bgr, colours);
  for (size_t j = 0; j < colours.size(); ++j) {
    SCOPED_TRACE(colours[j].name + (j >= colours.size() / 2 ? " (shade)" : ""));
    int differ = 0, in = 0;
    for (int v = 0; v < bgr.rows; ++v) {
      for (int u = 0; u < bgr.cols; ++u) {
        const bool one = InColourClass(bgr.at<cv::Vec3b>(v, u), colours[j]);
        differ += one != (masks[j].at<uint8_t>(v, u) != 0);
        in += one;
      }
    }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(in, 1000);  // the classes are not empty on these colours
  }
}

// Windows at the edges: wrapping at 0/360, one hue step wide, no saturation or value floor,
// the full saturation and value only, the widest hue window; and a part of an image.
TEST(ColourClassesTest, ThresholdBgrMatchesHsvAtWindowEdges) {
  std::vector<ColourClass> colours;
  ColourClass odd = MakeColourClass("odd", field::Rgb{250, 10, 120});
  odd.hue_deg = 359.3, odd.hue_tolerance_deg = 0.7, odd.min_saturation = 0, odd.min_value = 255;
  colours.push_back(odd);
  odd.hue_deg = 0.25, odd.hue_tolerance_deg = 1.25, odd.min_saturation = 255, odd.min_value = 0;
  colours.push_back(odd);
  odd.hue_deg = 181.0, odd.hue_tolerance_deg = 89.0, odd.min_saturation = 17, odd.min_value = 3;
  colours.push_back(odd);
  odd.hue_deg = 120.0, odd.hue_tolerance_deg = 1.0, odd.min_saturation = 0, odd.min_value = 0;
  colours.push_back(odd);
  const cv::Mat bgr = EveryColour();
  ExpectSameMasks(HsvPath(bgr, colours), ThresholdBgr(bgr, colours), colours);
  const cv::Mat part = bgr(cv::Rect(3, 5, 1001, 77));  // not continuous, odd width
  ExpectSameMasks(HsvPath(part, colours), ThresholdBgr(part, colours), colours);
}

}  // namespace
}  // namespace slamo::vision
