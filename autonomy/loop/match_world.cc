#include "autonomy/loop/match_world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"
#include "platform/field_geometry.h"

namespace slamo::autonomy {
namespace {

using platform::DriveStep;
using platform::DriveStepKind;
using platform::Pose2D;

using platform::kPi;

DriveStep Turn(double degrees) {
  return {DriveStepKind::kTurn, degrees, "turn " + std::to_string(degrees)};
}
DriveStep Forward(double metres) {
  return {DriveStepKind::kDrive, metres,
          (metres >= 0 ? "forward " : "back ") + std::to_string(std::abs(metres))};
}

// Frames taken to check an arrival, and how close counts as arrived.
// Cut the motors this long before the target at the current speed: the slow creep of the last
// centimetres (PWM deadband) costs more time than the coast-in error SLAM-O corrects (the
// thesis robot's, which has no motor model in its file).
constexpr double kStopLead_s = 0.15;
constexpr double kMinSpeed_mps = 0.06;

// How far the robot backs off a goal after a release.
constexpr double kBackOff_m = 0.15;

// The robot as driven in a match: at its match speed (or `speed_mps`), turning in place at
// that wheel speed, which is what the drive controller does.
field::RobotConfig MatchRobot(const field::RobotConfig& robot, double speed_mps) {
  field::RobotConfig out = robot;
  out.drive.cruise_speed_mps = speed_mps > 0.0 ? std::min(speed_mps, robot.drive.max_speed_mps)
                                               : robot.drive.match_speed_mps;
  out.drive.turn_rate_dps =
      out.drive.cruise_speed_mps / (robot.drive.track_width_m / 2.0) * 180.0 / kPi;
  return out;
}

}  // namespace

double PoseConsistency::HonestFraction() const {
  return updates ? static_cast<double>(in_band + below) / updates
                 : std::numeric_limits<double>::quiet_NaN();
}

PoseConsistency PoseConsistencyOf(const std::vector<PoseSample>& samples) {
  PoseConsistency c;
  std::tie(c.band_low, c.band_high) = mapping::NeesBand(3, 1);
  for (const PoseSample& s : samples) {
    if (!s.truth_known) continue;
    ++c.updates;
    const double nees = mapping::PoseNees(s.truth, s.estimate, s.covariance);
    if (nees < c.band_low) {
      ++c.below;
    } else if (nees > c.band_high) {
      ++c.above;
    } else {
      ++c.in_band;
    }
  }
  return c;
}

double PoseAte(const std::vector<PoseSample>& samples) {
  std::vector<Eigen::Vector2d> truth, estimate;
  for (const PoseSample& s : samples) {
    if (!s.truth_known) continue;
    truth.push_back(s.truth.head<2>());
    estimate.push_back(s.estimate.head<2>());
  }
  if (truth.empty()) return std::numeric_limits<double>::quiet_NaN();
  return mapping::PairedTrajectoryError(truth, estimate, /*align=*/false).rmse_m;
}

CameraView MakeCameraView(const platform::RgbdFrame& frame, const mapping::ObjectFrame& objects,
                          double t_s, int width) {
  CameraView view;
  view.t_s = t_s;
  const cv::Mat& colour = frame.colour;
  if (colour.empty() || width <= 0) return view;
  const double scale = static_cast<double>(width) / colour.cols;
  const int height = std::max(1, static_cast<int>(std::lround(colour.rows * scale)));
  cv::resize(colour, view.image, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  for (const mapping::ObjectFrame::Seen& s : objects.detections) {
    const vision::Detection& d = s.detection;
    CameraView::Seen seen;
    seen.box =
        cv::Rect2d(d.box.x * scale, d.box.y * scale, d.box.width * scale, d.box.height * scale);
    seen.kind = d.kind;
    seen.colour = d.colour;
    if (d.measurement) seen.range_m = d.measurement->range_m;
    seen.use = s.use;
    view.seen.push_back(std::move(seen));
  }
  return view;
}

mapping::SlamO SurveyedSlam(const field::SeasonConfig& field, const field::RobotConfig& robot,
                            const platform::Pose2D& start, bool relocalise, bool adaptive) {
  mapping::SlamOPrior prior;
  prior.pose = Eigen::Vector3d(start.x_m, start.y_m, start.theta_rad);
  prior.covariance = Eigen::Vector3d(1e-4, 1e-4, std::pow(kPi / 180.0, 2)).asDiagonal();
  prior.surveyed_markers = platform::SurveyedMarkers(field);
  prior.marker_sigma_m = 1e-3;
  // The filter from the robot file: its odometry's noise, its camera's range.
  mapping::SlamOOptions options;
  options.ekf.motion = mapping::MotionNoiseFor(robot.odometry_noise);
  options.ekf.max_range_m = robot.camera.max_range_m;
  options.ekf.add_landmarks = false;
  // Its camera's per-stop bias, shared by a stop's frames.
  const double bias_bearing_rad = robot.camera.stop_bias_bearing_sigma_deg * kPi / 180.0;
  options.stop_bias_covariance =
      Eigen::Vector2d(robot.camera.stop_bias_range_sigma_m * robot.camera.stop_bias_range_sigma_m,
                      bias_bearing_rad * bias_bearing_rad)
          .asDiagonal();
  options.ekf.adaptive.enabled = adaptive;
  options.relocalise = relocalise;
  return mapping::SlamO(field, robot.camera, prior, options);
}

double DefaultCheckSpacing(const MatchSetup& setup) {
  return setup.moving_frame_period_s > 0.0 && setup.steer_on_estimate ? 2.4 : 1.2;
}

MatchWorld::MatchWorld(std::unique_ptr<RobotIo> io, const field::SeasonConfig& season,
                       const field::RobotConfig& robot, const MatchSetup& setup, uint64_t seed,
                       bool perceive)
    : field_(season),
      robot_(MatchRobot(robot, setup.drive_speed_mps)),
      setup_(setup),
      perceive_(perceive),
      deadline_s_(season.rules.autonomous_s),
      io_(std::move(io)),
      slam_(SurveyedSlam(field_, robot_,
                         platform::StartPose(field_, setup.alliance, setup.start_index), true,
                         setup.adaptive_filter)),
      travel_(robot_.drive) {
  if (setup_.check_spacing_m < 0.0) setup_.check_spacing_m = DefaultCheckSpacing(setup_);
  const Pose2D start_pose = platform::StartPose(field_, setup.alliance, setup.start_index);
  io_->Start(field_, robot_, start_pose);
  markers_ = platform::SurveyedMarkers(field_);
  // The preload: loaded by hand, so its kind and colour are known.
  if (const std::optional<IntakeItem> preload = io_->Preload()) {
    strategy::ObjectBelief held;
    held.id = -1;
    held.kind = preload->kind;
    held.colour = preload->colour;
    held_ = held;
  }
  odometry_ = io_->OdometryPose();
  if (setup_.gyro) {
    const std::optional<double> heading = io_->GyroHeadingRad();
    if (!heading) {
      throw std::invalid_argument(
          "this robot has no yaw gyro (" + io_->Describe() +
          "): run without gyro-aided odometry (MatchSetup::gyro = false, --no-gyro)");
    }
    gyro_heading_ = *heading;
  }
  odometry_scale_ = io_->OdometryScale();
  drive_options_ = platform::DriveControllerOptionsFor(robot_.drive);
  drive_options_.hard_deadline_s = deadline_s_;
  drive_options_.timeout_margin_s = 2.0;  // a blocked step gives up quickly in a match
  // Do not wait for the last encoder tick of a coasting wheel: the odometry keeps counting
  // it into the next step.
  drive_options_.max_settle_s = 0.4;
  // A robot file with its motors' time constant: a step ends once the residual coast is under
  // one encoder tick (DriveControllerOptions::settle_ticks), not at the coast's last tick. On
  // the V5 robot that ends a 5-degree turn 0.10 s sooner and a 0.3 m drive 0.20 s sooner
  // (DriveScriptSettleTest); a 15 s period has 15-25 steps.
  if (robot_.drive.slip) {
    drive_options_.settle_s = robot_.drive.slip->motor_time_constant_s;
    drive_options_.settle_ticks = 1;
  }
  // A robot file with its own motor model: cut one motor time constant early, which is how far
  // (x speed) the wheels coast once cut. The V5 robot's 3 m/s^2 ramps reach the last 0.135 m at
  // full speed, so the thesis robot's 0.15 s lead stopped every approach ~9 cm short, and its
  // releases landed outside the Over Under and Push Back goals.
  drive_options_.stop_lead_s =
      robot_.drive.slip ? robot_.drive.slip->motor_time_constant_s : kStopLead_s;
  // And a turn's cut timed at the wheels' measured speed, which trails the ramp down: V5 turns
  // at match speed ended 3.9 degrees from the asked angle on average, now 1.5 (by the
  // encoders; DriveScriptSettleTest, without the settle rule above), and in the matches an
  // overshoot cost a correcting turn of 0.15-0.25 s.
  drive_options_.lead_on_measured_speed = robot_.drive.slip.has_value();
  drive_options_.min_speed_mps = kMinSpeed_mps;

  planning::PlannerOptions planner_options;
  planner_options.stop_spacing_m = 0.0;
  planner_ = std::make_unique<planning::Planner>(robot_, planner_options);
  planning::SeedPlanners(seed);
  planner_->SetMap(slam_.obstacle_map());
  travel_.SetPlanner(*planner_);
  travel_.min_leg_m = perceive && setup.arrival_fixes > 0 ? setup.arrival_tolerance_m : 0.0;
  travel_.reverse_max_m = setup.reverse_max_m;

  context_.season = &field_;
  context_.robot = &robot_;
  context_.alliance = setup.alliance;
  context_.frame_rate_hz = robot_.camera.frame_rate_hz;
  context_.travel_time_s = [this](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    return travel_.TravelTimeS(from, to);
  };
  context_.is_clear = [this](const Eigen::Vector2d& p) { return planner_->IsClear(p); };
  RecordSample();
  MaybeSnapshot(true);
}

const char* ScenarioName(Scenario scenario) {
  return scenario == Scenario::kDisturbed ? "disturbed" : "nominal";
}

Scenario ParseScenario(const std::string& name) {
  if (name == "nominal") return Scenario::kNominal;
  if (name == "disturbed") return Scenario::kDisturbed;
  throw std::invalid_argument("unknown scenario \"" + name + "\": expected nominal or disturbed");
}

strategy::Belief MatchWorld::Belief() const {
  strategy::Belief b;
  b.now_s = now_s();
  b.deadline_s = deadline_s_;
  b.pose = slam_.pose();
  b.pose_covariance = slam_.pose_covariance();
  b.held = held_;
  for (const mapping::TrackedObject& o : slam_.ConfirmedObjects(picked_ids_))
    b.objects.push_back({o.id, o.kind, o.colour, o.position_m, o.covariance, o.confidence});
  return b;
}

double MatchWorld::ObjectRadius(const std::string& kind) const {
  const field::ObjectType* type = field_.FindObjectType(kind);
  return type ? type->size_m / 2.0 : 0.1;
}

void MatchWorld::Advance(double dt_s) {
  const double before_s = now_s();
  io_->Advance(dt_s);
  if (io_->MotorsDriven()) {
    last_motion_s_ = now_s();
    if (before_s >= deadline_s_) overrun_s_ += now_s() - before_s;
  }
}

void MatchWorld::RecordSample() {
  PoseSample sample{now_s(), Eigen::Vector3d::Zero(), slam_.pose(), slam_.pose_covariance(), false};
  if (const std::optional<Pose2D> t = io_->TruePose()) {
    sample.truth_known = true;
    sample.truth = Eigen::Vector3d(t->x_m, t->y_m, t->theta_rad);
  }
  samples_.push_back(sample);
}

void MatchWorld::MaybeSnapshot(bool force) {
  if (setup_.snapshot_period_s <= 0.0) return;
  if (!force && now_s() < next_snapshot_s_) return;
  next_snapshot_s_ = now_s() + setup_.snapshot_period_s;
  Snapshot s;
  s.t_s = now_s();
  const std::optional<Pose2D> truth = io_->TruePose();
  s.truth_known = truth.has_value();
  if (truth) s.truth = *truth;
  // Between filter updates the estimate is the last one moved by the encoders since.
  mapping::OdometryStep u = mapping::OdometryIncrement(odometry_, io_->OdometryPose());
  u.dx_m *= odometry_scale_;
  u.dy_m *= odometry_scale_;
  s.estimate = mapping::EkfSlam::Move(slam_.pose(), u, nullptr, nullptr);
  s.covariance = slam_.pose_covariance();
  if (const std::optional<std::vector<TrueObject>> truth = io_->TrueObjects()) {
    for (const TrueObject& o : *truth) {
      if (o.held) continue;
      s.truth_objects.push_back({o.center_m.head<2>(), o.colour, o.radius_m});
    }
  }
  s.tracked = Belief().objects;
  s.action = action_label_;
  s.points = Points().value_or(0);
  s.camera = camera_view_;
  snapshots_.push_back(std::move(s));
}

void MatchWorld::KeepView(const platform::RgbdFrame& frame, const mapping::ObjectFrame& objects) {
  if (setup_.snapshot_period_s <= 0.0) return;  // no replay: nothing to keep
  camera_view_ = std::make_shared<const CameraView>(MakeCameraView(frame, objects, now_s()));
}

bool MatchWorld::Drive(const std::vector<DriveStep>& steps,
                       const std::optional<Eigen::Vector2d>& leg_end, bool reverse) {
  platform::DriveBodyLink body = DriveLinkFor(*io_, robot_);
  // Turns closed on the gyro (opt-in): a robot file with an inertial sensor, gyro-aided.
  if (setup_.gyro_turns && setup_.gyro && robot_.imu) {
    body.gyro = [this]() { return io_->GyroHeadingRad(); };
  }
  // Frames on the move: on straight drives, one every moving_frame_period_s (at least the
  // camera's latency, so that a frame's exposure never comes before the last prediction) while
  // the body holds its heading.
  const bool straight = std::any_of(steps.begin(), steps.end(), [](const DriveStep& s) {
    return s.kind == platform::DriveStepKind::kDrive;
  });
  const bool look_moving = perceive_ && straight && setup_.moving_frame_period_s > 0.0;
  const double frame_period_s = std::max(setup_.moving_frame_period_s, robot_.camera.latency_s);
  double last_frame_s = now_s();
  Pose2D last_odometry = io_->OdometryPose();
  // The readings of the last camera latency (and one before), to pair a frame with, from the
  // drive's start on.
  std::deque<OdometryReading> recent;
  std::optional<platform::DriveCorrection> correction;  // from the last frame, not yet applied
  if (look_moving && robot_.camera.latency_s > 0.0) {
    recent.push_back({now_s(), last_odometry, setup_.gyro ? io_->GyroHeadingRad() : std::nullopt});
  }
  body.advance = [&, this](double dt) {
    Advance(dt);
    MaybeSnapshot();
    if (!look_moving) return;
    const Pose2D odometry = io_->OdometryPose();
    if (robot_.camera.latency_s > 0.0) {
      recent.push_back({now_s(), odometry, setup_.gyro ? io_->GyroHeadingRad() : std::nullopt});
      while (recent.size() > 2 && recent[1].t_s < now_s() - robot_.camera.latency_s) {
        recent.pop_front();
      }
    }
    const double turned_deg =
        std::abs(platform::WrapAngleRad(odometry.theta_rad - last_odometry.theta_rad)) * 180.0 /
        kPi;
    const bool moved =
        std::hypot(odometry.x_m - last_odometry.x_m, odometry.y_m - last_odometry.y_m) > 1e-4;
    last_odometry = odometry;
    if (!moved || turned_deg > setup_.moving_frame_max_turn_dps * dt) return;
    if (now_s() + 1e-9 < last_frame_s + frame_period_s) return;
    if (now_s() >= deadline_s_) return;
    if (!ObserveMoving(recent)) return;  // none: the next period tries again
    last_frame_s = now_s();
    if (!leg_end || !setup_.steer_on_estimate) return;
    const Eigen::Vector3d est = slam_.pose();
    const Eigen::Vector2d d = *leg_end - est.head<2>();
    const double sign = reverse ? -1.0 : 1.0;
    const double change = platform::WrapAngleRad(std::atan2(sign * d.y(), sign * d.x()) - est.z());
    // What is left along the heading driven so far: re-aimed, the drive stops short of the leg
    // end by d (1 - cos(change)) (at most 6 %, at 20 degrees), for the next frame or the
    // arrival to finish. Driving all of d instead measured worse (200 seeds, paired: Over
    // Under disturbed -0.175 +- 0.130, 4 seeds better, 15 worse; the rest within +-0.04).
    const double remaining = d.norm() * std::cos(change);
    if (std::abs(change) > setup_.steer_max_deg * kPi / 180.0) return;
    if (remaining < setup_.steer_min_remaining_m) return;
    correction = platform::DriveCorrection{change, remaining / odometry_scale_};
  };
  body.correct = [&correction]() {
    std::optional<platform::DriveCorrection> c = correction;
    correction.reset();
    return c;
  };
  const int moving_before = moving_frames_;
  const Eigen::Vector3d start = slam_.pose();
  const std::vector<platform::DriveStepResult> results =
      platform::RunDriveScript(steps, drive_options_, body);
  if (std::any_of(steps.begin(), steps.end(),
                  [](const DriveStep& s) { return s.kind != platform::DriveStepKind::kWait; })) {
    frames_at_rest_ = 0;
  }
  PredictFromOdometry();
  const bool done =
      std::all_of(results.begin(), results.end(), [](const platform::DriveStepResult& r) {
        return r.status == platform::DriveStepStatus::kDone;
      });
  // Not after a blocked step: wheels slipping against an object carry the estimate past it.
  // Objects the footprint met on the way were pushed: not where they were believed (on a
  // drive that goes straight; a turn's slip is no way).
  if (done) {
    slam_.ForgetObjectsUnderRobot(robot_.length_m, robot_.width_m,
                                  straight ? std::optional<Eigen::Vector3d>(start) : std::nullopt);
  }
  if (moving_frames_ > moving_before) UpdateMaps();  // what the frames on the way saw
  RecordSample();
  return done;
}

void MatchWorld::PredictFromOdometry() {
  PredictTo(io_->OdometryPose(), setup_.gyro ? io_->GyroHeadingRad() : std::nullopt);
}

void MatchWorld::PredictTo(const Pose2D& odometry, const std::optional<double>& gyro) {
  mapping::OdometryStep u = mapping::OdometryIncrement(odometry_, odometry);
  u.dx_m *= odometry_scale_;
  u.dy_m *= odometry_scale_;
  if (setup_.gyro) {
    // Gyro-aided odometry: the turn comes from the gyro, which sees the body turn; the
    // encoders' turn is wrong whenever a wheel slips (and a turn blocked by a pinned object
    // spins the wheels without turning the robot at all).
    const double heading = gyro.value_or(gyro_heading_);
    u.dtheta_rad = platform::WrapAngleRad(heading - gyro_heading_);
    gyro_heading_ = heading;
  }
  slam_.Predict(u);
  odometry_ = odometry;
}

bool MatchWorld::ObserveMoving(const std::deque<OdometryReading>& recent) {
  std::optional<platform::RgbdFrame> captured = io_->CaptureReady();
  if (!captured) return false;
  // The frame shows the robot camera.latency_s ago: the filter is moved to that instant by
  // the readings about it (interpolated), updated, and moved on to now.
  const double exposed_s = now_s() - robot_.camera.latency_s;
  if (recent.size() < 2 || exposed_s >= recent.back().t_s) {
    PredictFromOdometry();
  } else {
    size_t k = 1;
    while (k + 1 < recent.size() && recent[k].t_s < exposed_s) ++k;
    const OdometryReading& a = recent[k - 1];
    const OdometryReading& b = recent[k];
    const double f = std::clamp((exposed_s - a.t_s) / (b.t_s - a.t_s), 0.0, 1.0);
    const Pose2D odometry{a.odometry.x_m + f * (b.odometry.x_m - a.odometry.x_m),
                          a.odometry.y_m + f * (b.odometry.y_m - a.odometry.y_m),
                          a.odometry.theta_rad + f * platform::WrapAngleRad(b.odometry.theta_rad -
                                                                            a.odometry.theta_rad)};
    std::optional<double> gyro;
    if (a.gyro && b.gyro) gyro = *a.gyro + f * platform::WrapAngleRad(*b.gyro - *a.gyro);
    PredictTo(odometry, gyro);
  }
  mapping::FrameSelectionOptions one = setup_.frames;
  one.rule = mapping::FrameRule::kFixed;
  one.fixed_frames = one.max_frames = 1;
  slam_.BeginStop(one);
  slam_.UpdateLandmarks(*captured);
  KeepView(*captured, slam_.TrackObjects(*captured, now_s()));
  ++frames_;
  ++moving_frames_;
  PredictFromOdometry();  // on to now
  RecordSample();
  return true;
}

void MatchWorld::Wait(double seconds) { Drive({DriveStep{DriveStepKind::kWait, seconds, "wait"}}); }

int MatchWorld::Observe(int max_frames) {
  if (!perceive_ || max_frames <= 0) return 0;
  mapping::FrameSelectionOptions rule = setup_.frames;
  rule.max_frames = std::min(rule.max_frames, max_frames);
  rule.fixed_frames = std::min(rule.fixed_frames, max_frames);
  rule.gmm_max_frames = std::min(rule.gmm_max_frames, max_frames);
  rule.gmm_min_frames = std::min(rule.gmm_min_frames, max_frames);
  slam_.BeginStop(rule);
  if (frames_at_rest_ == 0) look_start_s_ = now_s();
  platform::RgbdFrame rgbd;
  int taken = 0;
  bool last_tracked = false;
  int missed_frames = 0;
  const double dt = 1.0 / robot_.camera.frame_rate_hz;
  while (now_s() < deadline_s_) {
    std::optional<platform::RgbdFrame> captured = io_->Capture();
    if (!captured) {
      // No frame from the camera (RobotIo::Capture waited for one): try again a frame period
      // later, and give up the look after three misses in a row.
      if (++missed_frames >= 3) break;
      Advance(dt);
      continue;
    }
    missed_frames = 0;
    rgbd = std::move(*captured);
    const mapping::LandmarkFrame update = slam_.UpdateLandmarks(rgbd);
    // Objects on the first frame and the last: two sightings confirm an object, so a single
    // stop can map what it sees; a false detection rarely survives both.
    if (taken == 0) KeepView(rgbd, slam_.TrackObjects(rgbd, now_s()));
    last_tracked = taken == 0;
    ++taken;
    ++frames_;
    Advance(dt);
    RecordSample();
    MaybeSnapshot();
    if (!update.more_frames) break;
  }
  if (taken == 0) return 0;
  if (!last_tracked) KeepView(rgbd, slam_.TrackObjects(rgbd, now_s()));
  UpdateMaps();
  frames_at_rest_ += taken;
  return taken;
}

void MatchWorld::UpdateMaps() {
  // Objects narrower than half the robot are pushed aside by it (the simulator's contact
  // rule; VEX robots sweep small balls): they are mapped but not planned around. Larger ones
  // are obstacles: pushed, they pin against others and stop the robot. An obstacle has no
  // clearance margin: grazing a ball only nudges it, and the full margin would close the
  // approaches to the goals the balls lie around.
  mapping::ObstacleRule obstacles;
  obstacles.min_size_m = setup_.pushable_fraction * robot_.width_m;
  obstacles.shrink_m = planner_->inflation_radius_m();
  obstacles.grow_m = robot_.width_m / 2.0;
  slam_.UpdateMaps(picked_ids_, obstacles);
  planner_->SetMap(slam_.obstacle_map());
  travel_.SetPlanner(*planner_);
}

bool MatchWorld::TurnTo(double heading_rad) {
  const double turn = platform::WrapAngleRad(heading_rad - slam_.pose().z());
  if (std::abs(turn) < 2.0 * kPi / 180.0) return true;
  return Drive({Turn(turn * 180.0 / kPi)});
}

bool MatchWorld::PathClear(const std::vector<Eigen::Vector2d>& path) const {
  // A robot standing inside the clearance margin (after a close approach) may leave it: the
  // stretch that starts blocked is not held against the path.
  bool leaving = !path.empty() && !planner_->IsClear(path.front());
  for (size_t i = 1; i < path.size(); ++i) {
    const double length = (path[i] - path[i - 1]).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(length / 0.02)));
    for (int k = 0; k <= n; ++k) {
      const bool clear =
          planner_->IsClear(path[i - 1] + (path[i] - path[i - 1]) * (static_cast<double>(k) / n));
      if (clear) leaving = false;
      if (!clear && !leaving) return false;
    }
  }
  return true;
}

void MatchWorld::MergeCloseCorners(std::vector<Eigen::Vector2d>* corners) const {
  if (setup_.corner_merge_m <= 0.0) return;
  std::vector<Eigen::Vector2d>& c = *corners;
  // Over Under disturbed seed 37 (V5 robot): the first drive stopped to turn at two corners
  // 0.06 m apart, where the planner's path bent round one inflated disc in two steps.
  for (size_t i = 1; i + 2 < c.size();) {
    if ((c[i + 1] - c[i]).norm() >= setup_.corner_merge_m) {
      ++i;
      continue;
    }
    std::vector<Eigen::Vector2d> candidates;
    const Eigen::Vector2d in = c[i] - c[i - 1], out = c[i + 2] - c[i + 1];
    const double cross = in.x() * out.y() - in.y() * out.x();
    const Eigen::Vector2d middle = 0.5 * (c[i] + c[i + 1]);
    if (std::abs(cross) > 1e-9) {
      const Eigen::Vector2d w = c[i + 1] - c[i - 1];
      const Eigen::Vector2d meet = c[i - 1] + in * ((w.x() * out.y() - w.y() * out.x()) / cross);
      // Nearly parallel legs meet far away, and legs that meet behind the leg before or past
      // the leg after would make a detour, not a merge.
      if ((meet - middle).norm() <= 2.0 * setup_.corner_merge_m &&
          (meet - c[i - 1]).dot(in) > 0.0 && (c[i + 2] - meet).dot(out) > 0.0)
        candidates.push_back(meet);
    }
    candidates.insert(candidates.end(), {middle, c[i], c[i + 1]});
    bool merged = false;
    for (const Eigen::Vector2d& q : candidates) {
      if (PathClear({c[i - 1], q, c[i + 2]})) {
        c[i] = q;
        c.erase(c.begin() + static_cast<std::ptrdiff_t>(i) + 1);
        merged = true;
        break;
      }
    }
    if (!merged) ++i;
  }
}

bool MatchWorld::Navigate(const Eigen::Vector3d& target, double stop_spacing_m, int frames_per_stop,
                          double budget_s) {
  const double give_up_s = budget_s > 0.0 ? now_s() + budget_s : deadline_s_;
  const auto out_of_time = [&]() { return now_s() >= std::min(give_up_s, deadline_s_); };
  // The error an arrival leaves: its tolerance, or what the next action's aim absorbs.
  const double arrival_accepts =
      std::max(setup_.arrival_tolerance_m, setup_.arrival_slack_m >= 0.0
                                               ? setup_.arrival_slack_m
                                               : 0.5 * setup_.strategy_options.approach_margin_m);
  for (int attempt = 0; attempt < 3 && !out_of_time(); ++attempt) {
    Eigen::Vector3d pose = slam_.pose();
    if (!planner_->IsClear(pose.head<2>())) {
      // After a close approach the robot stands inside the clearance margin: back out, along
      // its heading, to the nearest clear point behind it (else ahead of it; else turn away
      // first).
      const Eigen::Vector2d back(-std::cos(pose.z()), -std::sin(pose.z()));
      double distance = 0.0;
      for (double d = 0.05; d <= 0.8 + 1e-9; d += 0.05) {
        if (planner_->IsClear(pose.head<2>() + d * back)) {
          distance = d + 0.03;
          break;
        }
      }
      // None behind (a robot that starts inside the margin with its back to the wall): the
      // nearest clear point ahead.
      double ahead = 0.0;
      for (double d = 0.05; distance <= 0.0 && d <= 0.8 + 1e-9; d += 0.05) {
        if (planner_->IsClear(pose.head<2>() - d * back)) {
          ahead = d + 0.03;
          break;
        }
      }
      if (distance > 0.0) {
        Drive({Forward(-distance / odometry_scale_)});
      } else if (ahead > 0.0) {
        Drive({Forward(ahead / odometry_scale_)});
      } else {
        Drive({Turn(180.0), Forward(0.3 / odometry_scale_)});
      }
      pose = slam_.pose();
    }
    planning::PlanRequest request;
    request.start_x_m = pose.x();
    request.start_y_m = pose.y();
    request.start_heading_deg = pose.z() * 180.0 / kPi;
    request.goal_x_m = target.x();
    request.goal_y_m = target.y();
    request.goal_heading_deg = target.z() * 180.0 / kPi;
    request.planner = setup_.planner;
    request.time_budget_s = setup_.plan_budget_s;
    request.max_iterations = setup_.plan_iterations;
    planning::PlanResult plan = planner_->Plan(request);
    if (plan.status != planning::PlanStatus::kSolved) {
      return false;
    }
    // Fewer corners, fewer stops to turn: keep only the corners a straight, clear segment
    // cannot skip (the planner's taut paths bend in small steps round the inflated discs).
    std::vector<Eigen::Vector2d> corners = {plan.path.front()};
    for (size_t from = 0; from + 1 < plan.path.size();) {
      size_t to = plan.path.size() - 1;
      while (to > from + 1 && !PathClear({plan.path[from], plan.path[to]})) --to;
      corners.push_back(plan.path[to]);
      from = to;
    }
    MergeCloseCorners(&corners);
    plan.path = corners;
    paths_.push_back(plan.path);
    // Stops: the strategy's, or (perceiving) a quick look every setup_.check_spacing_m, which
    // catches obstacles the map did not have and the wheels' slip.
    const double spacing = stop_spacing_m > 0.0                        ? stop_spacing_m
                           : perceive_ && setup_.check_spacing_m > 0.0 ? setup_.check_spacing_m
                                                                       : 0.0;
    const int stop_frames = stop_spacing_m > 0.0 ? frames_per_stop : setup_.correction_frames;
    // The path's corners, with stops added along each leg every `spacing` (a stop never cuts
    // a corner: the legs between stops are the plan's own).
    std::vector<Eigen::Vector2d> waypoints;
    for (size_t k = 1; k < plan.path.size(); ++k) {
      const Eigen::Vector2d a = plan.path[k - 1], b = plan.path[k];
      const int pieces =
          spacing > 0.0 ? std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing))) : 1;
      for (int j = 1; j <= pieces; ++j)
        waypoints.push_back(a + (b - a) * (static_cast<double>(j) / pieces));
    }
    bool replan = false;
    double unseen_m =
        setup_.check_spacing_m;  // driven since the last look (look before the first leg)
    for (size_t i = 0; i < waypoints.size() && !replan; ++i) {
      if (out_of_time()) return false;
      // Each segment is aimed from the latest estimate: SLAM-O corrects the encoders' drift.
      Eigen::Vector3d est = slam_.pose();
      Eigen::Vector2d d = waypoints[i] - est.head<2>();
      // The last leg, when the arrival is checked, is not worth its turn if shorter than the
      // arrival's tolerance (on Push Back a 3 cm leg to the side cost two quarter turns and
      // 1.5 s): the arrival accepts that error.
      const bool checked_last = i + 1 == waypoints.size() && perceive_ && setup_.arrival_fixes > 0;
      if (d.norm() < (checked_last ? setup_.arrival_tolerance_m : 0.02)) continue;
      // A short leg behind the robot is driven backwards: two half-turns saved (the camera
      // then looks where the robot comes from, so only for legs up to reverse_max_m).
      const bool reverse = [&]() {
        const double facing = platform::WrapAngleRad(std::atan2(d.y(), d.x()) - est.z());
        return std::abs(facing) > kPi / 2.0 && d.norm() <= setup_.reverse_max_m;
      }();
      const double sign = reverse ? -1.0 : 1.0;
      const auto leg_turn = [&](const Eigen::Vector2d& leg, const Eigen::Vector3d& from) {
        return platform::WrapAngleRad(std::atan2(sign * leg.y(), sign * leg.x()) - from.z());
      };
      const double turn = leg_turn(d, est);
      // The thesis's stops come at every stop point; the quick looks once per
      // setup_.check_spacing_m.
      const bool stop_here = stop_spacing_m > 0.0 || unseen_m + 1e-6 >= setup_.check_spacing_m;
      unseen_m = stop_here ? d.norm() : unseen_m + d.norm();
      if (spacing > 0.0 && stop_frames > 0 && stop_here) {
        // Face the segment, look along it, and plan again if the map now blocks the rest.
        if (std::abs(turn) > 3.0 * kPi / 180.0) Drive({Turn(turn * 180.0 / kPi)});
        Observe(stop_frames);
        // The planned legs ahead (the leg from here is the plan's, up to the drift the
        // estimate just corrected).
        std::vector<Eigen::Vector2d> rest = {i == 0 ? pose.head<2>() : waypoints[i - 1]};
        rest.insert(rest.end(), waypoints.begin() + static_cast<long>(i), waypoints.end());
        if (!PathClear(rest)) {
          replan = true, ++replans_;
          break;
        }
        est = slam_.pose();
        d = waypoints[i] - est.head<2>();
        const double again = leg_turn(d, est);
        std::vector<DriveStep> steps;
        if (std::abs(again) > 2.0 * kPi / 180.0) steps.push_back(Turn(again * 180.0 / kPi));
        steps.push_back(Forward(sign * d.norm() / odometry_scale_));
        Drive(steps, waypoints[i], reverse);
      } else {
        Drive({Turn(turn * 180.0 / kPi), Forward(sign * d.norm() / odometry_scale_)}, waypoints[i],
              reverse);
      }
    }
    if (replan) continue;
    // Arrival, closed on SLAM-O: observe, and drive the rest while the estimate is off.
    for (int fix = 0; perceive_ && fix < setup_.arrival_fixes && !out_of_time(); ++fix) {
      Observe(std::max(frames_per_stop, setup_.correction_frames));
      const Eigen::Vector2d d = target.head<2>() - slam_.pose().head<2>();
      if (d.norm() < arrival_accepts) break;
      const double turn = platform::WrapAngleRad(std::atan2(d.y(), d.x()) - slam_.pose().z());
      if (std::abs(turn) > kPi / 2) {  // overshot: back up rather than turn round
        Drive({Turn(platform::WrapAngleRad(turn + kPi) * 180.0 / kPi),
               Forward(-d.norm() / odometry_scale_)});
      } else {
        Drive({Turn(turn * 180.0 / kPi), Forward(d.norm() / odometry_scale_)});
      }
    }
    TurnTo(target.z());
    return (slam_.pose().head<2>() - target.head<2>()).norm() < 0.12;
  }
  return false;
}

bool MatchWorld::Push(const Eigen::Vector3d& target, double back_m) {
  const Eigen::Vector3d est = slam_.pose();
  const Eigen::Vector2d d = target.head<2>() - est.head<2>();
  const double turn = platform::WrapAngleRad(std::atan2(d.y(), d.x()) - est.z());
  Drive({Turn(turn * 180.0 / kPi), Forward(d.norm() / odometry_scale_)});
  const bool reached = (slam_.pose().head<2>() - target.head<2>()).norm() < 0.12;
  const double back = back_m >= 0.0 ? back_m : d.norm();
  if (now_s() < deadline_s_ && back > 0.0) Drive({Forward(-back / odometry_scale_)});
  return reached;
}

bool MatchWorld::Pick(const strategy::Action& action) {
  const strategy::Belief before = Belief();
  strategy::ObjectBelief target;
  target.position_m = action.target.head<2>();
  bool believed = false;
  pick_skipped_ = false;
  for (const strategy::ObjectBelief& o : before.objects) {
    if (o.id == action.object_id) target = o, believed = true;
  }
  if (perceive_ && frames_at_rest_ == 0) {
    Observe(std::max(action.frames, setup_.correction_frames));
    believed = false;
    for (const strategy::ObjectBelief& o : Belief().objects) {
      if (o.id == action.object_id) target = o, believed = true;
    }
  }
  // The look since the robot came to rest here, from where the camera sees the target whole
  // (StrategyOptions::pick_in_view): not seen in it, it is not there (pushed away, or never
  // was): no approach. Lost from the map since the strategy chose it: the same.
  if (perceive_ && setup_.strategy_options.pick_in_view && action.object_id >= 0) {
    bool gone = !believed;
    for (const mapping::TrackedObject& o : slam_.ConfirmedObjects(picked_ids_)) {
      if (o.id != action.object_id || o.last_seen_s >= look_start_s_) continue;
      if (frames_at_rest_ > 0 && slam_.WholeInView(slam_.pose(), o)) {
        slam_.ForgetObject(o.id);
        UpdateMaps();
        gone = true;
      }
    }
    if (gone) {
      pick_skipped_ = true;
      return false;
    }
  }
  const double r =
      ObjectRadius(target.kind.empty() ? field_.object_types.front().name : target.kind);
  const Eigen::Vector3d est = slam_.pose();
  const Eigen::Vector2d d = target.position_m - est.head<2>();
  const double turn = platform::WrapAngleRad(std::atan2(d.y(), d.x()) - est.z());
  const double forward = d.norm() - strategy::PickDistance(robot_, r);
  std::vector<DriveStep> steps = {Turn(turn * 180.0 / kPi)};
  if (std::abs(forward) > 0.01) steps.push_back(Forward(forward / odometry_scale_));
  const bool approached = Drive(steps);
  if (now_s() >= deadline_s_) return false;
  const bool room = !held_;  // a full intake takes nothing, whatever lies in its mouth
  const std::optional<IntakeItem> picked = io_->Pick(target);
  frames_at_rest_ = 0;  // what lay in front of the intake has changed
  Wait(robot_.intake.pick_s);
  if (!picked) {
    // Nothing in the intake's mouth: what was believed there is not (the intake's reach and
    // the robot's width, as SimField::Pick and a real roller intake take). Not after a
    // blocked approach: the wheels slipping carry the estimate past where the robot stands.
    if (approached && room) {
      slam_.ForgetObjectsUnderRobot(robot_.length_m, robot_.width_m, std::nullopt,
                                    robot_.intake.reach_m);
      // The target itself, whatever the errors' margin above: the intake was aimed at it and
      // found nothing (if it lies near, a look maps it again).
      if (action.object_id >= 0) slam_.ForgetObject(action.object_id);
    }
    UpdateMaps();
    return false;
  }
  // The intake knows what it took (kind and colour from its own sensor, or taken on trust).
  // Another kind or colour than the target's: the intake took a neighbour, and the target is
  // still on the field (the tracker lets the one taken fade from view).
  const bool took_target =
      target.kind.empty() || (picked->kind == target.kind && picked->colour == target.colour);
  strategy::ObjectBelief held;
  held.id = took_target ? action.object_id : -1;
  held.kind = picked->kind;
  held.colour = picked->colour;
  held_ = held;
  if (took_target && action.object_id >= 0) picked_ids_.push_back(action.object_id);
  UpdateMaps();
  return took_target;
}

bool MatchWorld::Score(const strategy::Action& action) {
  if (!held_) return false;
  const double r = ObjectRadius(held_->kind);
  const double margin = setup_.strategy_options.approach_margin_m;
  if (frames_at_rest_ == 0) Observe(setup_.correction_frames);
  const field::Goal& goal = field_.goals[action.goal_index];
  // A goal on a movable object (a mobile goal's stake): where the strategy saw it.
  const Eigen::Vector2d drop =
      goal.on_object.empty()
          ? strategy::DropTarget(field_, robot_, action.goal_index, action.target, r, margin)
          : action.goal_m;
  const Eigen::Vector3d est = slam_.pose();
  const Eigen::Vector2d d = drop - est.head<2>();
  const double turn = platform::WrapAngleRad(std::atan2(d.y(), d.x()) - est.z());
  // Into a goal structure the bumper stops just short of its edge (a tube's: of its mouth).
  double forward = d.norm() - strategy::ReleaseDistance(robot_, r);
  if (goal.kind == field::GoalKind::kGoal) {
    const double half = goal.entry == field::Goal::Entry::kEnds ? 0.0
                        : !goal.on_object.empty() ? platform::CarrierRadius(field_, goal)
                                                  : platform::GoalHalfSize(goal);
    forward = d.norm() - (half + robot_.length_m / 2.0 + 0.015);
  }
  std::vector<DriveStep> steps = {Turn(turn * 180.0 / kPi)};
  if (std::abs(forward) > 0.01) steps.push_back(Forward(forward / odometry_scale_));
  Drive(steps);
  if (now_s() >= deadline_s_) return false;
  const std::optional<ReleaseOutcome> released = io_->Release(action.goal_index);
  Wait(robot_.intake.release_s);
  // Back off the goal: pressed against it, the robot could not turn (its corners sweep the
  // structure) and its wheels would spin in place.
  if (now_s() < deadline_s_) Drive({Forward(-kBackOff_m / odometry_scale_)});
  if (!released) return false;
  held_.reset();
  return released->goal_index && *released->goal_index == action.goal_index;
}

bool MatchWorld::Drop(const strategy::Action& action) {
  if (!held_) return false;
  TurnTo(action.target.z());
  if (now_s() >= deadline_s_) return false;
  // No back-off as after a score: nothing presses against the robot here.
  const std::optional<ReleaseOutcome> released = io_->Release(-1);
  frames_at_rest_ = 0;  // the object now lies in front of the robot
  Wait(robot_.intake.release_s);
  if (!released) return false;
  held_.reset();
  return true;
}

void MatchWorld::IdleToDeadline() {
  if (now_s() < deadline_s_) Wait(deadline_s_ - now_s());
  MaybeSnapshot(true);
}

}  // namespace slamo::autonomy
