#include "autonomy/experiments/recording_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "autonomy/loop/match_world.h"
#include "mapping/slam_o.h"
#include "platform/field_geometry.h"
#include "platform/recording.h"

namespace slamo::autonomy {
namespace {

using platform::Pose2D;

using platform::kPi;

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

  // SLAM-O at the first true pose (else the first red tile), over the surveyed markers.
  const Pose2D start =
      has_truth ? truth.front().pose : platform::StartPose(season, field::Alliance::kRed, 0);
  mapping::SlamO slam = SurveyedSlam(season, robot, start, /*relocalise=*/false);
  result.landmark_truth = platform::SurveyedMarkers(season);

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

    // The encoders' increment since the last frame; objects on every N-th frame.
    mapping::OdometryStep u{0.0, 0.0, 0.0};
    if (odometry) {
      while (next_encoder < encoders.size() && encoders[next_encoder].t_s <= rgbd->t_s)
        odometry->Update(encoders[next_encoder++]);
      u = mapping::OdometryIncrement(last_odometry, odometry->pose());
      last_odometry = odometry->pose();
    }
    const bool objects =
        options.object_every_n_frames > 0 && frame % options.object_every_n_frames == 0;
    const mapping::LandmarkFrame update = slam.Process(*rgbd, u, objects);
    if (update.gated) {
      ++result.rejected_frames;
    } else {
      replay_updates += static_cast<int>(std::count(update.outcomes.begin(), update.outcomes.end(),
                                                    mapping::UpdateOutcome::kUpdated));
    }

    const Pose2D t = has_truth ? TruthAt(truth, rgbd->t_s)
                               : Pose2D{slam.pose().x(), slam.pose().y(), slam.pose().z()};
    const Eigen::Vector3d truth_v(t.x_m, t.y_m, t.theta_rad);
    result.samples.push_back({rgbd->t_s, truth_v, slam.pose(), slam.pose_covariance(), has_truth});
    Snapshot s;
    s.t_s = rgbd->t_s;
    s.truth_known = has_truth;
    s.truth = t;
    s.estimate = slam.pose();
    s.covariance = slam.pose_covariance();
    s.action = "REPLAY";
    result.snapshots.push_back(std::move(s));
  }
  if (result.frames_taken > 0) close_replay(result.frames_taken - 1);

  // The confirmed objects: the report and the object map (no truth to match them against).
  for (const mapping::TrackedObject& o : slam.ConfirmedObjects()) {
    ObjectReport report;
    report.id = o.id;
    report.kind = o.kind;
    report.colour = o.colour;
    report.estimate_m = o.position_m;
    report.covariance = o.covariance;
    result.objects.push_back(report);
  }
  slam.UpdateMaps();
  if (!out_dir.empty()) slam.object_map().WriteBinary(out_dir + "/objects.bt");

  result.pose_ate_m = PoseAte(result.samples);
  for (int i = 0; i < slam.ekf().landmark_count(); ++i) {
    result.landmark_estimates.push_back(slam.ekf().landmark(i));
    result.landmark_covariances.push_back(slam.ekf().landmark_covariance(i));
  }
  result.deadline_s = t_last - t_first;
  result.duration_s = t_last - t_first;
  result.observe_s = t_last - t_first;
  result.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace slamo::autonomy
