#include "vision/colour_classes.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "field_configs/config_error.h"

namespace slamo::vision {
namespace {

cv::Vec3b ConvertOne(const cv::Vec3b& bgr, int code) {
  cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar(bgr[0], bgr[1], bgr[2]));
  cv::Mat out;
  cv::cvtColor(pixel, out, code);
  return out.at<cv::Vec3b>(0, 0);
}

std::vector<ColourClass> ClassesFor(const field::SeasonConfig& season,
                                    const std::set<std::string>& names) {
  std::vector<ColourClass> out;
  for (const std::string& name : names)
    out.push_back(MakeColourClass(name, season.colours.at(name)));
  return out;
}

}  // namespace

ColourClass MakeColourClass(const std::string& name, const field::Rgb& rgb) {
  ColourClass c;
  c.name = name;
  c.reference_bgr = cv::Vec3b(rgb.b, rgb.g, rgb.r);
  // Full-range hue (0..255 for 0..360 deg) for precision.
  const cv::Vec3b hsv = ConvertOne(c.reference_bgr, cv::COLOR_BGR2HSV_FULL);
  if (hsv[1] < 60) {
    throw std::invalid_argument("colour '" + name + "' is too grey to detect by hue (saturation " +
                                std::to_string(hsv[1]) + " of 255)");
  }
  c.hue_deg = hsv[0] * 360.0 / 256.0;
  c.min_saturation = std::min(90, static_cast<int>(hsv[1]) * 2 / 3);
  c.min_value = std::min(40, static_cast<int>(hsv[2]) / 3);
  const cv::Vec3b lab = ConvertOne(c.reference_bgr, cv::COLOR_BGR2Lab);
  c.lab_ab = cv::Vec2f(lab[1], lab[2]);
  return c;
}

std::vector<ColourClass> ObjectColourClasses(const field::SeasonConfig& season) {
  std::set<std::string> names;
  for (const field::ObjectType& type : season.object_types) {
    names.insert(type.colours.begin(), type.colours.end());
  }
  return ClassesFor(season, names);
}

std::vector<ColourClass> LandmarkColourClasses(const field::SeasonConfig& season) {
  std::set<std::string> names;
  for (const field::Landmark& l : season.landmarks) names.insert(l.colour);
  return ClassesFor(season, names);
}

std::vector<ColourClass> LoadColourClasses(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw field::ConfigError(path, 0, 0, "(file)", "a readable colours file");
  std::stringstream text;
  text << in.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw field::ConfigError(path, e.mark.line + 1, e.mark.column + 1, "(document)",
                             "valid YAML (" + e.msg + ")");
  }
  const auto fail = [&](const YAML::Node& node, const std::string& key, const std::string& what) {
    const YAML::Mark m = node.Mark();
    throw field::ConfigError(path, m.line >= 0 ? m.line + 1 : 0, m.line >= 0 ? m.column + 1 : 0,
                             key, what);
  };
  if (!root.IsMap() || !root["colours"] || !root["colours"].IsMap()) {
    fail(root, "colours", "a map 'colours:' of name -> {rgb: \"#rrggbb\", ...}");
  }
  std::vector<ColourClass> out;
  for (const auto& entry : root["colours"]) {
    const std::string name = entry.first.as<std::string>();
    const YAML::Node spec = entry.second;
    const std::string key = "colours." + name;
    if (!spec.IsMap()) fail(spec, key, "a map {rgb: \"#rrggbb\", ...}");
    for (const auto& field : spec) {
      const std::string k = field.first.as<std::string>();
      if (k != "rgb" && k != "hue_tolerance_deg" && k != "min_saturation" && k != "min_value") {
        fail(field.first, key + "." + k,
             "unknown key: expected one of {rgb, hue_tolerance_deg, min_saturation, min_value}");
      }
    }
    const YAML::Node rgb = spec["rgb"];
    const std::string hex = rgb && rgb.IsScalar() ? rgb.Scalar() : "";
    if (hex.size() != 7 || hex[0] != '#' ||
        !std::all_of(hex.begin() + 1, hex.end(), [](char ch) { return std::isxdigit(ch); })) {
      fail(rgb ? rgb : spec, key + ".rgb", "a colour \"#rrggbb\" in quotes");
    }
    const auto channel = [&](int i) {
      return static_cast<std::uint8_t>(std::stoi(hex.substr(1 + 2 * i, 2), nullptr, 16));
    };
    ColourClass c;
    try {
      c = MakeColourClass(name, field::Rgb{channel(0), channel(1), channel(2)});
    } catch (const std::invalid_argument& e) {
      fail(rgb, key + ".rgb", std::string("a saturated colour: ") + e.what());
    }
    const auto number = [&](const char* k, double lo, double hi, double* value) {
      const YAML::Node n = spec[k];
      if (!n) return;
      try {
        *value = n.as<double>();
      } catch (const YAML::Exception&) {
        fail(n, key + "." + k, "a number");
      }
      if (*value < lo || *value > hi) {
        std::ostringstream range;
        range << "a number in [" << lo << ", " << hi << "]";
        fail(n, key + "." + k, range.str());
      }
    };
    double tolerance = c.hue_tolerance_deg, sat = c.min_saturation, val = c.min_value;
    number("hue_tolerance_deg", 1.0, 90.0, &tolerance);
    number("min_saturation", 0.0, 255.0, &sat);
    number("min_value", 0.0, 255.0, &val);
    c.hue_tolerance_deg = tolerance;
    c.min_saturation = static_cast<int>(sat);
    c.min_value = static_cast<int>(val);
    out.push_back(c);
  }
  if (out.empty()) fail(root["colours"], "colours", "at least one colour");
  return out;
}

namespace {

// One channel's window [lo, hi] as cv::inRange takes it for an 8-bit image: each bound rounded
// to the nearest integer (cvRound), an empty or out-of-range window matching nothing, the
// rest saturated to 0..255. A value x is in it when (x - lo) mod 256 <= span.
struct ByteWindow {
  bool empty = true;
  uint8_t lo = 0, span = 0;
};

ByteWindow InRangeWindow(double lo, double hi) {
  const int l = cvRound(lo), h = cvRound(hi);
  if (l > h || l > 255 || h < 0) return {};
  const int first = std::max(l, 0), last = std::min(h, 255);
  return {false, static_cast<uint8_t>(first), static_cast<uint8_t>(last - first)};
}

// A class's windows: hue (a wrapping window as its two halves), saturation and value.
struct HsvWindows {
  ByteWindow hue[2], saturation, value;
};

HsvWindows WindowsOf(const ColourClass& colour) {
  // As ThresholdHsv below: OpenCV 8-bit hue is degrees / 2, the window may wrap around 0.
  HsvWindows w;
  const double lo_deg = colour.hue_deg - colour.hue_tolerance_deg;
  const double hi_deg = colour.hue_deg + colour.hue_tolerance_deg;
  if (lo_deg < 0.0 || hi_deg >= 360.0) {
    const double a = lo_deg < 0.0 ? lo_deg + 360.0 : lo_deg;
    const double b = hi_deg >= 360.0 ? hi_deg - 360.0 : hi_deg;
    w.hue[0] = InRangeWindow(a / 2.0, 180.0);
    w.hue[1] = InRangeWindow(0.0, b / 2.0);
  } else {
    w.hue[0] = InRangeWindow(lo_deg / 2.0, hi_deg / 2.0);
  }
  w.saturation = InRangeWindow(colour.min_saturation, 255.0);
  w.value = InRangeWindow(colour.min_value, 255.0);
  return w;
}

bool In(const ByteWindow& w, uint8_t x) {
  return !w.empty && static_cast<uint8_t>(x - w.lo) <= w.span;
}

#if CV_SIMD128
// 255 in each lane whose byte is in the window.
cv::v_uint8x16 In(const ByteWindow& w, const cv::v_uint8x16& x) {
  if (w.empty) return cv::v_setzero_u8();
  return cv::v_sub_wrap(x, cv::v_setall_u8(w.lo)) <= cv::v_setall_u8(w.span);
}
#endif

}  // namespace

std::vector<cv::Mat> ThresholdHsv(const cv::Mat& hsv, const std::vector<ColourClass>& colours) {
  std::vector<cv::Mat> masks;
  if (hsv.type() != CV_8UC3) {
    for (const ColourClass& c : colours) masks.push_back(ThresholdHsv(hsv, c));
    return masks;
  }
  // The windows of ThresholdHsv's cv::inRange calls; a pixel is in a class when its hue is in
  // either hue window (the OR of the two calls) and its saturation and value in theirs.
  std::vector<HsvWindows> windows;
  for (const ColourClass& c : colours) windows.push_back(WindowsOf(c));
  for (size_t j = 0; j < colours.size(); ++j) masks.emplace_back(hsv.size(), CV_8UC1);
  for (int v = 0; v < hsv.rows; ++v) {
    const uint8_t* p = hsv.ptr<uint8_t>(v);
    for (size_t j = 0; j < windows.size(); ++j) {
      const HsvWindows& w = windows[j];
      uint8_t* m = masks[j].ptr<uint8_t>(v);
      int u = 0;
#if CV_SIMD128
      for (; u + 16 <= hsv.cols; u += 16) {
        cv::v_uint8x16 h, s, x;
        cv::v_load_deinterleave(p + 3 * u, h, s, x);
        cv::v_store(m + u,
                    (In(w.hue[0], h) | In(w.hue[1], h)) & In(w.saturation, s) & In(w.value, x));
      }
#endif
      for (; u < hsv.cols; ++u) {
        const uint8_t* q = p + 3 * u;
        const bool in = (In(w.hue[0], q[0]) || In(w.hue[1], q[0])) && In(w.saturation, q[1]) &&
                        In(w.value, q[2]);
        m[u] = in ? 255 : 0;
      }
    }
  }
  return masks;
}

cv::Mat ThresholdHsv(const cv::Mat& hsv, const ColourClass& colour) {
  // OpenCV 8-bit hue is degrees / 2. The window may wrap around 0 (red).
  const double lo_deg = colour.hue_deg - colour.hue_tolerance_deg;
  const double hi_deg = colour.hue_deg + colour.hue_tolerance_deg;
  const auto to_cv = [](double deg) { return deg / 2.0; };
  const cv::Scalar gate_lo(0, colour.min_saturation, colour.min_value);
  cv::Mat mask;
  if (lo_deg < 0.0 || hi_deg >= 360.0) {
    const double a = lo_deg < 0.0 ? lo_deg + 360.0 : lo_deg;
    const double b = hi_deg >= 360.0 ? hi_deg - 360.0 : hi_deg;
    cv::Mat upper, lower;
    cv::inRange(hsv, cv::Scalar(to_cv(a), gate_lo[1], gate_lo[2]), cv::Scalar(180, 255, 255),
                upper);
    cv::inRange(hsv, cv::Scalar(0, gate_lo[1], gate_lo[2]), cv::Scalar(to_cv(b), 255, 255), lower);
    cv::bitwise_or(upper, lower, mask);
  } else {
    cv::inRange(hsv, cv::Scalar(to_cv(lo_deg), gate_lo[1], gate_lo[2]),
                cv::Scalar(to_cv(hi_deg), 255, 255), mask);
  }
  return mask;
}

}  // namespace slamo::vision
