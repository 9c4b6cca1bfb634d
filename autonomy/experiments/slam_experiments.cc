#include "autonomy/experiments/slam_experiments.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include <Eigen/Geometry>

#include "mapping/slam_o.h"
#include "platform/drive_script.h"
#include "platform/sim/sim_drive_script.h"
#include "platform/sim/sim_field.h"
#include "platform/sim/sim_renderer.h"

namespace slamo::autonomy {

using platform::Pose2D;

double WaypointsRun::AccumulatedError() const {
  double sum = 0.0;
  for (double e : stop_error_m) sum += e;
  return sum;
}

double WaypointsRun::OdometryAccumulatedError() const {
  double sum = 0.0;
  for (double e : odometry_error_m) sum += e;
  return sum;
}

field::SeasonConfig WaypointsField(const field::SeasonConfig& season, int landmarks) {
  field::SeasonConfig out = season;
  out.structures.clear();
  out.objects.clear();
  out.goals.clear();
  out.opponents.clear();
  out.landmarks.clear();
  // Markers 0.6 m apart on the far wall, distinct colours, unique ids.
  const char* colours[] = {"green", "magenta", "yellow"};
  const double ys[] = {0.0, 0.6, -0.6};
  for (int i = 0; i < landmarks && i < 3; ++i) {
    field::Landmark l;
    l.id = "L" + std::to_string(i);
    l.position_m = field::Vec2{season.HalfSize(), ys[landmarks == 2 ? i + 1 : i]};
    l.height_m = 0.40;
    l.size_m = 0.12;
    l.shape = field::LandmarkShape::kDisc;
    l.colour = colours[i];
    out.landmarks.push_back(l);
  }
  return out;
}

WaypointsRun RunWaypoints(const field::SeasonConfig& field, const field::RobotConfig& robot,
                          const WaypointsSetup& setup, uint64_t seed) {
  const std::vector<std::string> legs(setup.stops,
                                      "forward " + std::to_string(setup.stop_spacing_m));
  return RunRoute(field, robot, Pose2D{-1.2, 0.0, 0.0}, legs, setup, seed, false);
}

WaypointsRun RunRoute(const field::SeasonConfig& field, const field::RobotConfig& robot,
                      const Pose2D& start, const std::vector<std::string>& legs,
                      const WaypointsSetup& setup, uint64_t seed, bool objects) {
  WaypointsRun run;
  platform::SimField sim(field, robot, field::Alliance::kRed, seed, start);
  platform::SimRenderer renderer(field, robot.camera, platform::RenderOptions{}, seed);
  // SLAM-O as the thesis ran it: no plausibility gate, no relocalisation; the experiment's
  // own measurement model.
  mapping::SlamOOptions options;
  options.ekf = setup.ekf;
  if (setup.motion_from_robot) {
    options.ekf.motion = mapping::MotionNoiseFor(robot.odometry_noise);
    options.ekf.max_range_m = robot.camera.max_range_m;
  }
  options.stop_bias_covariance = setup.bias_covariance;
  options.white_covariance = setup.white_covariance;
  options.iterate_frames = setup.iterate;
  options.plausibility_gate = false;
  mapping::SlamOPrior prior;
  prior.pose = Eigen::Vector3d(start.x_m, start.y_m, start.theta_rad);
  prior.covariance = Eigen::Vector3d(1e-6, 1e-6, 1e-6).asDiagonal();
  if (setup.known_landmarks) {
    for (const Eigen::Vector3d& c : renderer.landmark_centres())
      prior.surveyed_markers.push_back(c.head<2>());
    prior.marker_sigma_m = setup.known_landmark_sigma_m;
  }
  mapping::SlamO slam(field, robot.camera, prior, options);
  std::map<int, double> first_range;
  const std::vector<platform::SimObject> initial_objects = sim.world().objects;
  platform::SimClock clock;
  const platform::DriveControllerOptions drive = platform::DriveControllerOptionsFor(robot.drive);
  Pose2D odometry = sim.drive().odometry_pose();
  // Encoder odometry starts at the origin; the start pose moves it onto the field.
  const Eigen::Isometry2d field_from_odometry =
      Eigen::Translation2d(start.x_m, start.y_m) *
      Eigen::Rotation2Dd(start.theta_rad - odometry.theta_rad) *
      Eigen::Translation2d(-odometry.x_m, -odometry.y_m);

  for (const std::string& leg : legs) {
    // Drive the leg; the filter predicts from the encoders' view of it.
    platform::RunDriveScript(platform::ParseDriveScript(leg), drive, &sim.drive(), &clock,
                             [&sim](double dt) { sim.Step(dt); });
    const Pose2D now = sim.drive().odometry_pose();
    slam.Predict(mapping::OdometryIncrement(odometry, now));
    odometry = now;
    const Pose2D truth = sim.robot_pose();
    const Eigen::Vector3d truth_v(truth.x_m, truth.y_m, truth.theta_rad);

    // Observe until the frame rule says stop.
    slam.BeginStop(setup.frames);
    std::vector<Eigen::Vector2d> errors;
    platform::RgbdFrame rgbd;
    for (;;) {
      rgbd = renderer.Render(sim.world(), truth, clock.NowS(), nullptr);
      const auto t0 = std::chrono::steady_clock::now();
      const mapping::LandmarkFrame update = slam.UpdateLandmarks(rgbd);
      run.compute_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      // Each measurement's error against the truth (the marker as drawn), where the marker is
      // known by its colour.
      for (const mapping::RangeBearing& z : update.measurements) {
        if (z.id < 0) continue;
        const Eigen::Vector2d expected =
            mapping::EkfSlam::Observe(truth_v, renderer.landmark_centres()[z.id].head<2>());
        errors.emplace_back(z.range_m - expected.x(),
                            platform::WrapAngleRad(z.bearing_rad - expected.y()));
      }
      ++run.frames;
      clock.Advance(1.0 / robot.camera.frame_rate_hz);
      if (!setup.iterate || !update.more_frames) break;
    }
    if (objects) {
      // Objects once per stop, from the best pose estimate; the confirmed ones go into the
      // OctoMap (objects that vanished leave it).
      slam.TrackObjects(rgbd, clock.NowS());
      for (const mapping::TrackedObject& o : slam.tracker().objects()) {
        if (!first_range.count(o.id))
          first_range[o.id] = (o.position_m - slam.pose().head<2>()).norm();
      }
      slam.UpdateMaps();
    }
    run.errors_by_stop.push_back(errors);
    const Eigen::Vector3d estimate = slam.pose();
    const Eigen::Vector2d odometry_in_field =
        field_from_odometry * Eigen::Vector2d(now.x_m, now.y_m);
    run.stop_error_m.push_back(std::hypot(estimate.x() - truth.x_m, estimate.y() - truth.y_m));
    run.odometry_error_m.push_back((odometry_in_field - truth_v.head<2>()).norm());
    run.stop_nees.push_back(mapping::PoseNees(truth_v, estimate, slam.pose_covariance()));
  }
  if (objects && !setup.map_out_dir.empty()) {
    slam.object_map().WriteBinary(setup.map_out_dir + "/objects.bt");
    slam.object_map().WriteColored(setup.map_out_dir + "/objects.ot");
  }
  // Score the tracked objects against where the objects really are now.
  for (const mapping::TrackedObject& o : slam.tracker().objects()) {
    WaypointsRun::ObjectResult r;
    r.tracked = o;
    r.confirmed = slam.tracker().Confirmed(o);
    r.first_range_m = first_range[o.id];
    double best = 0.5;
    for (size_t k = 0; k < sim.world().objects.size(); ++k) {
      const platform::SimObject& t = sim.world().objects[k];
      if (t.held || t.type->name != o.kind || t.colour != o.colour) continue;
      const double e = (t.center_m.head<2>() - o.position_m).norm();
      if (e < best) {
        best = e, r.matched = true, r.truth_m = t.center_m.head<2>(), r.error_m = e;
        r.truth_moved = (t.center_m - initial_objects[k].center_m).norm() > 0.01;
      }
    }
    run.objects.push_back(r);
  }
  return run;
}

void EstimateMeasurementNoise(const std::vector<WaypointsRun>& runs, Eigen::Vector2d* white,
                              Eigen::Vector2d* bias) {
  // One-way analysis of variance over stops: within-stop spread is the white part; the spread
  // of the stop means beyond what the white part explains is the bias.
  Eigen::Vector2d within = Eigen::Vector2d::Zero(), means_sq = Eigen::Vector2d::Zero();
  int within_n = 0, groups = 0;
  double mean_group_size = 0.0;
  for (const WaypointsRun& run : runs) {
    for (const std::vector<Eigen::Vector2d>& stop : run.errors_by_stop) {
      if (stop.size() < 2) continue;
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      for (const Eigen::Vector2d& e : stop) mean += e;
      mean /= static_cast<double>(stop.size());
      for (const Eigen::Vector2d& e : stop) within += (e - mean).cwiseAbs2();
      within_n += static_cast<int>(stop.size()) - 1;
      means_sq += mean.cwiseAbs2();
      mean_group_size += static_cast<double>(stop.size());
      ++groups;
    }
  }
  if (groups == 0 || within_n == 0) {
    *white = *bias = Eigen::Vector2d::Zero();
    return;
  }
  *white = within / within_n;
  mean_group_size /= groups;
  *bias = (means_sq / groups - *white / mean_group_size).cwiseMax(0.0);
}

}  // namespace slamo::autonomy
