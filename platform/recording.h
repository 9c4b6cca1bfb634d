// Recorded runs: RGB-D frames (colour BGR8 registered to depth, depth uint16 mm, timestamps),
// cumulative encoder ticks with timestamps and, when known, the true robot pose. Two formats
// (see platform/RECORDING.md for the byte-level details):
//
//   TUM RGB-D folder   rgb/<t>.png, depth/<t>.png (16-bit, 5000 per metre: depth_mm * 5),
//                      rgb.txt, depth.txt, groundtruth.txt (when known) as in the TUM RGB-D
//                      benchmark, plus encoders.txt (`t left right`) and recording.json
//                      (robot, camera intrinsics, wheel geometry).
//   MRPT rawlog        observation-only: a CObservationComment with the same JSON first, then
//                      CObservation3DRangeScan (intensity image + uint16 depth in mm),
//                      CObservationOdometry (encoder ticks, dead-reckoned pose) and
//                      CObservationRobotPose (ground truth, label GROUND_TRUTH) in call order.
//
// Writers stream to disk (a long run is never held in memory); readers implement RgbdCamera
// and hand frames out one at a time in time order, with encoders and ground truth loaded up
// front. Bad input throws RecordingError naming the file and line (TUM) or record (rawlog).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "platform/drive_base.h"
#include "platform/rgbd.h"

namespace slamo::platform {

// A recording that cannot be written or read; the message names the file and line or record.
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a recording says about itself (recording.json; the rawlog's leading comment).
struct RecordingInfo {
  std::string source;       // "sim", "openni2", ...
  std::string robot;        // robot name from its config
  std::string description;  // free text: season, seed, script, ...
  std::string camera_model;
  int width_px = 0;
  int height_px = 0;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
  double metres_per_tick = 0.0;  // wheel travel per encoder tick; 0 = unknown
  double track_width_m = 0.0;    // 0 = unknown
};

// The robot's name, camera intrinsics and wheel geometry.
RecordingInfo RecordingInfoFor(const field::RobotConfig& robot);

// The true robot pose on the field (not the camera's) at t_s.
struct StampedPose {
  double t_s = 0.0;
  Pose2D pose;
};

// TUM's depth PNG scale: 5000 units per metre, so a TUM depth value is depth_mm * 5 and the
// deepest storable reading is 13.107 m.
inline constexpr double kTumDepthUnitsPerMetre = 5000.0;

class RecordingWriter {
 public:
  virtual ~RecordingWriter() = default;
  // Frame times must increase (by at least 1 us: TUM names files by time); colour CV_8UC3 and
  // depth CV_16UC1 of one size. Encoder and ground-truth times must not decrease.
  virtual void AddFrame(const RgbdFrame& frame) = 0;
  virtual void AddEncoders(const EncoderTicks& ticks) = 0;
  virtual void AddGroundTruth(const StampedPose& pose) = 0;
  // Finishes the files (TUM: recording.json; rawlog: flush). Throws RecordingError. The
  // destructor closes a writer not closed yet, ignoring errors.
  virtual void Close() = 0;
  // Where it writes (the folder or the .rawlog file).
  virtual const std::string& path() const = 0;
};

// Into a TUM RGB-D folder, created if needed; one that already holds a recording (rgb.txt,
// depth.txt, recording.json, rgb/ or depth/) is an error, nothing is overwritten.
std::unique_ptr<RecordingWriter> OpenTumWriter(const std::string& dir, const RecordingInfo& info);
// Into an MRPT rawlog (gzip-compressed); an existing file is replaced.
std::unique_ptr<RecordingWriter> OpenRawlogWriter(const std::string& path,
                                                  const RecordingInfo& info);

class RecordingReader : public RgbdCamera {
 public:
  // The next frame in time order (index counts from 0); nothing after the last one. Throws
  // RecordingError on an unreadable image or record.
  std::optional<RgbdFrame> Grab() override = 0;
  const RecordingInfo& info() const { return info_; }
  size_t frame_count() const { return frame_count_; }
  const std::vector<EncoderTicks>& encoders() const { return encoders_; }
  const std::vector<StampedPose>& ground_truth() const { return ground_truth_; }
  const std::string& path() const { return path_; }

 protected:
  std::string path_;
  RecordingInfo info_;
  size_t frame_count_ = 0;
  std::vector<EncoderTicks> encoders_;
  std::vector<StampedPose> ground_truth_;
};

struct TumReaderOptions {
  // A colour image is paired with the depth image nearest in time within this (TUM's
  // associate.py default); slamo recordings pair exactly.
  double max_pair_dt_s = 0.02;
};

// A TUM RGB-D folder: ours, or a benchmark sequence (no encoders.txt or recording.json needed;
// a benchmark's 3D ground truth is read as x, y and the yaw of its quaternion).
std::unique_ptr<RecordingReader> OpenTumRecording(const std::string& dir,
                                                  const TumReaderOptions& options = {});
// An MRPT rawlog (gzip-compressed or not; observation-only or sensory frames). Frames come
// from CObservation3DRangeScan with an intensity image the size of the depth image, encoders
// from CObservationOdometry with encoder info, ground truth from CObservationRobotPose.
std::unique_ptr<RecordingReader> OpenRawlogRecording(const std::string& path);
// A folder is read as TUM, a file as a rawlog.
std::unique_ptr<RecordingReader> OpenRecording(const std::string& path);

}  // namespace slamo::platform
