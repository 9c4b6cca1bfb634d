#include "mapping/replay_log.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>

#include <mrpt/core/Clock.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/serialization/CArchive.h>

#include "platform/rawlog_guard.h"
#include "platform/rawlog_reader.h"

namespace slamo::mapping {
namespace {

// ---- Text format ----

class TextLogReader {
 public:
  TextLogReader(const std::string& path, const ReplayLogOptions& options)
      : path_(path), options_(options) {}

  ReplayLog Read() {
    std::ifstream in(path_);
    if (!in) throw ReplayLogError(path_ + ": cannot open");
    std::string line;
    for (line_number_ = 1; std::getline(in, line); ++line_number_) {
      const auto hash = line.find('#');
      if (hash != std::string::npos) line.erase(hash);
      std::istringstream words(line);
      fields_.clear();
      for (std::string word; words >> word;) fields_.push_back(word);
      if (fields_.empty()) continue;
      const std::string& tag = fields_[0];
      if (tag == "start") {
        ReadStart();
      } else if (tag == "odom") {
        ReadOdometry();
      } else if (tag == "obs") {
        ReadObservation();
      } else {
        throw Error("unknown tag `" + tag + "` (expected start, odom or obs)");
      }
    }
    return std::move(log_);
  }

 private:
  ReplayLogError Error(const std::string& what) const {
    return ReplayLogError(path_ + ":" + std::to_string(line_number_) + ": " + what);
  }

  void ExpectFields(std::initializer_list<size_t> counts, const char* usage) const {
    const size_t n = fields_.size();
    if (std::find(counts.begin(), counts.end(), n) != counts.end()) return;
    const size_t fewest = *std::min_element(counts.begin(), counts.end());
    throw Error(std::string(n < fewest ? "truncated line" : "too many fields") + ": expected `" +
                usage + "`, found " + std::to_string(n - 1) + " values after `" + fields_[0] + "`");
  }

  double Number(size_t index, const char* name) const {
    const std::string& token = fields_[index];
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size()) {
      throw Error(std::string(name) + " `" + token + "` is not a number");
    }
    if (!std::isfinite(value) || errno == ERANGE) {
      throw Error(std::string(name) + " `" + token + "` is not finite");
    }
    return value;
  }

  double Time() {
    const double t = Number(1, "time");
    if (t < last_t_) {
      throw Error("time goes backwards: " + fields_[1] + " s after " + std::to_string(last_t_) +
                  " s");
    }
    last_t_ = t;
    return t;
  }

  void ReadStart() {
    ExpectFields({4}, "start <x_m> <y_m> <theta_rad>");
    if (log_.start_pose || !log_.events.empty()) {
      throw Error("`start` must come once, before any odom or obs line");
    }
    log_.start_pose = Eigen::Vector3d(Number(1, "x_m"), Number(2, "y_m"), Number(3, "theta_rad"));
  }

  void ReadOdometry() {
    ExpectFields({4, 5, 8},
                 "odom <t_s> <v_mps> <w_radps>` or `odom <t_s> <dx_m> <dy_m> <dtheta_rad> "
                 "[<sigma_dx_m> <sigma_dy_m> <sigma_dtheta_rad>]");
    const double t = Time();
    OdometryStep step;
    if (fields_.size() == 4) {
      const double v = Number(2, "v_mps"), w = Number(3, "w_radps");
      const double dt = last_odometry_t_ ? t - *last_odometry_t_ : 0.0;
      step.dx_m = v * dt;
      step.dtheta_rad = w * dt;
    } else {
      step.dx_m = Number(2, "dx_m");
      step.dy_m = Number(3, "dy_m");
      step.dtheta_rad = Number(4, "dtheta_rad");
    }
    if (fields_.size() == 8) {
      const double sx = Number(5, "sigma_dx_m"), sy = Number(6, "sigma_dy_m"),
                   st = Number(7, "sigma_dtheta_rad");
      if (!(sx > 0.0 && sy > 0.0 && st > 0.0)) throw Error("odometry sigmas must be > 0");
      step.covariance = Eigen::Vector3d(sx * sx, sy * sy, st * st).asDiagonal();
    }
    last_odometry_t_ = t;
    log_.events.push_back({t, step});
  }

  void ReadObservation() {
    ExpectFields({5, 7},
                 "obs <t_s> <id> <range_m> <bearing_rad> [<sigma_range_m> <sigma_bearing_rad>]");
    const double t = Time();
    const double id = Number(2, "id");
    if (id != std::floor(id) || id < -1 || id > std::numeric_limits<int>::max()) {
      throw Error("id `" + fields_[2] + "` is not an integer >= -1");
    }
    RangeBearing z;
    z.id = static_cast<int>(id);
    z.range_m = Number(3, "range_m");
    z.bearing_rad = Number(4, "bearing_rad");
    if (z.range_m <= 0.0) throw Error("range_m `" + fields_[3] + "` is not positive");
    double sigma_range = options_.sigma_range_m, sigma_bearing = options_.sigma_bearing_rad;
    if (fields_.size() == 7) {
      sigma_range = Number(5, "sigma_range_m");
      sigma_bearing = Number(6, "sigma_bearing_rad");
      if (sigma_range <= 0.0 || sigma_bearing <= 0.0) throw Error("sigmas must be positive");
    }
    z.covariance =
        Eigen::Vector2d(sigma_range * sigma_range, sigma_bearing * sigma_bearing).asDiagonal();
    log_.events.push_back({t, z});
  }

  std::string path_;
  ReplayLogOptions options_;
  int line_number_ = 0;
  std::vector<std::string> fields_;
  double last_t_ = -std::numeric_limits<double>::infinity();
  std::optional<double> last_odometry_t_;
  ReplayLog log_;
};

// ---- MRPT rawlog ----

double ToSeconds(mrpt::Clock::time_point t) { return mrpt::Clock::toDouble(t); }

class RawlogReader {
 public:
  RawlogReader(const std::string& path, const ReplayLogOptions& options)
      : path_(path), options_(options) {}

  ReplayLog Read() {
    if (!std::ifstream(path_)) throw ReplayLogError(path_ + ": cannot open");
    try {
      records_ = std::make_unique<platform::RawlogRecords>(path_, options_.rawlog_check_timeout_s);
      while (const std::optional<platform::RawlogEntry> entry = records_->Next()) {
        if (entry->actions) {
          AddActions(*entry->actions);
        } else {
          AddObservation(*entry->observation);
        }
      }
    } catch (const platform::RawlogError& e) {
      throw ReplayLogError(e.what());
    }
    // Records carry their own stamps; put the events in time order.
    std::stable_sort(log_.events.begin(), log_.events.end(),
                     [](const LogEvent& a, const LogEvent& b) { return a.t_s < b.t_s; });
    return std::move(log_);
  }

 private:
  ReplayLogError Error(const std::string& what) const {
    return ReplayLogError(records_->Where(what));
  }

  // A stamp, or the last one seen when it is missing.
  double Stamp(mrpt::Clock::time_point t) {
    if (t != mrpt::Clock::time_point()) last_t_ = ToSeconds(t);
    return last_t_;
  }

  // The actions of one collection are alternative estimates of one motion: take the first.
  void AddActions(const mrpt::obs::CActionCollection& actions) {
    for (const auto& action : actions) {
      if (const auto* move = dynamic_cast<const mrpt::obs::CActionRobotMovement2D*>(action.get())) {
        AddMovement(*move);
        break;
      }
    }
  }

  // The movement's mean and, as MRPT's own EKF uses it, its pose PDF's covariance.
  void AddMovement(const mrpt::obs::CActionRobotMovement2D& move) {
    if (!move.poseChange) throw Error("a robot movement without a pose change");
    mrpt::math::CMatrixDouble33 c;
    mrpt::poses::CPose2D mean;
    move.poseChange->getCovarianceAndMean(c, mean);
    Eigen::Matrix3d covariance;
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) covariance(r, k) = c(r, k);
    if (!covariance.allFinite() || (covariance.diagonal().array() < 0.0).any()) {
      throw Error("a robot movement whose covariance is not finite or has a negative variance");
    }
    AddStep(move.timestamp, mean, 0.5 * (covariance + covariance.transpose()));
  }

  void AddStep(mrpt::Clock::time_point t, const mrpt::poses::CPose2D& d,
               std::optional<Eigen::Matrix3d> covariance = std::nullopt) {
    if (!std::isfinite(d.x()) || !std::isfinite(d.y()) || !std::isfinite(d.phi())) {
      throw Error("an odometry step that is not finite");
    }
    LogEvent event;
    event.t_s = Stamp(t);
    event.data = OdometryStep{d.x(), d.y(), d.phi(), std::move(covariance)};
    log_.events.push_back(std::move(event));
  }

  void AddObservation(const mrpt::obs::CObservation& observation) {
    if (const auto* odometry = dynamic_cast<const mrpt::obs::CObservationOdometry*>(&observation)) {
      // Absolute odometry: the step is the change since the previous reading.
      const mrpt::poses::CPose2D d =
          last_odometry_ ? odometry->odometry - *last_odometry_ : mrpt::poses::CPose2D();
      last_odometry_ = odometry->odometry;
      AddStep(odometry->timestamp, d);
    } else if (const auto* bearing_range =
                   dynamic_cast<const mrpt::obs::CObservationBearingRange*>(&observation)) {
      AddBearingRange(*bearing_range);
    }  // other sensors are not used here
  }

  // Each entry moved from the sensor to the robot centre: the point
  // p = s + range cos(pitch) (cos(a), sin(a)), a = yaw + sensor yaw, seen from the centre, with
  // the covariance propagated through J = dh/dp dp/d(range, yaw). The sensor's roll and pitch
  // are taken as zero (a planar robot).
  void AddBearingRange(const mrpt::obs::CObservationBearingRange& o) {
    const double t = Stamp(o.timestamp);
    if (std::isfinite(o.maxSensorDistance) && o.maxSensorDistance > 0.0) {
      log_.sensor_max_range_m =
          std::max(log_.sensor_max_range_m.value_or(0.0), double{o.maxSensorDistance});
    }
    const mrpt::poses::CPose3D& sensor = o.sensorLocationOnRobot;
    for (const auto& m : o.sensedData) {
      const double r = m.range * std::cos(m.pitch);
      const double a = m.yaw + sensor.yaw();
      const Eigen::Vector2d p(sensor.x() + r * std::cos(a), sensor.y() + r * std::sin(a));
      const double rho = p.norm();
      if (!std::isfinite(rho) || rho < 1e-6) continue;  // at the centre: no bearing
      Eigen::Matrix2d sensor_covariance;
      if (platform::StoredBool(o.validCovariances)) {
        sensor_covariance << m.covariance(0, 0), m.covariance(0, 1), m.covariance(1, 0),
            m.covariance(1, 1);
      } else {
        const double sr = o.sensor_std_range > 0 ? o.sensor_std_range : options_.sigma_range_m;
        const double sb = o.sensor_std_yaw > 0 ? o.sensor_std_yaw : options_.sigma_bearing_rad;
        sensor_covariance = Eigen::Vector2d(sr * sr, sb * sb).asDiagonal();
      }
      Eigen::Matrix2d dh_dp, dp_dz;
      dh_dp << p.x() / rho, p.y() / rho, -p.y() / (rho * rho), p.x() / (rho * rho);
      const double c = std::cos(m.pitch);
      dp_dz << c * std::cos(a), -r * std::sin(a), c * std::sin(a), r * std::cos(a);
      const Eigen::Matrix2d j = dh_dp * dp_dz;
      RangeBearing z;
      z.range_m = rho;
      z.bearing_rad = std::atan2(p.y(), p.x());
      z.covariance = j * sensor_covariance * j.transpose();
      z.id = m.landmarkID >= 0 ? m.landmarkID : -1;
      if (!z.covariance.allFinite()) throw Error("a bearing-range covariance that is not finite");
      log_.events.push_back({t, z});
    }
  }

  std::string path_;
  ReplayLogOptions options_;
  std::unique_ptr<platform::RawlogRecords> records_;
  double last_t_ = 0.0;
  std::optional<mrpt::poses::CPose2D> last_odometry_;
  ReplayLog log_;
};

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

ReplayLog ReadTextLog(const std::string& path, const ReplayLogOptions& options) {
  return TextLogReader(path, options).Read();
}

void WriteTextLog(const std::string& path, const ReplayLog& log) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out << "# slamo replay log: odom <t_s> <dx_m> <dy_m> <dtheta_rad>; obs <t_s> <id> <range_m> "
         "<bearing_rad> <sigma_range_m> <sigma_bearing_rad>\n";
  char line[256];
  if (log.start_pose) {
    std::snprintf(line, sizeof(line), "start %.12g %.12g %.12g\n", log.start_pose->x(),
                  log.start_pose->y(), log.start_pose->z());
    out << line;
  }
  for (const LogEvent& e : log.events) {
    if (e.is_odometry()) {
      const OdometryStep& u = e.odometry();
      if (u.covariance) {
        const Eigen::Vector3d sigma = u.covariance->diagonal().cwiseSqrt();
        std::snprintf(line, sizeof(line), "odom %.9f %.12g %.12g %.12g %.12g %.12g %.12g\n", e.t_s,
                      u.dx_m, u.dy_m, u.dtheta_rad, sigma.x(), sigma.y(), sigma.z());
      } else {
        std::snprintf(line, sizeof(line), "odom %.9f %.12g %.12g %.12g\n", e.t_s, u.dx_m, u.dy_m,
                      u.dtheta_rad);
      }
    } else {
      const RangeBearing& z = e.measurement();
      std::snprintf(line, sizeof(line), "obs %.9f %d %.12g %.12g %.12g %.12g\n", e.t_s, z.id,
                    z.range_m, z.bearing_rad, std::sqrt(z.covariance(0, 0)),
                    std::sqrt(z.covariance(1, 1)));
    }
    out << line;
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

ReplayLog ReadRawlog(const std::string& path, const ReplayLogOptions& options) {
  return RawlogReader(path, options).Read();
}

void WriteRawlog(const std::string& path, const ReplayLog& log) {
  mrpt::io::CFileGZOutputStream file;
  if (!file.open(path)) throw std::runtime_error(path + ": cannot open for writing");
  auto archive = mrpt::serialization::archiveFrom(file);
  // Alternating records: one action collection (one movement, or none before the first step),
  // then a sensory frame with the measurements up to the next step.
  const std::vector<LogEvent>& events = log.events;
  size_t k = 0;
  while (k < events.size()) {
    mrpt::obs::CActionCollection actions;
    if (events[k].is_odometry()) {
      const OdometryStep& u = events[k].odometry();
      const mrpt::poses::CPose2D mean(u.dx_m, u.dy_m, u.dtheta_rad);
      mrpt::obs::CActionRobotMovement2D move;
      move.timestamp = mrpt::Clock::fromDouble(events[k].t_s);
      move.estimationMethod = mrpt::obs::CActionRobotMovement2D::emOdometry;
      move.rawOdometryIncrementReading = mean;
      // The step's own covariance, else the thesis robot's motion model (MRPT needs one).
      const Eigen::Matrix3d q =
          u.covariance ? *u.covariance : MotionModelCovariance(MotionNoise{}, u);
      mrpt::math::CMatrixDouble33 covariance;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) covariance(r, c) = q(r, c);
      move.poseChange = mrpt::poses::CPosePDFGaussian::Create(mean, covariance);
      actions.insert(move);
      ++k;
    }
    mrpt::obs::CSensoryFrame frame;
    for (; k < events.size() && !events[k].is_odometry(); ++k) {
      const RangeBearing& z = events[k].measurement();
      auto observation = mrpt::obs::CObservationBearingRange::Create();
      observation->timestamp = mrpt::Clock::fromDouble(events[k].t_s);
      observation->sensorLabel = "slamo";
      observation->validCovariances = true;
      mrpt::obs::CObservationBearingRange::TMeasurement m;
      m.range = static_cast<float>(z.range_m);
      m.yaw = static_cast<float>(z.bearing_rad);
      m.pitch = 0.0f;
      m.landmarkID = z.id;
      m.covariance.setZero();
      m.covariance(0, 0) = z.covariance(0, 0);
      m.covariance(0, 1) = m.covariance(1, 0) = z.covariance(0, 1);
      m.covariance(1, 1) = z.covariance(1, 1);
      m.covariance(2, 2) = 1e-6;
      observation->sensedData.push_back(m);
      frame.insert(observation);
    }
    archive << actions << frame;
  }
}

ReplayLog ReadReplayLog(const std::string& path, const ReplayLogOptions& options) {
  bool rawlog = EndsWith(path, ".rawlog") || EndsWith(path, ".rawlog.gz");
  if (!rawlog) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ReplayLogError(path + ": cannot open");
    unsigned char magic[2] = {0, 0};
    in.read(reinterpret_cast<char*>(magic), 2);
    // gzip, or an uncompressed MRPT record (its first byte has the high bit set).
    rawlog = (magic[0] == 0x1f && magic[1] == 0x8b) || magic[0] >= 0x80;
  }
  return rawlog ? ReadRawlog(path, options) : ReadTextLog(path, options);
}

}  // namespace slamo::mapping
