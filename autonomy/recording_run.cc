#include "autonomy/recording_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "autonomy/match_world.h"
#include "mapping/ekf_slam.h"
#include "mapping/object_map.h"
#include "mapping/object_tracker.h"
#include "platform/field_geometry.h"
#include "platform/recording.h"
#include "vision/detector.h"

namespace slamo::autonomy {
namespace {

using platform::Pose2D;

constexpr double kPi = 3.14159265358979323846;

// As in match_world.cc: the per-stop measurement bias (range m, bearing rad).
const Eigen::Matrix2d kStopBias = Eigen::Vector2d(0.01 * 0.01, 0.005 * 0.005).asDiagonal();

mapping::OdometryStep Increment(const Pose2D& from, const Pose2D& to) {
  const double c = std::cos(from.theta_rad), s = std::sin(from.theta_rad);
  const double dx = to.x_m - from.x_m, dy = to.y_m - from.y_m;
  return {c * dx + s * dy, -s * dx + c * dy, platform::WrapAngleRad(to.theta_rad - from.theta_rad)};
}

// The ground truth at t_s, linear between the poses either side (held beyond the ends).
Pose2D TruthAt(const std::vector<platform::StampedPose>& truth, double t_s) {
  const auto after =
      std::lower_bound(truth.begin(), truth.end(), t_s,
                       [](const platform::StampedPose& p, double t) { return p.t_s < t; });
  if (after == truth.begin()) return truth.front().pose;
  if (after == truth.end()) return truth.back().pose;
  const platform::StampedPose& a = *(after - 1);
  const platform::StampedPose& b = *after;
  const double f = b.t_s > a.t_s ? (t_s - a.t_s) / (b.t_s - a.t_s) : 1.0;
  return {a.pose.x_m + f * (b.pose.x_m - a.pose.x_m), a.pose.y_m + f * (b.pose.y_m - a.pose.y_m),
          platform::WrapAngleRad(a.pose.theta_rad +
                                 f * platform::WrapAngleRad(b.pose.theta_rad - a.pose.theta_rad))};
}

Pose2D FirstRedStart(const field::SeasonConfig& season) {
  for (const field::StartTile& s : season.starts) {
    if (s.alliance == field::Alliance::kRed)
      return {s.center_m.x, s.center_m.y, s.heading_deg * kPi / 180.0};
  }
  throw std::invalid_argument(season.name + " has no red starting tile");
}

}  // namespace

MatchResult RunRecording(const field::SeasonConfig& season, const field::RobotConfig& robot,
                         const std::string& dir, const RecordingRunOptions& options,
                         const std::string& out_dir) {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::unique_ptr<platform::RecordingReader> reader = platform::OpenRecording(dir);
  const std::vector<platform::StampedPose>& truth = reader->ground_truth();
  const std::vector<platform::EncoderTicks>& encoders = reader->encoders();
  const bool has_truth = !truth.empty();

  MatchResult result;
  result.season = season.name;
  result.strategy = "recording";
  result.robot_io = "recording " + dir;
  result.truth_known = false;  // no points: nothing scores a recording
  result.frames = "every frame of " + dir;
  result.field = season;

  // The EKF at the first true pose (else the first red tile), over the surveyed markers.
  const Pose2D start = has_truth ? truth.front().pose : FirstRedStart(season);
  mapping::EkfOptions ekf_options;
  ekf_options.add_landmarks = false;
  mapping::EkfSlam ekf(Eigen::Vector3d(start.x_m, start.y_m, start.theta_rad),
                       Eigen::Vector3d(1e-4, 1e-4, std::pow(kPi / 180.0, 2)).asDiagonal(),
                       ekf_options);
  const std::vector<int> marker_id = AddSurveyedMarkers(season, &ekf);
  result.landmark_truth = platform::SurveyedMarkers(season);
  const vision::DetectorSetup landmark_detector =
      vision::LandmarkDetectorSetup(season, &robot.camera);
  const vision::DetectorSetup object_detector = vision::ObjectDetectorSetup(season, &robot.camera);

  // Wheel geometry: the recording's, else the robot file's.
  double metres_per_tick = reader->info().metres_per_tick;
  if (metres_per_tick <= 0.0 && robot.drive.encoder_ticks_per_rev > 0.0)
    metres_per_tick = kPi * robot.drive.wheel_diameter_m / robot.drive.encoder_ticks_per_rev;
  const double track_width_m =
      reader->info().track_width_m > 0.0 ? reader->info().track_width_m : robot.drive.track_width_m;
  std::optional<platform::EncoderOdometry> odometry;
  if (!encoders.empty() && metres_per_tick > 0.0 && track_width_m > 0.0)
    odometry.emplace(metres_per_tick, track_width_m, encoders.front());
  size_t next_encoder = 1;
  Pose2D last_odometry;

  mapping::ObjectTracker tracker;
  mapping::ObjectMap object_map(season);
  const double half_fov = std::atan(robot.camera.width_px / 2.0 / robot.camera.fx) - 0.05;
  int frame_in_stop = 0;
  double t_first = 0.0, t_last = 0.0;
  TimelineEntry replay;
  int replay_updates = 0, replay_first = 0;
  const auto close_replay = [&](int last_frame) {
    replay.end_s = t_last;
    replay.detail = "frames " + std::to_string(replay_first) + "-" + std::to_string(last_frame) +
                    ", " + std::to_string(replay_updates) + " landmark updates";
    result.timeline.push_back(replay);
  };

  while (options.max_frames <= 0 || result.frames_taken < options.max_frames) {
    std::optional<platform::RgbdFrame> rgbd = reader->Grab();
    if (!rgbd) break;
    const int frame = result.frames_taken++;
    if (frame == 0) t_first = rgbd->t_s;
    t_last = rgbd->t_s;
    if (frame == 0 || rgbd->t_s >= replay.t_s + 1.0) {
      if (frame > 0) close_replay(frame - 1);
      replay = TimelineEntry{};
      replay.t_s = rgbd->t_s;
      replay.action = "REPLAY";
      replay_updates = 0;
      replay_first = frame;
    }

    // Predict with the encoders' increment since the last frame.
    mapping::OdometryStep u{0.0, 0.0, 0.0};
    if (odometry) {
      while (next_encoder < encoders.size() && encoders[next_encoder].t_s <= rgbd->t_s)
        odometry->Update(encoders[next_encoder++]);
      u = Increment(last_odometry, odometry->pose());
      last_odometry = odometry->pose();
    }
    ekf.Predict(u);
    // Frames of a standing robot share the camera's bias (IteratedFrameCovariance).
    const bool still = std::hypot(u.dx_m, u.dy_m) < 1e-3 && std::abs(u.dtheta_rad) < 1e-3;
    frame_in_stop = still ? frame_in_stop + 1 : 1;

    std::vector<mapping::RangeBearing> measurements;
    for (const vision::Detection& d :
         vision::Detect(rgbd->colour, rgbd->depth_mm, landmark_detector, {})) {
      if (!d.measurement) continue;
      int index = -1;
      for (size_t i = 0; i < season.landmarks.size(); ++i) {
        if (season.landmarks[i].colour == d.colour) index = static_cast<int>(i);
      }
      if (index < 0) continue;
      mapping::RangeBearing z;
      z.range_m = d.measurement->range_m;
      z.bearing_rad = d.measurement->bearing_rad;
      z.covariance =
          mapping::IteratedFrameCovariance(d.measurement->covariance, kStopBias, frame_in_stop);
      z.id = marker_id[index];
      z.signature = d.colour;
      measurements.push_back(z);
    }
    // An update that jumps the pose beyond 3 sigma (at least 0.3 m) or off the field paired
    // wrongly: the frame is dropped (as in MatchWorld::Observe).
    const mapping::EkfSlam prior = ekf;
    const std::vector<mapping::UpdateOutcome> outcomes = ekf.UpdateFrame(measurements);
    const Eigen::Vector2d jump = ekf.pose().head<2>() - prior.pose().head<2>();
    const double allowed =
        std::max(0.3, 3.0 * std::sqrt(prior.pose_covariance().topLeftCorner<2, 2>().trace()));
    if (jump.norm() > allowed || std::abs(ekf.pose().x()) >= season.HalfSize() ||
        std::abs(ekf.pose().y()) >= season.HalfSize()) {
      ekf = prior;
      ++result.rejected_frames;
    } else {
      replay_updates += static_cast<int>(
          std::count(outcomes.begin(), outcomes.end(), mapping::UpdateOutcome::kUpdated));
    }

    // Objects on every N-th frame, placed through the pose estimate.
    if (options.object_every_n_frames > 0 && frame % options.object_every_n_frames == 0) {
      std::vector<mapping::ObjectObservation> seen;
      for (const vision::Detection& d :
           vision::Detect(rgbd->colour, rgbd->depth_mm, object_detector, {})) {
        if (!d.measurement) continue;
        seen.push_back({d.kind, d.colour, d.measurement->range_m, d.measurement->bearing_rad,
                        d.measurement->covariance});
      }
      const Eigen::Vector3d pose = ekf.pose();
      tracker.Update(pose, ekf.pose_covariance(), seen, rgbd->t_s, [&](const Eigen::Vector2d& p) {
        const Eigen::Vector2d z = mapping::EkfSlam::Observe(pose, p);
        return z.x() > 0.8 && z.x() < 3.5 && std::abs(z.y()) < half_fov;
      });
    }

    const Pose2D t = has_truth ? TruthAt(truth, rgbd->t_s)
                               : Pose2D{ekf.pose().x(), ekf.pose().y(), ekf.pose().z()};
    const Eigen::Vector3d truth_v(t.x_m, t.y_m, t.theta_rad);
    result.samples.push_back({rgbd->t_s, truth_v, ekf.pose(), ekf.pose_covariance(), has_truth});
    Snapshot s;
    s.t_s = rgbd->t_s;
    s.truth_known = has_truth;
    s.truth = t;
    s.estimate = ekf.pose();
    s.covariance = ekf.pose_covariance();
    s.action = "REPLAY";
    result.snapshots.push_back(std::move(s));
  }
  if (result.frames_taken > 0) close_replay(result.frames_taken - 1);

  // The confirmed objects: the report and the object map (no truth to match them against).
  std::vector<mapping::MappedObject> mapped;
  for (const mapping::TrackedObject& o : tracker.objects()) {
    if (!tracker.Confirmed(o)) continue;
    ObjectReport report;
    report.id = o.id;
    report.kind = o.kind;
    report.colour = o.colour;
    report.estimate_m = o.position_m;
    report.covariance = o.covariance;
    result.objects.push_back(report);
    const field::ObjectType* type = season.FindObjectType(o.kind);
    if (!type) continue;
    mapped.push_back({o.id, o.kind, o.colour,
                      Eigen::Vector3d(o.position_m.x(), o.position_m.y(), type->height_m / 2.0),
                      type->size_m / 2.0, type->height_m, o.confidence});
  }
  object_map.SetObjects(mapped);
  if (!out_dir.empty()) object_map.WriteBinary(out_dir + "/objects.bt");

  if (has_truth && !result.samples.empty()) {
    double sum_sq = 0.0;
    for (const PoseSample& s : result.samples)
      sum_sq += (s.estimate - s.truth).head<2>().squaredNorm();
    result.pose_ate_m = std::sqrt(sum_sq / result.samples.size());
  } else {
    result.pose_ate_m = std::numeric_limits<double>::quiet_NaN();
  }
  for (int i = 0; i < ekf.landmark_count(); ++i) {
    result.landmark_estimates.push_back(ekf.landmark(i));
    result.landmark_covariances.push_back(ekf.landmark_covariance(i));
  }
  result.deadline_s = t_last - t_first;
  result.duration_s = t_last - t_first;
  result.observe_s = t_last - t_first;
  result.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace slamo::autonomy
