// RGB-D frames as plain timestamped data, and the camera interface every source implements:
// the simulator's renderer, recordings, and a real OpenNI2 camera later.
#pragma once

#include <cstdint>
#include <optional>

#include <opencv2/core.hpp>

namespace slamo::platform {

struct RgbdFrame {
  double t_s = 0.0;
  int64_t index = 0;
  cv::Mat colour;    // CV_8UC3, BGR, registered to the depth image
  cv::Mat depth_mm;  // CV_16UC1, depth along the optical axis in millimetres; 0 = no reading
};

class RgbdCamera {
 public:
  virtual ~RgbdCamera() = default;
  // The next frame, or nothing when none arrived (a dropped frame is not an error).
  virtual std::optional<RgbdFrame> Grab() = 0;
};

}  // namespace slamo::platform
