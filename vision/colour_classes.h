// The colours vision looks for: a class per colour name, with the hue window and the
// saturation / value gates of the HSV threshold and the Lab a*b* reference of K-Means. Built
// from a season's palette (the colours its objects or landmarks come in) or from a small
// colours file, for ordinary photos.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "field_configs/season_config.h"

namespace slamo::vision {

struct ColourClass {
  std::string name;
  cv::Vec3b reference_bgr;
  double hue_deg = 0.0;             // of the reference colour, 0..360
  double hue_tolerance_deg = 14.0;  // accepted hue window: hue_deg +- this (wraps at 0/360)
  int min_saturation = 90;          // 0..255: below it is grey, white highlight or reflection
  int min_value = 40;               // 0..255: below it is shadow or black
  cv::Vec2f lab_ab;                 // reference a*, b* (OpenCV 8-bit Lab, 128-centred)
};

// A class from a reference colour; greys (saturation below 60) cannot be told by hue and
// are rejected with std::invalid_argument.
ColourClass MakeColourClass(const std::string& name, const field::Rgb& rgb);

// The classes of the colours the season's objects come in (objects = true) or its landmarks
// use (objects = false), in name order.
std::vector<ColourClass> ObjectColourClasses(const field::SeasonConfig& season);
std::vector<ColourClass> LandmarkColourClasses(const field::SeasonConfig& season);

// A colours file:
//   colours:
//     red: {rgb: "#c81e28", hue_tolerance_deg: 14, min_saturation: 90, min_value: 40}
// (all but rgb optional). Throws field::ConfigError naming the file, line and key.
std::vector<ColourClass> LoadColourClasses(const std::string& path);

// Binary mask (CV_8UC1, 255 = in class) of an HSV image (OpenCV 8-bit: hue 0..180).
cv::Mat ThresholdHsv(const cv::Mat& hsv, const ColourClass& colour);

// Whether one 8-bit BGR pixel is in `colour`: the test ThresholdBgr makes of each pixel.
bool InColourClass(const cv::Vec3b& bgr, const ColourClass& colour);

// ThresholdHsv of each class, the same masks, in one pass over the image.
std::vector<cv::Mat> ThresholdHsv(const cv::Mat& hsv, const std::vector<ColourClass>& colours);

// The masks ThresholdHsv gives on cv::cvtColor(bgr, COLOR_BGR2HSV), bit for bit, straight
// from an 8-bit BGR image: OpenCV's integer HSV of each pixel and the windows in one pass.
std::vector<cv::Mat> ThresholdBgr(const cv::Mat& bgr, const std::vector<ColourClass>& colours);

}  // namespace slamo::vision
