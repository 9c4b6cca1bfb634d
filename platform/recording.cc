#include "platform/recording.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include <mrpt/core/Clock.h>
#include <mrpt/img/CImage.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationComment.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "platform/clock.h"
#include "platform/rawlog_guard.h"
#include "platform/rawlog_reader.h"

namespace slamo::platform {
namespace {

namespace fs = std::filesystem;

constexpr const char* kFormatName = "slamo-recording";
constexpr int kFormatVersion = 1;
constexpr const char* kGroundTruthLabel = "GROUND_TRUTH";
constexpr const char* kOdometryLabel = "ODOMETRY";
constexpr const char* kCameraLabel = "RGBD";
// The deepest reading a TUM depth PNG holds: 65535 / 5 mm.
constexpr int kTumMaxDepthMm = 13107;

// Timestamps as TUM writes them: seconds with 6 decimals (names files too).
std::string FormatTime(double t_s) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", t_s);
  return text;
}

// ---- recording.json / the rawlog comment ----

nlohmann::json InfoToJson(const RecordingInfo& info) {
  nlohmann::json j;
  j["format"] = kFormatName;
  j["version"] = kFormatVersion;
  j["source"] = info.source;
  j["robot"] = info.robot;
  j["description"] = info.description;
  j["camera"] = {{"model", info.camera_model},
                 {"width_px", info.width_px},
                 {"height_px", info.height_px},
                 {"fx", info.fx},
                 {"fy", info.fy},
                 {"cx", info.cx},
                 {"cy", info.cy}};
  j["drive"] = {{"metres_per_tick", info.metres_per_tick}, {"track_width_m", info.track_width_m}};
  return j;
}

template <typename T>
void Get(const nlohmann::json& j, const char* key, T* value) {
  if (j.is_object() && j.contains(key) && !j.at(key).is_null()) *value = j.at(key).get<T>();
}

// Throws nlohmann::json::exception on a wrong type.
RecordingInfo InfoFromJson(const nlohmann::json& j) {
  RecordingInfo info;
  Get(j, "source", &info.source);
  Get(j, "robot", &info.robot);
  Get(j, "description", &info.description);
  if (j.contains("camera")) {
    const nlohmann::json& c = j.at("camera");
    Get(c, "model", &info.camera_model);
    Get(c, "width_px", &info.width_px);
    Get(c, "height_px", &info.height_px);
    Get(c, "fx", &info.fx);
    Get(c, "fy", &info.fy);
    Get(c, "cx", &info.cx);
    Get(c, "cy", &info.cy);
  }
  if (j.contains("drive")) {
    Get(j.at("drive"), "metres_per_tick", &info.metres_per_tick);
    Get(j.at("drive"), "track_width_m", &info.track_width_m);
  }
  return info;
}

// ---- Checks shared by the writers ----

class WriterChecks {
 public:
  explicit WriterChecks(std::string path) : path_(std::move(path)) {}

  // Throws when the frame cannot be written; Accept() it once it is.
  void Frame(const RgbdFrame& frame) const {
    if (frame.colour.type() != CV_8UC3) {
      throw Error("frame " + FormatTime(frame.t_s) + ": colour must be CV_8UC3 (BGR)");
    }
    if (frame.depth_mm.type() != CV_16UC1) {
      throw Error("frame " + FormatTime(frame.t_s) + ": depth must be CV_16UC1 (mm)");
    }
    if (frame.colour.size() != frame.depth_mm.size()) {
      throw Error("frame " + FormatTime(frame.t_s) +
                  ": colour and depth differ in size (colour must be registered to depth)");
    }
    if (!std::isfinite(frame.t_s)) throw Error("frame time is not finite");
    if (frames_ > 0 && !(frame.t_s > last_frame_t_ && FormatTime(frame.t_s) != last_frame_name_)) {
      throw Error("frame time " + FormatTime(frame.t_s) + " s does not increase by 1 us after " +
                  last_frame_name_ + " s");
    }
  }

  void Accept(const RgbdFrame& frame) {
    last_frame_t_ = frame.t_s;
    last_frame_name_ = FormatTime(frame.t_s);
    ++frames_;
  }

  void Encoders(const EncoderTicks& ticks) {
    if (!std::isfinite(ticks.t_s)) throw Error("encoder time is not finite");
    if (ticks.t_s < last_encoder_t_) {
      throw Error("encoder time goes backwards: " + FormatTime(ticks.t_s) + " s after " +
                  FormatTime(last_encoder_t_) + " s");
    }
    last_encoder_t_ = ticks.t_s;
  }

  void GroundTruth(const StampedPose& pose) {
    if (!std::isfinite(pose.t_s) || !std::isfinite(pose.pose.x_m) ||
        !std::isfinite(pose.pose.y_m) || !std::isfinite(pose.pose.theta_rad)) {
      throw Error("a ground-truth pose that is not finite");
    }
    if (pose.t_s < last_truth_t_) {
      throw Error("ground-truth time goes backwards: " + FormatTime(pose.t_s) + " s after " +
                  FormatTime(last_truth_t_) + " s");
    }
    last_truth_t_ = pose.t_s;
  }

  RecordingError Error(const std::string& what) const {
    return RecordingError(path_ + ": " + what);
  }
  int frames() const { return frames_; }

 private:
  std::string path_;
  int frames_ = 0;
  double last_frame_t_ = 0.0;
  std::string last_frame_name_;
  double last_encoder_t_ = -std::numeric_limits<double>::infinity();
  double last_truth_t_ = -std::numeric_limits<double>::infinity();
};

// ---- TUM RGB-D folder: writer ----

class TumWriter : public RecordingWriter {
 public:
  TumWriter(const std::string& dir, const RecordingInfo& info)
      : dir_(dir), info_(info), checks_(dir) {
    std::error_code ec;
    if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec)) {
      throw checks_.Error("exists and is not a folder");
    }
    for (const char* entry : {"rgb.txt", "depth.txt", "recording.json", "encoders.txt",
                              "groundtruth.txt", "rgb", "depth"}) {
      if (fs::exists(fs::path(dir_) / entry, ec)) {
        throw checks_.Error(std::string("already holds a recording (") + entry +
                            "); choose another folder or remove it");
      }
    }
    fs::create_directories(fs::path(dir_) / "rgb", ec);
    if (!ec) fs::create_directories(fs::path(dir_) / "depth", ec);
    if (ec) throw checks_.Error("cannot create the folder: " + ec.message());
    Open("rgb.txt", &rgb_txt_,
         "# colour images\n# slamo recording: " + info_.robot + "\n# timestamp filename\n");
    Open("depth.txt", &depth_txt_,
         "# depth maps (16-bit PNG, 5000 per metre)\n# slamo recording: " + info_.robot +
             "\n# timestamp filename\n");
  }

  ~TumWriter() override {
    try {
      if (!closed_) Close();
    } catch (...) {  // NOLINT(bugprone-empty-catch): a destructor must not throw
    }
  }

  void AddFrame(const RgbdFrame& frame) override {
    checks_.Frame(frame);
    double max_mm = 0.0;
    cv::minMaxLoc(frame.depth_mm, nullptr, &max_mm);
    if (max_mm > kTumMaxDepthMm) {
      throw checks_.Error("frame " + FormatTime(frame.t_s) + ": a depth of " +
                          std::to_string(static_cast<int>(max_mm)) +
                          " mm is beyond what TUM's 16-bit PNG holds (13107 mm)");
    }
    const std::string name = FormatTime(frame.t_s) + ".png";
    cv::Mat tum_depth;
    frame.depth_mm.convertTo(tum_depth, CV_16UC1, kTumDepthUnitsPerMetre / 1000.0);
    WriteImage("rgb/" + name, frame.colour);
    WriteImage("depth/" + name, tum_depth);
    rgb_txt_ << FormatTime(frame.t_s) << " rgb/" << name << "\n";
    depth_txt_ << FormatTime(frame.t_s) << " depth/" << name << "\n";
    checks_.Accept(frame);
  }

  void AddEncoders(const EncoderTicks& ticks) override {
    checks_.Encoders(ticks);
    if (!encoders_txt_.is_open()) {
      Open("encoders.txt", &encoders_txt_,
           "# cumulative wheel encoder ticks (slamo; positive forward)\n# timestamp left right\n");
    }
    encoders_txt_ << FormatTime(ticks.t_s) << " " << ticks.left << " " << ticks.right << "\n";
    ++encoder_readings_;
  }

  void AddGroundTruth(const StampedPose& pose) override {
    checks_.GroundTruth(pose);
    if (!truth_txt_.is_open()) {
      Open("groundtruth.txt", &truth_txt_,
           "# ground truth trajectory: the robot on the field (z = 0, yaw about z)\n"
           "# slamo recording: " +
               info_.robot + "\n# timestamp tx ty tz qx qy qz qw\n");
    }
    const double half = 0.5 * pose.pose.theta_rad;
    char line[256];
    std::snprintf(line, sizeof(line), "%s %.9f %.9f 0 0 0 %.12f %.12f\n",
                  FormatTime(pose.t_s).c_str(), pose.pose.x_m, pose.pose.y_m, std::sin(half),
                  std::cos(half));
    truth_txt_ << line;
    ++truth_poses_;
  }

  void Close() override {
    closed_ = true;
    const std::pair<const char*, std::ofstream*> streams[] = {{"rgb.txt", &rgb_txt_},
                                                              {"depth.txt", &depth_txt_},
                                                              {"encoders.txt", &encoders_txt_},
                                                              {"groundtruth.txt", &truth_txt_}};
    for (const auto& [name, stream] : streams) {
      if (!stream->is_open()) continue;
      stream->close();
      if (!*stream) throw checks_.Error(std::string(name) + ": write failed");
    }
    nlohmann::json j = InfoToJson(info_);
    j["depth_units_per_metre"] = kTumDepthUnitsPerMetre;
    j["frames"] = checks_.frames();
    j["encoder_readings"] = encoder_readings_;
    j["ground_truth_poses"] = truth_poses_;
    std::ofstream json(fs::path(dir_) / "recording.json");
    json << j.dump(2) << "\n";
    json.close();
    if (!json) throw checks_.Error("recording.json: write failed");
  }

  const std::string& path() const override { return dir_; }

 private:
  void Open(const std::string& name, std::ofstream* out, const std::string& header) {
    out->open(fs::path(dir_) / name);
    if (!*out) throw checks_.Error(name + ": cannot open for writing");
    *out << header;
  }

  void WriteImage(const std::string& name, const cv::Mat& image) {
    bool ok = false;
    try {
      ok = cv::imwrite((fs::path(dir_) / name).string(), image);
    } catch (const cv::Exception& e) {
      throw checks_.Error(name + ": cannot write (" + e.msg + ")");
    }
    if (!ok) throw checks_.Error(name + ": cannot write");
  }

  std::string dir_;
  RecordingInfo info_;
  WriterChecks checks_;
  std::ofstream rgb_txt_, depth_txt_, encoders_txt_, truth_txt_;
  int encoder_readings_ = 0;
  int truth_poses_ = 0;
  bool closed_ = false;
};

// ---- MRPT rawlog: writer ----

mrpt::img::TCamera CameraParams(const RecordingInfo& info, const cv::Size& size) {
  mrpt::img::TCamera camera;
  camera.ncols = static_cast<uint32_t>(size.width);
  camera.nrows = static_cast<uint32_t>(size.height);
  camera.setIntrinsicParamsFromValues(info.fx, info.fy, info.cx, info.cy);
  return camera;
}

class RawlogWriter : public RecordingWriter {
 public:
  RawlogWriter(const std::string& path, const RecordingInfo& info)
      : path_(path), info_(info), checks_(path) {
    // Colour images go into the rawlog losslessly (this is MRPT's default; made sure of here).
    mrpt::img::CImage::DISABLE_JPEG_COMPRESSION(true);
    bool ok = false;
    try {
      ok = file_.open(path_);
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok) throw checks_.Error("cannot open for writing");
    archive_ = mrpt::serialization::archiveUniquePtrFrom(file_);
    mrpt::obs::CObservationComment comment;
    comment.sensorLabel = "slamo";
    comment.timestamp = mrpt::Clock::time_point();
    comment.text = InfoToJson(info_).dump();
    Write(comment);
  }

  ~RawlogWriter() override {
    try {
      if (!closed_) Close();
    } catch (...) {  // NOLINT(bugprone-empty-catch): a destructor must not throw
    }
  }

  void AddFrame(const RgbdFrame& frame) override {
    checks_.Frame(frame);
    mrpt::obs::CObservation3DRangeScan scan;
    scan.sensorLabel = kCameraLabel;
    scan.timestamp = mrpt::Clock::fromDouble(frame.t_s);
    scan.hasRangeImage = true;
    scan.range_is_depth = true;
    scan.rangeUnits = 0.001f;  // millimetres, as our depth
    scan.rangeImage_setSize(frame.depth_mm.rows, frame.depth_mm.cols);
    for (int r = 0; r < frame.depth_mm.rows; ++r) {
      const uint16_t* row = frame.depth_mm.ptr<uint16_t>(r);
      for (int c = 0; c < frame.depth_mm.cols; ++c) scan.rangeImage(r, c) = row[c];
    }
    scan.hasIntensityImage = true;
    scan.intensityImageChannel = mrpt::obs::CObservation3DRangeScan::CH_VISIBLE;
    scan.intensityImage = mrpt::img::CImage(frame.colour, mrpt::img::DEEP_COPY);
    scan.cameraParams = CameraParams(info_, frame.depth_mm.size());
    scan.cameraParamsIntensity = scan.cameraParams;  // registered: the same camera
    Write(scan);
    checks_.Accept(frame);
  }

  void AddEncoders(const EncoderTicks& ticks) override {
    constexpr int64_t kMin = std::numeric_limits<int32_t>::min();
    constexpr int64_t kMax = std::numeric_limits<int32_t>::max();
    if (ticks.left < kMin || ticks.left > kMax || ticks.right < kMin || ticks.right > kMax) {
      throw checks_.Error("encoder ticks at " + FormatTime(ticks.t_s) +
                          " s do not fit MRPT's 32-bit encoder fields");
    }
    checks_.Encoders(ticks);
    mrpt::obs::CObservationOdometry odometry;
    odometry.sensorLabel = kOdometryLabel;
    odometry.timestamp = mrpt::Clock::fromDouble(ticks.t_s);
    odometry.hasEncodersInfo = true;
    odometry.encoderLeftTicks = static_cast<int32_t>(ticks.left);
    odometry.encoderRightTicks = static_cast<int32_t>(ticks.right);
    // The dead-reckoned pose, for readers that use only MRPT's odometry (slamo replay).
    if (info_.metres_per_tick > 0.0 && info_.track_width_m > 0.0) {
      if (!dead_reckoning_) {
        dead_reckoning_.emplace(info_.metres_per_tick, info_.track_width_m, ticks);
      }
      const Pose2D& p = dead_reckoning_->Update(ticks);
      odometry.odometry = mrpt::poses::CPose2D(p.x_m, p.y_m, p.theta_rad);
    }
    Write(odometry);
  }

  void AddGroundTruth(const StampedPose& pose) override {
    checks_.GroundTruth(pose);
    mrpt::obs::CObservationRobotPose truth;
    truth.sensorLabel = kGroundTruthLabel;
    truth.timestamp = mrpt::Clock::fromDouble(pose.t_s);
    truth.pose.mean =
        mrpt::poses::CPose3D(pose.pose.x_m, pose.pose.y_m, 0.0, pose.pose.theta_rad, 0.0, 0.0);
    truth.pose.cov.setZero();
    Write(truth);
  }

  void Close() override {
    if (closed_) return;
    closed_ = true;
    archive_.reset();
    file_.close();
  }

  const std::string& path() const override { return path_; }

 private:
  void Write(const mrpt::serialization::CSerializable& object) {
    try {
      *archive_ << object;
    } catch (const std::exception& e) {
      throw checks_.Error(std::string("write failed: ") + e.what());
    }
  }

  std::string path_;
  RecordingInfo info_;
  WriterChecks checks_;
  mrpt::io::CFileGZOutputStream file_;
  mrpt::serialization::CArchive::UniquePtr archive_;
  std::optional<EncoderOdometry> dead_reckoning_;
  bool closed_ = false;
};

// ---- TUM RGB-D folder: reader ----

// One line of a TUM index or data file, split into fields; comments and blank lines skipped.
class LineFile {
 public:
  LineFile(const std::string& dir, const std::string& name) : name_(name) {
    path_ = (fs::path(dir) / name).string();
    in_.open(path_);
  }
  bool is_open() const { return in_.is_open(); }
  const std::string& path() const { return path_; }

  bool Next(std::vector<std::string>* fields) {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_number_;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const auto first = line.find_first_not_of(" \t");
      if (first == std::string::npos || line[first] == '#') continue;
      std::istringstream words(line);
      fields->clear();
      for (std::string word; words >> word;) fields->push_back(word);
      return true;
    }
    return false;
  }

  int line_number() const { return line_number_; }

  RecordingError Error(const std::string& what) const {
    return RecordingError(path_ + ":" + std::to_string(line_number_) + ": " + what);
  }

  double Number(const std::string& token, const char* name) const {
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(token.c_str(), &end);
    if (token.empty() || end != token.c_str() + token.size()) {
      throw Error(std::string(name) + " `" + token + "` is not a number");
    }
    if (!std::isfinite(value) || errno == ERANGE) {
      throw Error(std::string(name) + " `" + token + "` is not finite");
    }
    return value;
  }

  int64_t Integer(const std::string& token, const char* name) const {
    char* end = nullptr;
    errno = 0;
    const long long value = std::strtoll(token.c_str(), &end, 10);
    if (token.empty() || end != token.c_str() + token.size() || errno == ERANGE) {
      throw Error(std::string(name) + " `" + token + "` is not an integer");
    }
    return value;
  }

  void ExpectFields(const std::vector<std::string>& fields, size_t n, const char* usage) const {
    if (fields.size() == n) return;
    throw Error(std::string(fields.size() < n ? "truncated line" : "too many fields") +
                ": expected `" + usage + "`, found " + std::to_string(fields.size()) + " fields");
  }

 private:
  std::string name_;
  std::string path_;
  std::ifstream in_;
  int line_number_ = 0;
};

struct IndexEntry {
  double t_s = 0.0;
  std::string file;
  int line = 0;
};

class TumReader : public RecordingReader {
 public:
  TumReader(const std::string& dir, const TumReaderOptions& options) : dir_(dir) {
    path_ = dir;
    std::error_code ec;
    if (!fs::exists(dir_, ec)) throw RecordingError(dir_ + ": no such folder");
    if (!fs::is_directory(dir_, ec)) throw RecordingError(dir_ + ": not a folder");
    ReadInfo();
    const std::vector<IndexEntry> rgb = ReadIndex("rgb.txt");
    const std::vector<IndexEntry> depth = ReadIndex("depth.txt");
    PairImages(rgb, depth, options.max_pair_dt_s);
    ReadEncoders();
    ReadGroundTruth();
  }

  std::optional<RgbdFrame> Grab() override {
    if (next_ >= frames_.size()) return std::nullopt;
    const FramePair& pair = frames_[next_];
    RgbdFrame frame;
    frame.t_s = pair.rgb.t_s;
    frame.index = static_cast<int64_t>(next_);
    frame.colour = ReadImage(pair.rgb, "rgb.txt", cv::IMREAD_COLOR);
    const cv::Mat raw = ReadImage(pair.depth, "depth.txt", cv::IMREAD_ANYDEPTH);
    if (raw.type() != CV_16UC1) {
      throw IndexError("depth.txt", pair.depth,
                       pair.depth.file + ": not a 16-bit single-channel depth image");
    }
    if (raw.size() != frame.colour.size()) {
      throw IndexError("depth.txt", pair.depth,
                       pair.depth.file + ": " + std::to_string(raw.cols) + "x" +
                           std::to_string(raw.rows) + " depth for a " +
                           std::to_string(frame.colour.cols) + "x" +
                           std::to_string(frame.colour.rows) +
                           " colour image (colour must be registered to depth)");
    }
    frame.depth_mm = ToMillimetres(raw);
    ++next_;
    return frame;
  }

 private:
  struct FramePair {
    IndexEntry rgb;
    IndexEntry depth;
  };

  RecordingError IndexError(const std::string& index, const IndexEntry& entry,
                            const std::string& what) const {
    return RecordingError((fs::path(dir_) / index).string() + ":" + std::to_string(entry.line) +
                          ": " + what);
  }

  cv::Mat ReadImage(const IndexEntry& entry, const std::string& index, int flags) const {
    const std::string file = (fs::path(dir_) / entry.file).string();
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) {
      throw IndexError(index, entry, entry.file + ": no such image");
    }
    cv::Mat image;
    try {
      image = cv::imread(file, flags);
    } catch (const cv::Exception& e) {
      throw IndexError(index, entry, entry.file + ": cannot read the image (" + e.msg + ")");
    }
    if (image.empty()) throw IndexError(index, entry, entry.file + ": cannot read the image");
    return image;
  }

  cv::Mat ToMillimetres(const cv::Mat& raw) const {
    cv::Mat mm(raw.size(), CV_16UC1);
    const bool tum_scale = depth_units_per_metre_ == kTumDepthUnitsPerMetre;
    const double mm_per_unit = 1000.0 / depth_units_per_metre_;
    for (int r = 0; r < raw.rows; ++r) {
      const uint16_t* in = raw.ptr<uint16_t>(r);
      uint16_t* out = mm.ptr<uint16_t>(r);
      for (int c = 0; c < raw.cols; ++c) {
        // Nearest millimetre: exact for our depth_mm * 5.
        out[c] = tum_scale ? static_cast<uint16_t>((in[c] + 2) / 5)
                           : cv::saturate_cast<uint16_t>(std::lround(in[c] * mm_per_unit));
      }
    }
    return mm;
  }

  void ReadInfo() {
    const fs::path file = fs::path(dir_) / "recording.json";
    std::error_code ec;
    if (!fs::exists(file, ec)) return;  // a TUM benchmark sequence
    std::ifstream in(file);
    if (!in) throw RecordingError(file.string() + ": cannot open");
    try {
      const nlohmann::json j = nlohmann::json::parse(in);
      info_ = InfoFromJson(j);
      Get(j, "depth_units_per_metre", &depth_units_per_metre_);
    } catch (const nlohmann::json::exception& e) {
      throw RecordingError(file.string() + ": " + e.what());
    }
    if (!(depth_units_per_metre_ > 0.0) || !std::isfinite(depth_units_per_metre_)) {
      throw RecordingError(file.string() + ": depth_units_per_metre must be positive");
    }
  }

  std::vector<IndexEntry> ReadIndex(const std::string& name) const {
    LineFile file(dir_, name);
    if (!file.is_open()) throw RecordingError(file.path() + ": missing (cannot open)");
    std::vector<IndexEntry> entries;
    std::vector<std::string> fields;
    while (file.Next(&fields)) {
      file.ExpectFields(fields, 2, "timestamp filename");
      IndexEntry entry{file.Number(fields[0], "timestamp"), fields[1], file.line_number()};
      if (!entries.empty() && entry.t_s <= entries.back().t_s) {
        throw file.Error("time does not increase: " + fields[0] + " s after " +
                         FormatTime(entries.back().t_s) + " s");
      }
      entries.push_back(std::move(entry));
    }
    return entries;
  }

  // Each colour image with the nearest unused depth image within max_dt_s.
  void PairImages(const std::vector<IndexEntry>& rgb, const std::vector<IndexEntry>& depth,
                  double max_dt_s) {
    std::vector<bool> used(depth.size(), false);
    size_t j = 0;
    for (const IndexEntry& colour : rgb) {
      while (j + 1 < depth.size() &&
             std::abs(depth[j + 1].t_s - colour.t_s) <= std::abs(depth[j].t_s - colour.t_s)) {
        ++j;
      }
      if (j < depth.size() && !used[j] && std::abs(depth[j].t_s - colour.t_s) <= max_dt_s) {
        used[j] = true;
        frames_.push_back({colour, depth[j]});
      }
    }
    if (!rgb.empty() && !depth.empty() && frames_.empty()) {
      throw RecordingError(dir_ + ": no colour image has a depth image within " +
                           std::to_string(max_dt_s) + " s");
    }
    frame_count_ = frames_.size();
  }

  void ReadEncoders() {
    LineFile file(dir_, "encoders.txt");
    if (!file.is_open()) return;  // optional
    std::vector<std::string> fields;
    while (file.Next(&fields)) {
      file.ExpectFields(fields, 3, "timestamp left right");
      const EncoderTicks ticks{file.Number(fields[0], "timestamp"), file.Integer(fields[1], "left"),
                               file.Integer(fields[2], "right")};
      if (!encoders_.empty() && ticks.t_s < encoders_.back().t_s) {
        throw file.Error("time goes backwards: " + fields[0] + " s after " +
                         FormatTime(encoders_.back().t_s) + " s");
      }
      encoders_.push_back(ticks);
    }
  }

  void ReadGroundTruth() {
    LineFile file(dir_, "groundtruth.txt");
    if (!file.is_open()) return;  // optional
    std::vector<std::string> fields;
    while (file.Next(&fields)) {
      file.ExpectFields(fields, 8, "timestamp tx ty tz qx qy qz qw");
      double v[8];
      static const char* const kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
      for (int i = 0; i < 8; ++i) v[i] = file.Number(fields[i], kNames[i]);
      const double qx = v[4], qy = v[5], qz = v[6], qw = v[7];
      const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
      if (std::abs(norm - 1.0) > 1e-3) {
        throw file.Error("quaternion is not a unit quaternion (norm " + std::to_string(norm) + ")");
      }
      StampedPose pose;
      pose.t_s = v[0];
      pose.pose.x_m = v[1];
      pose.pose.y_m = v[2];
      pose.pose.theta_rad =
          WrapAngleRad(std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)));
      if (!ground_truth_.empty() && pose.t_s < ground_truth_.back().t_s) {
        throw file.Error("time goes backwards: " + fields[0] + " s after " +
                         FormatTime(ground_truth_.back().t_s) + " s");
      }
      ground_truth_.push_back(pose);
    }
  }

  std::string dir_;
  double depth_units_per_metre_ = kTumDepthUnitsPerMetre;
  std::vector<FramePair> frames_;
  size_t next_ = 0;
};

// ---- MRPT rawlog: reader ----

// A recording rawlog's observations in order (rawlog_reader.h flattens the records; actions
// are skipped: odometry increments as actions are not part of a recording's data).
class RawlogStream {
 public:
  explicit RawlogStream(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw RecordingError(path + ": no such file");
    try {
      records_ = std::make_unique<RawlogRecords>(path);
    } catch (const RawlogError& e) {
      throw RecordingError(e.what());
    }
  }

  // The next observation, or null at the end of the file.
  std::shared_ptr<const mrpt::obs::CObservation> Next() {
    try {
      while (const std::optional<RawlogEntry> entry = records_->Next()) {
        if (entry->observation) return entry->observation;
      }
    } catch (const RawlogError& e) {
      throw RecordingError(e.what());
    }
    return nullptr;
  }

  RecordingError Error(const std::string& what) const {
    return RecordingError(records_->Where(what));
  }

 private:
  std::unique_ptr<RawlogRecords> records_;
};

double Seconds(mrpt::Clock::time_point t) { return mrpt::Clock::toDouble(t); }

// A 3D range scan as an RgbdFrame; throws through `stream` naming the record.
RgbdFrame ToFrame(const mrpt::obs::CObservation3DRangeScan& scan, const RawlogStream& stream) {
  // Every bool below was read from the file: StoredBool (rawlog_guard.h). MRPT's own
  // isExternallyStored() accessors load such bools too (one is private), so external storage
  // is told by what MRPT read instead: a file name, and no depth image in the record.
  if (!StoredBool(scan.hasRangeImage)) {
    throw stream.Error("a 3D range scan without a depth image");
  }
  if (!scan.intensityImage.getExternalStorageFile().empty()) {
    throw stream.Error("a 3D range scan with externally stored images (not supported)");
  }
  if (scan.rangeImage.rows() == 0 || scan.rangeImage.cols() == 0) {
    throw stream.Error(
        "a 3D range scan with an empty depth image (or one stored externally: not supported)");
  }
  if (!StoredBool(scan.range_is_depth)) {
    throw stream.Error("a 3D range scan of ranges, not depth along the axis (not supported)");
  }
  if (!StoredBool(scan.hasIntensityImage)) {
    throw stream.Error("a 3D range scan without an intensity image");
  }
  RgbdFrame frame;
  frame.t_s = Seconds(scan.timestamp);
  const int rows = static_cast<int>(scan.rangeImage.rows());
  const int cols = static_cast<int>(scan.rangeImage.cols());
  frame.depth_mm.create(rows, cols, CV_16UC1);
  const bool millimetres = scan.rangeUnits == 0.001f;
  const double mm_per_unit = static_cast<double>(scan.rangeUnits) * 1000.0;
  for (int r = 0; r < rows; ++r) {
    uint16_t* out = frame.depth_mm.ptr<uint16_t>(r);
    for (int c = 0; c < cols; ++c) {
      const uint16_t v = scan.rangeImage(r, c);
      out[c] = millimetres ? v : cv::saturate_cast<uint16_t>(std::lround(v * mm_per_unit));
    }
  }
  cv::Mat colour;
  scan.intensityImage.asCvMat(colour, mrpt::img::DEEP_COPY);
  if (colour.type() == CV_8UC1) {
    cv::cvtColor(colour, colour, cv::COLOR_GRAY2BGR);
  } else if (colour.type() != CV_8UC3) {
    throw stream.Error("an intensity image that is not 8-bit grey or BGR");
  }
  if (colour.size() != frame.depth_mm.size()) {
    throw stream.Error("a " + std::to_string(colour.cols) + "x" + std::to_string(colour.rows) +
                       " intensity image for a " + std::to_string(cols) + "x" +
                       std::to_string(rows) + " depth image (colour must be registered to depth)");
  }
  frame.colour = colour;
  return frame;
}

class RawlogReader : public RecordingReader {
 public:
  explicit RawlogReader(const std::string& path) {
    path_ = path;
    // First pass: everything but the images; the frames are counted and checked.
    RawlogStream stream(path);
    bool have_info = false;
    double last_frame_t = 0.0;
    while (const std::shared_ptr<const mrpt::obs::CObservation> o = stream.Next()) {
      if (const auto* comment = dynamic_cast<const mrpt::obs::CObservationComment*>(o.get())) {
        if (have_info) continue;
        const nlohmann::json j = nlohmann::json::parse(comment->text, nullptr, false);
        if (j.is_object() && j.value("format", "") == kFormatName) {
          try {
            info_ = InfoFromJson(j);
          } catch (const nlohmann::json::exception& e) {
            throw stream.Error(std::string("recording description: ") + e.what());
          }
          have_info = true;
        }
      } else if (const auto* scan =
                     dynamic_cast<const mrpt::obs::CObservation3DRangeScan*>(o.get())) {
        const RgbdFrame frame = ToFrame(*scan, stream);
        if (frame_count_ > 0 && !(frame.t_s > last_frame_t)) {
          throw stream.Error("frame time does not increase: " + FormatTime(frame.t_s) +
                             " s after " + FormatTime(last_frame_t) + " s");
        }
        last_frame_t = frame.t_s;
        if (frame_count_ == 0 && !have_info) {
          info_.camera_model = scan->sensorLabel;
          info_.width_px = frame.depth_mm.cols;
          info_.height_px = frame.depth_mm.rows;
          info_.fx = scan->cameraParams.fx();
          info_.fy = scan->cameraParams.fy();
          info_.cx = scan->cameraParams.cx();
          info_.cy = scan->cameraParams.cy();
        }
        ++frame_count_;
      } else if (const auto* odometry =
                     dynamic_cast<const mrpt::obs::CObservationOdometry*>(o.get())) {
        if (!StoredBool(odometry->hasEncodersInfo)) continue;
        const EncoderTicks ticks{Seconds(odometry->timestamp), odometry->encoderLeftTicks,
                                 odometry->encoderRightTicks};
        if (!encoders_.empty() && ticks.t_s < encoders_.back().t_s) {
          throw stream.Error("encoder time goes backwards: " + FormatTime(ticks.t_s) + " s after " +
                             FormatTime(encoders_.back().t_s) + " s");
        }
        encoders_.push_back(ticks);
      } else if (const auto* robot_pose =
                     dynamic_cast<const mrpt::obs::CObservationRobotPose*>(o.get())) {
        const mrpt::poses::CPose3D& mean = robot_pose->pose.mean;
        const StampedPose pose{Seconds(robot_pose->timestamp),
                               Pose2D{mean.x(), mean.y(), WrapAngleRad(mean.yaw())}};
        if (!ground_truth_.empty() && pose.t_s < ground_truth_.back().t_s) {
          throw stream.Error("ground-truth time goes backwards: " + FormatTime(pose.t_s) +
                             " s after " + FormatTime(ground_truth_.back().t_s) + " s");
        }
        ground_truth_.push_back(pose);
      }  // other sensors are not part of a recording
    }
    frames_ = std::make_unique<RawlogStream>(path);
  }

  std::optional<RgbdFrame> Grab() override {
    if (next_index_ >= static_cast<int64_t>(frame_count_)) return std::nullopt;
    while (const std::shared_ptr<const mrpt::obs::CObservation> o = frames_->Next()) {
      if (const auto* scan = dynamic_cast<const mrpt::obs::CObservation3DRangeScan*>(o.get())) {
        RgbdFrame frame = ToFrame(*scan, *frames_);
        frame.index = next_index_++;
        return frame;
      }
    }
    throw RecordingError(path_ + ": the file changed while it was read (fewer frames)");
  }

 private:
  std::unique_ptr<RawlogStream> frames_;
  int64_t next_index_ = 0;
};

}  // namespace

RecordingInfo RecordingInfoFor(const field::RobotConfig& robot) {
  RecordingInfo info;
  info.robot = robot.name;
  info.camera_model = robot.camera.model;
  info.width_px = robot.camera.width_px;
  info.height_px = robot.camera.height_px;
  info.fx = robot.camera.fx;
  info.fy = robot.camera.fy;
  info.cx = robot.camera.cx;
  info.cy = robot.camera.cy;
  if (robot.drive.encoder_ticks_per_rev > 0.0) {
    info.metres_per_tick = kPi * robot.drive.wheel_diameter_m / robot.drive.encoder_ticks_per_rev;
  }
  info.track_width_m = robot.drive.track_width_m;
  return info;
}

std::unique_ptr<RecordingWriter> OpenTumWriter(const std::string& dir, const RecordingInfo& info) {
  return std::make_unique<TumWriter>(dir, info);
}

std::unique_ptr<RecordingWriter> OpenRawlogWriter(const std::string& path,
                                                  const RecordingInfo& info) {
  return std::make_unique<RawlogWriter>(path, info);
}

std::unique_ptr<RecordingReader> OpenTumRecording(const std::string& dir,
                                                  const TumReaderOptions& options) {
  return std::make_unique<TumReader>(dir, options);
}

std::unique_ptr<RecordingReader> OpenRawlogRecording(const std::string& path) {
  return std::make_unique<RawlogReader>(path);
}

std::unique_ptr<RecordingReader> OpenRecording(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return OpenTumRecording(path);
  return OpenRawlogRecording(path);
}

}  // namespace slamo::platform
