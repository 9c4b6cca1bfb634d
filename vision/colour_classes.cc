#include "vision/colour_classes.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/core/utility.hpp>
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

// cv::cvtColor's 8-bit BGR -> HSV (hue 0..180), integer for integer: with v the largest
// channel and diff = v - smallest, s = (diff * round(255 * 2^12 / v) + 2^11) >> 12 and
// h = (d * round(30 * 2^12 / diff) + 2^11) >> 12, plus 180 when negative, where d is g - b,
// b - r + 2 diff or r - g + 4 diff as red, green or blue is the largest (in that order).
constexpr int kHsvShift = 12;
constexpr int kSatScale = 255 << kHsvShift;  // s's divisor numerator, over v
constexpr int kHueScale = 30 << kHsvShift;   // h's, over diff: 180 / 6 hue steps per sixth

struct HsvDivisors {
  int saturation[256], hue[256];  // round(scale / i), 0 for i = 0, as OpenCV tabulates them
  HsvDivisors() {
    saturation[0] = hue[0] = 0;
    for (int i = 1; i < 256; ++i) {
      saturation[i] = cvRound(static_cast<double>(kSatScale) / i);
      hue[i] = cvRound(static_cast<double>(kHueScale) / i);
    }
  }
};

cv::Vec3b BgrToHsv(const HsvDivisors& div, int b, int g, int r) {
  const int v = std::max({b, g, r});
  const int diff = v - std::min({b, g, r});
  const int s = (diff * div.saturation[v] + (1 << (kHsvShift - 1))) >> kHsvShift;
  const int d = v == r ? g - b : v == g ? b - r + 2 * diff : r - g + 4 * diff;
  int h = (d * div.hue[diff] + (1 << (kHsvShift - 1))) >> kHsvShift;
  if (h < 0) h += 180;
  return cv::Vec3b(static_cast<uint8_t>(h), static_cast<uint8_t>(s), static_cast<uint8_t>(v));
}

#if defined(__x86_64__) && defined(__GNUC__)
#define SLAMO_THRESHOLD_BGR_AVX2 1

// Where each byte of 16 BGR pixels lies in their 48 bytes: index[c][k] gathers channel c's
// bytes that are in the k-th 16 (-1 elsewhere, for _mm_shuffle_epi8).
struct Deinterleave {
  alignas(16) int8_t index[3][3][16];
};

const Deinterleave& DeinterleaveIndex() {
  static const Deinterleave table = [] {
    Deinterleave d;
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < 16; ++i) {
          const int byte = 3 * i + c;
          d.index[c][k][i] = static_cast<int8_t>(byte / 16 == k ? byte % 16 : -1);
        }
      }
    }
    return d;
  }();
  return table;
}

// 255 in each lane whose byte is in the window.
__attribute__((target("avx2"))) __m128i InAvx2(const ByteWindow& w, __m128i x) {
  if (w.empty) return _mm_setzero_si128();
  const __m128i t = _mm_sub_epi8(x, _mm_set1_epi8(static_cast<char>(w.lo)));
  return _mm_cmpeq_epi8(_mm_min_epu8(t, _mm_set1_epi8(static_cast<char>(w.span))), t);
}

// round(scale / x) in 32-bit lanes, 0 where x = 0: the float quotient is within 2^-24 of
// scale / x (< 2^20), nearer than any half-integer is to it (at least 1 / (2 x) away), so it
// rounds to OpenCV's tabulated divisor.
__attribute__((target("avx2"))) __m256i DivisorAvx2(__m256 scale, __m256i x) {
  const __m256i q = _mm256_cvtps_epi32(_mm256_div_ps(scale, _mm256_cvtepi32_ps(x)));
  return _mm256_andnot_si256(_mm256_cmpeq_epi32(x, _mm256_setzero_si256()), q);
}

// (a * b + 2^11) >> 12 of 16 lanes (two halves of eight), packed to unsigned bytes.
__attribute__((target("avx2"))) __m128i ScaleDownAvx2(const __m256i (&a)[2], const __m256i (&b)[2],
                                                      bool wrap_hue) {
  const __m256i half = _mm256_set1_epi32(1 << (kHsvShift - 1));
  __m256i q[2];
  for (int i = 0; i < 2; ++i) {
    q[i] = _mm256_srai_epi32(_mm256_add_epi32(_mm256_mullo_epi32(a[i], b[i]), half), kHsvShift);
    if (wrap_hue) {
      const __m256i negative = _mm256_cmpgt_epi32(_mm256_setzero_si256(), q[i]);
      q[i] = _mm256_add_epi32(q[i], _mm256_and_si256(negative, _mm256_set1_epi32(180)));
    }
  }
  // packs works within 128-bit lanes: put the four quarters back in order.
  const __m256i packed = _mm256_permute4x64_epi64(_mm256_packs_epi32(q[0], q[1]), 0xD8);
  return _mm_packus_epi16(_mm256_castsi256_si128(packed), _mm256_extracti128_si256(packed, 1));
}

// The masks of a row's pixels, 16 at a time, for AVX2 processors: BgrToHsv's integers in
// 32-bit lanes, the float divisions standing for its tables. Returns the pixels done.
__attribute__((target("avx2"))) int ThresholdRowAvx2(const uint8_t* bgr, int n,
                                                     const std::vector<HsvWindows>& windows,
                                                     const std::vector<uint8_t*>& masks) {
  const Deinterleave& d = DeinterleaveIndex();
  const __m256 sat_scale = _mm256_set1_ps(static_cast<float>(kSatScale));
  const __m256 hue_scale = _mm256_set1_ps(static_cast<float>(kHueScale));
  int u = 0;
  for (; u + 16 <= n; u += 16) {
    const uint8_t* p = bgr + 3 * u;
    __m128i in[3], channel[3];
    for (int k = 0; k < 3; ++k) in[k] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p) + k);
    for (int c = 0; c < 3; ++c) {
      channel[c] = _mm_setzero_si128();
      for (int k = 0; k < 3; ++k) {
        const __m128i index = _mm_load_si128(reinterpret_cast<const __m128i*>(d.index[c][k]));
        channel[c] = _mm_or_si128(channel[c], _mm_shuffle_epi8(in[k], index));
      }
    }
    const __m128i b = channel[0], g = channel[1], r = channel[2];
    const __m128i v = _mm_max_epu8(b, _mm_max_epu8(g, r));
    const __m128i diff = _mm_sub_epi8(v, _mm_min_epu8(b, _mm_min_epu8(g, r)));
    // The hue's numerator by which channel is largest, in 16 bits (-255..1275).
    const __m256i b16 = _mm256_cvtepu8_epi16(b), g16 = _mm256_cvtepu8_epi16(g);
    const __m256i r16 = _mm256_cvtepu8_epi16(r), diff16 = _mm256_cvtepu8_epi16(diff);
    const __m256i red_max = _mm256_cvtepi8_epi16(_mm_cmpeq_epi8(v, r));
    const __m256i green_max = _mm256_cvtepi8_epi16(_mm_cmpeq_epi8(v, g));
    const __m256i blue_num =
        _mm256_add_epi16(_mm256_sub_epi16(r16, g16), _mm256_slli_epi16(diff16, 2));
    const __m256i green_num =
        _mm256_add_epi16(_mm256_sub_epi16(b16, r16), _mm256_slli_epi16(diff16, 1));
    const __m256i num = _mm256_blendv_epi8(_mm256_blendv_epi8(blue_num, green_num, green_max),
                                           _mm256_sub_epi16(g16, b16), red_max);
    // 32-bit halves: value, diff, numerator.
    const __m256i v32[2] = {_mm256_cvtepu8_epi32(v), _mm256_cvtepu8_epi32(_mm_srli_si128(v, 8))};
    const __m256i diff32[2] = {_mm256_cvtepu8_epi32(diff),
                               _mm256_cvtepu8_epi32(_mm_srli_si128(diff, 8))};
    const __m256i num32[2] = {_mm256_cvtepi16_epi32(_mm256_castsi256_si128(num)),
                              _mm256_cvtepi16_epi32(_mm256_extracti128_si256(num, 1))};
    const __m256i sat_div[2] = {DivisorAvx2(sat_scale, v32[0]), DivisorAvx2(sat_scale, v32[1])};
    const __m256i hue_div[2] = {DivisorAvx2(hue_scale, diff32[0]),
                                DivisorAvx2(hue_scale, diff32[1])};
    const __m128i s = ScaleDownAvx2(diff32, sat_div, false);
    const __m128i h = ScaleDownAvx2(num32, hue_div, true);
    for (size_t j = 0; j < windows.size(); ++j) {
      const HsvWindows& w = windows[j];
      const __m128i in_class =
          _mm_and_si128(_mm_or_si128(InAvx2(w.hue[0], h), InAvx2(w.hue[1], h)),
                        _mm_and_si128(InAvx2(w.saturation, s), InAvx2(w.value, v)));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(masks[j] + u), in_class);
    }
  }
  return u;
}

// ThresholdBgr of an 8-bit BGR image on a processor with AVX2: the rows 16 pixels at a time,
// the pixels left at a row's end one by one.
std::vector<cv::Mat> ThresholdBgrAvx2(const cv::Mat& bgr, const std::vector<ColourClass>& colours) {
  static const HsvDivisors divisors;
  std::vector<HsvWindows> windows;
  for (const ColourClass& c : colours) windows.push_back(WindowsOf(c));
  std::vector<cv::Mat> masks;
  for (size_t j = 0; j < colours.size(); ++j) masks.emplace_back(bgr.size(), CV_8UC1);
  std::vector<uint8_t*> rows(colours.size());
  for (int row = 0; row < bgr.rows; ++row) {
    const uint8_t* p = bgr.ptr<uint8_t>(row);
    for (size_t j = 0; j < masks.size(); ++j) rows[j] = masks[j].ptr<uint8_t>(row);
    int u = ThresholdRowAvx2(p, bgr.cols, windows, rows);
    for (; u < bgr.cols; ++u) {
      const uint8_t* q = p + 3 * u;
      const cv::Vec3b hsv = BgrToHsv(divisors, q[0], q[1], q[2]);
      for (size_t j = 0; j < windows.size(); ++j) {
        const HsvWindows& w = windows[j];
        const bool in = (In(w.hue[0], hsv[0]) || In(w.hue[1], hsv[0])) &&
                        In(w.saturation, hsv[1]) && In(w.value, hsv[2]);
        rows[j][u] = in ? 255 : 0;
      }
    }
  }
  return masks;
}

#endif

}  // namespace

std::vector<cv::Mat> ThresholdBgr(const cv::Mat& bgr, const std::vector<ColourClass>& colours) {
#ifdef SLAMO_THRESHOLD_BGR_AVX2
  if (bgr.type() == CV_8UC3 && cv::checkHardwareSupport(CV_CPU_AVX2)) {
    return ThresholdBgrAvx2(bgr, colours);
  }
#endif
  // Without AVX2, OpenCV's own conversion is the faster way to the same masks.
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  return ThresholdHsv(hsv, colours);
}

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

bool InColourClass(const cv::Vec3b& bgr, const ColourClass& colour) {
  static const HsvDivisors divisors;
  const cv::Vec3b hsv = BgrToHsv(divisors, bgr[0], bgr[1], bgr[2]);
  const HsvWindows w = WindowsOf(colour);
  return (In(w.hue[0], hsv[0]) || In(w.hue[1], hsv[0])) && In(w.saturation, hsv[1]) &&
         In(w.value, hsv[2]);
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
