// A real RGB-D camera through OpenNI2, by way of MRPT's COpenNI2Sensor (Debian
// libmrpt-hwdrivers-dev, built with libopenni2). OpenNI2 drives the PrimeSense family:
// PrimeSense Carmine 1.08 / 1.09, Microsoft Kinect V1 (through the freenect OpenNI2 driver)
// and Asus Xtion / Xtion Pro Live. The Kinect V2 (the thesis robot's camera) is not an OpenNI2
// device: it needs libfreenect2, which slamo does not use.
//
// Thin on purpose: it opens the first device (or the one with a given serial number) at
// 640x480 and converts each MRPT observation to an RgbdFrame (BGR8 colour, depth uint16 mm, t_s
// in Unix seconds from MRPT's host-clock stamp). MRPT's driver turns on OpenNI2's depth-to-colour
// registration when the device supports it (PrimeSense-based devices do). It cannot be tested here
// without a device; everything downstream is tested with recordings (platform/recording.h).
// Built as its own library (slamo_openni2) so that only the program links MRPT's hwdrivers.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "field_configs/robot_config.h"
#include "platform/rgbd.h"

namespace slamo::platform {

// A camera that cannot be opened or read; the message says why and what to check.
class CameraError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Whether a robot config's camera.model is driven by OpenNI2 (case-insensitive): models
// starting with primesense, carmine, kinect_v1, kinect1, xtion or asus_xtion.
bool IsOpenNI2CameraModel(const std::string& model);

// The models above, for messages.
inline constexpr const char* kOpenNI2Models =
    "primesense_carmine_1_08, primesense_carmine_1_09, kinect_v1, xtion, xtion_pro_live";

struct OpenNI2Options {
  int device_index = 0;        // which connected device, when serial_number is 0
  unsigned serial_number = 0;  // a device's serial number; 0 = by index
};

class OpenNI2Camera : public RgbdCamera {
 public:
  // Opens the camera. The device streams 640x480; the config's width_px and height_px must
  // say so. Throws CameraError (no device, a model OpenNI2 does not drive, a wrong size).
  explicit OpenNI2Camera(const field::CameraConfig& camera, const OpenNI2Options& options = {});
  ~OpenNI2Camera() override;
  OpenNI2Camera(const OpenNI2Camera&) = delete;
  OpenNI2Camera& operator=(const OpenNI2Camera&) = delete;

  // The next frame; nothing when the driver has none yet. Throws CameraError on a hardware
  // error (the camera unplugged).
  std::optional<RgbdFrame> Grab() override;

 private:
  struct Device;
  std::unique_ptr<Device> device_;
  int64_t next_index_ = 0;
};

}  // namespace slamo::platform
