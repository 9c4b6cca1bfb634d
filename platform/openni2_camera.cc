#include "platform/openni2_camera.h"

#include <algorithm>
#include <cctype>
#include <sstream>

#include <mrpt/core/Clock.h>
#include <mrpt/hwdrivers/COpenNI2Generic.h>
#include <mrpt/hwdrivers/COpenNI2Sensor.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace slamo::platform {
namespace {

constexpr int kWidthPx = 640;
constexpr int kHeightPx = 480;

// The gist of an MRPT exception: its `Message:` line.
std::string Gist(const std::string& text) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("Message:", 0) == 0) {
      line.erase(0, 8);
      const auto first = line.find_first_not_of(" \t");
      return first == std::string::npos ? "no message" : line.substr(first);
    }
  }
  return text.substr(0, text.find('\n'));
}

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

bool IsOpenNI2CameraModel(const std::string& model) {
  std::string m = model;
  std::transform(m.begin(), m.end(), m.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* prefix :
       {"primesense", "carmine", "kinect_v1", "kinect1", "xtion", "asus_xtion"}) {
    if (StartsWith(m, prefix)) return true;
  }
  return false;
}

struct OpenNI2Camera::Device {
  // MRPT's sensor throws from its destructor when its device is gone; such a sensor is
  // released (leaked) rather than destroyed, see ~OpenNI2Camera.
  std::unique_ptr<mrpt::hwdrivers::COpenNI2Sensor> sensor;
  int id = 0;
};

OpenNI2Camera::OpenNI2Camera(const field::CameraConfig& camera, const OpenNI2Options& options)
    : device_(std::make_unique<Device>()) {
  if (!IsOpenNI2CameraModel(camera.model)) {
    throw CameraError("camera model '" + camera.model + "' is not an OpenNI2 device (OpenNI2 " +
                      "drives " + kOpenNI2Models + ")");
  }
  if (camera.width_px != kWidthPx || camera.height_px != kHeightPx) {
    throw CameraError("an OpenNI2 camera streams 640x480; the robot file says " +
                      std::to_string(camera.width_px) + "x" + std::to_string(camera.height_px) +
                      " (camera.width_px, camera.height_px)");
  }
  try {
    // Probe first: a sensor object that finds no device cannot be destroyed safely.
    int connected = 0;
    {
      mrpt::hwdrivers::COpenNI2Generic probe;
      connected = probe.getConnectedDevices();
    }
    if (connected <= 0) {
      throw CameraError("no OpenNI2 camera found (" + camera.model +
                        "): is it plugged in and powered, and can this user open its USB "
                        "device (udev rules of libopenni2-0)?");
    }
    if (options.serial_number == 0 && options.device_index >= connected) {
      throw CameraError("OpenNI2 device " + std::to_string(options.device_index) + " asked for, " +
                        std::to_string(connected) + " connected");
    }
    device_->sensor = std::make_unique<mrpt::hwdrivers::COpenNI2Sensor>();
    auto& sensor = *device_->sensor;
    sensor.enableGrabRGB(true);
    sensor.enableGrabDepth(true);
    sensor.enableGrab3DPoints(false);
    if (options.serial_number != 0) {
      sensor.setSerialToOpen(options.serial_number);
    } else {
      sensor.setSensorIDToOpen(static_cast<unsigned>(options.device_index));
    }
    sensor.initialize();
    device_->id = options.device_index;
    if (options.serial_number != 0 &&
        !sensor.getDeviceIDFromSerialNum(options.serial_number, device_->id)) {
      throw CameraError("no OpenNI2 camera with serial number " +
                        std::to_string(options.serial_number));
    }
    if (!sensor.isOpen(static_cast<unsigned>(device_->id))) {
      throw CameraError("the OpenNI2 camera did not open (in use by another program?)");
    }
  } catch (const CameraError&) {
    if (device_->sensor && !device_->sensor->isOpen(static_cast<unsigned>(device_->id))) {
      (void)device_->sensor.release();  // see Device
    }
    throw;
  } catch (const std::exception& e) {
    if (device_->sensor) (void)device_->sensor.release();  // see Device
    throw CameraError("OpenNI2: " + Gist(e.what()));
  }
}

OpenNI2Camera::~OpenNI2Camera() {
  if (device_ && device_->sensor && !device_->sensor->isOpen(static_cast<unsigned>(device_->id))) {
    (void)device_->sensor.release();  // see Device
  }
}

std::optional<RgbdFrame> OpenNI2Camera::Grab() {
  mrpt::obs::CObservation3DRangeScan scan;
  bool there_is_obs = false, hardware_error = false;
  try {
    device_->sensor->getNextObservation(scan, there_is_obs, hardware_error);
  } catch (const std::exception& e) {
    throw CameraError("OpenNI2: " + Gist(e.what()));
  }
  if (hardware_error) throw CameraError("OpenNI2: the camera stopped answering (unplugged?)");
  if (!there_is_obs || !scan.hasRangeImage || !scan.hasIntensityImage) return std::nullopt;

  RgbdFrame frame;
  frame.t_s = mrpt::Clock::toDouble(scan.timestamp);
  frame.index = next_index_++;
  const int rows = static_cast<int>(scan.rangeImage.rows());
  const int cols = static_cast<int>(scan.rangeImage.cols());
  frame.depth_mm.create(rows, cols, CV_16UC1);
  const double mm_per_unit = static_cast<double>(scan.rangeUnits) * 1000.0;
  for (int r = 0; r < rows; ++r) {
    uint16_t* out = frame.depth_mm.ptr<uint16_t>(r);
    for (int c = 0; c < cols; ++c) {
      out[c] = cv::saturate_cast<uint16_t>(std::lround(scan.rangeImage(r, c) * mm_per_unit));
    }
  }
  cv::Mat colour;
  scan.intensityImage.asCvMat(colour, mrpt::img::DEEP_COPY);
  if (colour.type() == CV_8UC1) cv::cvtColor(colour, colour, cv::COLOR_GRAY2BGR);
  if (colour.size() != frame.depth_mm.size()) {
    // Registration maps depth onto the colour camera; match the pixel grids if sizes differ.
    cv::resize(colour, colour, frame.depth_mm.size(), 0, 0, cv::INTER_LINEAR);
  }
  frame.colour = colour;
  return frame;
}

}  // namespace slamo::platform
