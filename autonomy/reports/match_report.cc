#include "autonomy/reports/match_report.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "autonomy/reports/field_picture.h"
#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"

namespace slamo::autonomy {
namespace {

const cv::Scalar kTruth(30, 30, 30);
const cv::Scalar kEstimate(0, 120, 255);        // orange
const cv::Scalar kPath(200, 120, 0);            // blue
const cv::Scalar kAttemptInside(40, 160, 40);   // green
const cv::Scalar kAttemptOutside(30, 30, 220);  // red
const cv::Scalar kNotUsed(150, 150, 150);       // grey: detections not tracked

cv::Scalar Palette(const field::SeasonConfig& season, const std::string& name) {
  const auto it = season.colours.find(name);
  if (it == season.colours.end()) return cv::Scalar(128, 128, 128);
  return cv::Scalar(it->second.b, it->second.g, it->second.r);
}

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

void Text(cv::Mat& image, const std::string& text, cv::Point at, double scale = 0.5,
          cv::Scalar colour = cv::Scalar(20, 20, 20)) {
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// The 3-sigma ellipse of a position covariance, drawn `exaggerate` times its size.
void Ellipse(FieldCanvas& canvas, const Eigen::Vector2d& centre, const Eigen::Matrix2d& cov,
             double exaggerate, cv::Scalar colour) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  const Eigen::Vector2d axes = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt() * 3.0 * exaggerate;
  const Eigen::Vector2d major = eig.eigenvectors().col(1);
  const double angle_deg = -std::atan2(major.y(), major.x()) * 180.0 / M_PI;  // image y is down
  cv::ellipse(
      canvas.image(), canvas.ToPixel(centre.x(), centre.y()),
      cv::Size(std::max(1, canvas.ToPixels(axes.y())), std::max(1, canvas.ToPixels(axes.x()))),
      angle_deg, 0, 360, colour, 1, cv::LINE_AA);
}

void Robot(FieldCanvas& canvas, const Eigen::Vector3d& pose, const field::RobotConfig* robot,
           double length, double width, cv::Scalar colour, int thickness) {
  (void)robot;
  const double c = std::cos(pose.z()), s = std::sin(pose.z());
  std::vector<cv::Point> corners;
  for (const auto& [lx, ly] : {std::pair{1, 1}, {1, -1}, {-1, -1}, {-1, 1}}) {
    const double x = lx * length / 2, y = ly * width / 2;
    corners.push_back(canvas.ToPixel(pose.x() + c * x - s * y, pose.y() + s * x + c * y));
  }
  cv::polylines(canvas.image(), corners, true, colour, thickness, cv::LINE_AA);
  cv::line(canvas.image(), canvas.ToPixel(pose.x(), pose.y()),
           canvas.ToPixel(pose.x() + c * length / 2, pose.y() + s * length / 2), colour, thickness,
           cv::LINE_AA);
}

FieldCanvas BaseCanvas(const MatchResult& result, double px_per_m) {
  FieldPictureOptions options;
  options.draw_objects = false;
  options.px_per_m = px_per_m;
  FieldCanvas canvas(result.field, options);
  canvas.DrawFloorAndWalls();
  canvas.DrawStructures();
  canvas.DrawGoals();
  canvas.DrawLandmarks();
  canvas.DrawScaleBar();
  return canvas;
}

}  // namespace

nlohmann::json AttemptJson(const AttemptCheck& a) {
  return {{"t_s", a.t_s},
          {"action", a.action},
          {"ok", a.ok},
          {"estimate_m", {a.estimate_m.x(), a.estimate_m.y()}},
          {"truth_m", {a.truth_m.x(), a.truth_m.y()}},
          {"error_m", a.error_m},
          {"three_sigma_m", a.three_sigma_m},
          {"inside_three_sigma", a.Inside()},
          {"kind", a.kind},
          {"colour", a.colour},
          {"goal_index", a.goal_index},
          {"aim_m", {a.aim_m.x(), a.aim_m.y()}},
          {"range_m", a.range_m},
          {"bearing_rad", a.bearing_rad},
          {"target_truth_id", a.target_truth_id},
          {"target_error_m", a.target_error_m},
          {"outcome", a.outcome},
          {"taken_kind", a.taken_kind},
          {"taken_colour", a.taken_colour}};
}

AttemptCheck AttemptFromJson(const nlohmann::json& j) {
  AttemptCheck a;
  a.t_s = j.at("t_s").get<double>();
  a.action = j.at("action").get<std::string>();
  a.ok = j.at("ok").get<bool>();
  a.estimate_m = {j.at("estimate_m").at(0).get<double>(), j.at("estimate_m").at(1).get<double>()};
  a.truth_m = {j.at("truth_m").at(0).get<double>(), j.at("truth_m").at(1).get<double>()};
  a.error_m = j.at("error_m").get<double>();
  a.three_sigma_m = j.at("three_sigma_m").get<double>();
  a.kind = j.at("kind").get<std::string>();
  a.colour = j.at("colour").get<std::string>();
  a.goal_index = j.at("goal_index").get<int>();
  a.aim_m = {j.at("aim_m").at(0).get<double>(), j.at("aim_m").at(1).get<double>()};
  a.range_m = j.at("range_m").get<double>();
  a.bearing_rad = j.at("bearing_rad").get<double>();
  a.target_truth_id = j.at("target_truth_id").get<int>();
  a.target_error_m = j.at("target_error_m").get<double>();
  a.outcome = j.at("outcome").get<std::string>();
  a.taken_kind = j.value("taken_kind", "");
  a.taken_colour = j.value("taken_colour", "");
  return a;
}

nlohmann::json ReportJson(const MatchResult& r) {
  nlohmann::json j;
  j["season"] = r.season;
  j["seed"] = r.seed;
  j["strategy"] = r.strategy;
  j["frames"] = r.frames;
  j["scenario"] = r.scenario;
  j["robot_io"] = r.robot_io;
  j["truth_known"] = r.truth_known;
  if (r.truth_known) {
    j["points"] = r.points;
    j["points_start"] = r.points_start;
    j["points_gained"] = r.points - r.points_start;
  } else {  // no referee on hardware
    j["points"] = nullptr;
    j["points_start"] = nullptr;
    j["points_gained"] = nullptr;
  }
  j["duration_s"] = r.duration_s;
  j["deadline_s"] = r.deadline_s;
  j["overrun_s"] = r.overrun_s;
  j["refused_actions"] = r.refused;
  if (std::isnan(r.pose_ate_m)) {
    j["pose_ate_m"] = nullptr;
  } else {
    j["pose_ate_m"] = r.pose_ate_m;
  }
  if (r.consistency.updates > 0) {
    // The filter against the truth at every update, and at every pick and score attempt.
    const PoseConsistency& c = r.consistency;
    j["nees"] = {{"band", {c.band_low, c.band_high}},
                 {"updates", c.updates},
                 {"in_band", c.in_band},
                 {"conservative", c.below},
                 {"overconfident", c.above},
                 {"in_band_or_conservative_fraction", c.HonestFraction()}};
    j["updates"] = nlohmann::json::array();
    for (const PoseSample& s : r.samples) {
      if (!s.truth_known) continue;
      j["updates"].push_back({{"t_s", s.t_s},
                              {"error_m", (s.estimate.head<2>() - s.truth.head<2>()).norm()},
                              {"sigma_m", std::sqrt(s.covariance(0, 0) + s.covariance(1, 1))},
                              {"nees", mapping::PoseNees(s.truth, s.estimate, s.covariance)}});
    }
  }
  if (r.truth_known) {
    j["attempts"] = nlohmann::json::array();
    int inside = 0;
    for (const AttemptCheck& a : r.attempts) {
      inside += a.Inside();
      j["attempts"].push_back(AttemptJson(a));
    }
    j["attempts_inside_three_sigma"] = inside;
  }
  if (!r.board.empty()) j["board"] = r.board;
  j["seconds"] = {{"observe", r.observe_s},
                  {"drive", r.drive_s},
                  {"pick_score", r.score_s},
                  {"idle", r.idle_s}};
  j["frames_taken"] = r.frames_taken;
  j["moving_frames"] = r.moving_frames;
  j["replans"] = r.replans;
  j["relocalisations"] = r.relocalisations;
  j["rejected_frames"] = r.rejected_frames;
  j["odometry_scale"] = r.odometry_scale;
  j["wall_s"] = r.wall_s;
  j["objects"] = nlohmann::json::array();
  for (const ObjectReport& o : r.objects) {
    nlohmann::json e = {{"id", o.id},
                        {"class", o.kind},
                        {"colour", o.colour},
                        {"est_x", o.estimate_m.x()},
                        {"est_y", o.estimate_m.y()},
                        {"matched", o.matched}};
    if (o.matched) {
      e["true_x"] = o.truth_m.x();
      e["true_y"] = o.truth_m.y();
      e["error_m"] = o.error_m;
    } else {
      e["true_x"] = nullptr;
      e["true_y"] = nullptr;
    }
    j["objects"].push_back(e);
  }
  j["timeline"] = nlohmann::json::array();
  for (const TimelineEntry& t : r.timeline) {
    j["timeline"].push_back({{"t_s", t.t_s},
                             {"end_s", t.end_s},
                             {"action", t.action},
                             {"detail", t.detail},
                             {"ok", t.ok},
                             {"expected_s", t.expected_s}});
  }
  return j;
}

namespace {
void WriteTumPoses(const MatchResult& result, const std::string& path, bool truth) {
  std::vector<mapping::TimedPose> poses;
  for (const PoseSample& s : result.samples) {
    const Eigen::Vector3d& p = truth ? s.truth : s.estimate;
    poses.push_back({s.t_s, p.x(), p.y(), p.z()});
  }
  mapping::WriteTumTrajectory(path, poses, truth ? "ground truth" : "SLAM-O estimate");
}
}  // namespace

void WriteTum(const MatchResult& result, const std::string& path) {
  WriteTumPoses(result, path, false);
}
void WriteTruthTum(const MatchResult& result, const std::string& path) {
  WriteTumPoses(result, path, true);
}

cv::Mat DrawMatchMap(const MatchResult& r) {
  FieldCanvas canvas = BaseCanvas(r, 200.0);
  cv::Mat& image = canvas.image();
  // Objects as they lie at the end (truth: outlines), and SLAM-O's estimates (crosses).
  if (!r.snapshots.empty()) {
    for (const Snapshot::Object& o : r.snapshots.back().truth_objects) {
      cv::circle(image, canvas.ToPixel(o.position_m.x(), o.position_m.y()),
                 std::max(2, canvas.ToPixels(o.radius_m)), Palette(r.field, o.colour), 2,
                 cv::LINE_AA);
    }
  }
  for (const auto& path : r.paths) {
    for (size_t i = 1; i < path.size(); ++i) {
      cv::line(image, canvas.ToPixel(path[i - 1].x(), path[i - 1].y()),
               canvas.ToPixel(path[i].x(), path[i].y()), kPath, 2, cv::LINE_AA);
    }
  }
  for (const ObjectReport& o : r.objects) {
    const cv::Point p = canvas.ToPixel(o.estimate_m.x(), o.estimate_m.y());
    cv::drawMarker(image, p, Palette(r.field, o.colour), cv::MARKER_TILTED_CROSS, 14, 2);
    if (o.matched)
      cv::line(image, p, canvas.ToPixel(o.truth_m.x(), o.truth_m.y()), cv::Scalar(0, 0, 0), 1);
    Ellipse(canvas, o.estimate_m, o.covariance, 1.0, Palette(r.field, o.colour));
  }
  for (size_t i = 0; i < r.landmark_estimates.size(); ++i) {
    cv::drawMarker(image, canvas.ToPixel(r.landmark_estimates[i].x(), r.landmark_estimates[i].y()),
                   kEstimate, cv::MARKER_CROSS, 16, 2);
  }
  // Trajectories: truth from the snapshots (dense), the estimate as the robot had it.
  for (size_t i = 1; i < r.snapshots.size(); ++i) {
    const Snapshot& a = r.snapshots[i - 1];
    const Snapshot& b = r.snapshots[i];
    if (a.truth_known && b.truth_known)
      cv::line(image, canvas.ToPixel(a.truth.x_m, a.truth.y_m),
               canvas.ToPixel(b.truth.x_m, b.truth.y_m), kTruth, 2, cv::LINE_AA);
    cv::line(image, canvas.ToPixel(a.estimate.x(), a.estimate.y()),
             canvas.ToPixel(b.estimate.x(), b.estimate.y()), kEstimate, 2, cv::LINE_AA);
  }
  // Pick and score attempts: the believed 3-sigma around the estimate, the true position.
  for (const AttemptCheck& a : r.attempts) {
    const cv::Scalar colour = a.Inside() ? kAttemptInside : kAttemptOutside;
    cv::circle(image, canvas.ToPixel(a.estimate_m.x(), a.estimate_m.y()),
               std::max(2, canvas.ToPixels(a.three_sigma_m)), colour, 2, cv::LINE_AA);
    cv::drawMarker(image, canvas.ToPixel(a.truth_m.x(), a.truth_m.y()), colour,
                   a.Inside() ? cv::MARKER_CROSS : cv::MARKER_TILTED_CROSS, 12, 2);
  }
  double last_t = -1e9;
  for (const PoseSample& s : r.samples) {
    if (s.t_s - last_t < 5.0) continue;
    last_t = s.t_s;
    Ellipse(canvas, s.estimate.head<2>(), s.covariance.topLeftCorner<2, 2>(), 1.0, kEstimate);
  }
  // Legend and figures on the right.
  const cv::Point origin = canvas.ToPixel(r.field.HalfSize(), r.field.HalfSize());
  int x = origin.x + 60, y = origin.y + 10;  // clear of the right wall's landmark labels
  const auto line = [&](const std::string& text, cv::Scalar colour = cv::Scalar(20, 20, 20)) {
    Text(image, text, cv::Point(x, y += 22), 0.45, colour);
  };
  line(r.season + "  seed " + std::to_string(r.seed) + "  strategy " + r.strategy);
  if (r.truth_known) {
    line("points " + std::to_string(r.points) + " (start " + std::to_string(r.points_start) +
         ", +" + std::to_string(r.points - r.points_start) + ")");
  } else {
    line("on " + r.robot_io.substr(0, 40));
    line("points unknown (no referee off the simulator)");
  }
  line("deadline " + Fixed(r.deadline_s, 0) + " s, last motion " + Fixed(r.duration_s, 1) + " s");
  line("overrun " + Fixed(r.overrun_s, 2) + " s, refused actions " + std::to_string(r.refused));
  if (!std::isnan(r.pose_ate_m))
    line("pose ATE " + Fixed(r.pose_ate_m * 100, 1) + " cm over " +
         std::to_string(r.samples.size()) + " updates");
  if (r.consistency.updates > 0)
    line("NEES in band or below: " + Fixed(100.0 * r.consistency.HonestFraction(), 0) + " %");
  line("observe " + Fixed(r.observe_s, 1) + " s, drive " + Fixed(r.drive_s, 1) + " s,");
  line("  pick/score " + Fixed(r.score_s, 1) + " s, idle " + Fixed(r.idle_s, 1) + " s");
  y += 12;
  if (!std::isnan(r.pose_ate_m)) line("true trajectory", kTruth);
  line("estimated trajectory, 3-sigma ellipses", kEstimate);
  line("planned paths", kPath);
  line("objects: circles truth at the end,");
  line("  crosses estimates (3-sigma ellipses),");
  line("  black line: error");
  line("landmarks: disc truth, orange + estimate", kEstimate);
  if (!r.attempts.empty()) {
    line("picks/scores: + true position, circle 3-sigma,");
    line("  green: error inside it", kAttemptInside);
    line("  red x: error outside it", kAttemptOutside);
  }
  return image;
}

cv::Mat DrawSnapshot(const MatchResult& r, size_t k) {
  const Snapshot& s = r.snapshots.at(k);
  FieldCanvas canvas = BaseCanvas(r, 110.0);
  cv::Mat& image = canvas.image();
  for (const Snapshot::Object& o : s.truth_objects) {
    cv::circle(image, canvas.ToPixel(o.position_m.x(), o.position_m.y()),
               std::max(2, canvas.ToPixels(o.radius_m)), Palette(r.field, o.colour), cv::FILLED,
               cv::LINE_AA);
  }
  for (const strategy::ObjectBelief& o : s.tracked) {
    cv::drawMarker(image, canvas.ToPixel(o.position_m.x(), o.position_m.y()), cv::Scalar(0, 0, 0),
                   cv::MARKER_TILTED_CROSS, 10, 2);
  }
  for (size_t i = 1; i <= k; ++i) {
    const Snapshot& a = r.snapshots[i - 1];
    const Snapshot& b = r.snapshots[i];
    if (a.truth_known && b.truth_known)
      cv::line(image, canvas.ToPixel(a.truth.x_m, a.truth.y_m),
               canvas.ToPixel(b.truth.x_m, b.truth.y_m), kTruth, 1, cv::LINE_AA);
    cv::line(image, canvas.ToPixel(a.estimate.x(), a.estimate.y()),
             canvas.ToPixel(b.estimate.x(), b.estimate.y()), kEstimate, 1, cv::LINE_AA);
  }
  const double length = 0.45, width = 0.42;
  if (s.truth_known)
    Robot(canvas, Eigen::Vector3d(s.truth.x_m, s.truth.y_m, s.truth.theta_rad), nullptr, length,
          width, kTruth, 2);
  Robot(canvas, s.estimate, nullptr, length, width, kEstimate, 1);
  const cv::Point origin = canvas.ToPixel(r.field.HalfSize(), r.field.HalfSize());
  int x = origin.x + 30, y = origin.y + 10;
  Text(image, r.season + " seed " + std::to_string(r.seed) + " " + r.strategy,
       cv::Point(x, y += 22));
  Text(image, "t = " + Fixed(s.t_s, 2) + " / " + Fixed(r.deadline_s, 0) + " s",
       cv::Point(x, y += 22), 0.6);
  Text(image, s.truth_known ? "points " + std::to_string(s.points) : "points unknown",
       cv::Point(x, y += 22), 0.6);
  std::string action = s.action;
  while (!action.empty()) {
    Text(image, action.substr(0, 38), cv::Point(x, y += 20), 0.45);
    action = action.size() > 38 ? action.substr(38) : "";
  }
  Text(image, "black: truth, orange: estimate", cv::Point(x, y += 30), 0.45);
  Text(image, "x: tracked objects", cv::Point(x, y += 20), 0.45);
  cv::Mat frame;
  cv::hconcat(image, DrawCameraPanel(r.field, s, cv::Size(kCameraPanelWidth, image.rows)), frame);
  return frame;
}

cv::Mat DrawCameraPanel(const field::SeasonConfig& season, const Snapshot& s, cv::Size size) {
  cv::Mat panel(size, CV_8UC3, cv::Scalar(250, 250, 250));
  const int margin = 10, top = 45, legend = 70;
  const cv::Rect area(margin, top, std::max(1, size.width - 2 * margin),
                      std::max(1, size.height - top - legend));
  if (!s.camera || s.camera->image.empty()) {
    Text(panel, "camera", cv::Point(margin, 30), 0.6);
    cv::rectangle(panel, area, kNotUsed, 1);
    Text(panel, "no camera frame taken yet", cv::Point(area.x + 20, area.y + area.height / 2), 0.55,
         kNotUsed);
    return panel;
  }
  const CameraView& v = *s.camera;
  int tracked = 0;
  for (const CameraView::Seen& d : v.seen) tracked += d.use == mapping::DetectionUse::kTracked;
  Text(panel,
       "camera at t = " + Fixed(v.t_s, 2) + " s: " + std::to_string(v.seen.size()) +
           " detections, " + std::to_string(tracked) + " tracked",
       cv::Point(margin, 30), 0.5);
  const double f = std::min(static_cast<double>(area.width) / v.image.cols,
                            static_cast<double>(area.height) / v.image.rows);
  const cv::Size shown(std::max(1, static_cast<int>(v.image.cols * f)),
                       std::max(1, static_cast<int>(v.image.rows * f)));
  cv::Mat scaled;
  cv::resize(v.image, scaled, shown, 0, 0, cv::INTER_LINEAR);
  scaled.copyTo(panel(cv::Rect(area.x, area.y, shown.width, shown.height)));
  for (const CameraView::Seen& d : v.seen) {
    const bool used = d.use == mapping::DetectionUse::kTracked;
    const cv::Scalar colour = used ? Palette(season, d.colour) : kNotUsed;
    const cv::Point tl(area.x + static_cast<int>(std::lround(d.box.x * f)),
                       area.y + static_cast<int>(std::lround(d.box.y * f)));
    const cv::Point br(area.x + static_cast<int>(std::lround(d.box.br().x * f)),
                       area.y + static_cast<int>(std::lround(d.box.br().y * f)));
    cv::rectangle(panel, tl, br, colour, used ? 2 : 1, cv::LINE_8);
    std::string label = (d.kind.empty() ? "?" : d.kind) + " " + d.colour + " " +
                        (d.range_m >= 0.0 ? Fixed(d.range_m, 2) + " m" : "no range");
    if (d.use == mapping::DetectionUse::kOffField) label += ", off field";
    // On a strip of the box's colour above the box (below it at the top of the image).
    int baseline = 0;
    const cv::Size text = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.4, 1, &baseline);
    const int strip_y = tl.y - text.height - 6 >= area.y ? tl.y - text.height - 6 : br.y + 2;
    // Left of the box's left edge when it would leave the panel on the right.
    const int strip_x = std::max(0, std::min(tl.x, size.width - text.width - 6));
    const cv::Rect strip(strip_x, strip_y, text.width + 6, text.height + 6);
    cv::rectangle(panel, strip & cv::Rect(0, 0, size.width, size.height), colour, cv::FILLED);
    const bool light = 0.114 * colour[0] + 0.587 * colour[1] + 0.299 * colour[2] > 140.0;
    Text(panel, label, cv::Point(strip.x + 3, strip.y + text.height + 2), 0.4,
         light ? cv::Scalar(20, 20, 20) : cv::Scalar(255, 255, 255));
  }
  int y = area.y + shown.height + 5;
  Text(panel, "boxes: detections (kind, colour, range),", cv::Point(margin, y += 20), 0.45);
  Text(panel, "  grey: not tracked (off field, or no range)", cv::Point(margin, y += 20), 0.45,
       kNotUsed);
  return panel;
}

int WriteReplay(const MatchResult& r, const std::string& path, double speedup) {
  if (r.snapshots.size() < 2) return 0;
  const double period = std::max(1e-3, r.snapshots[1].t_s - r.snapshots[0].t_s);
  const cv::Mat first = DrawSnapshot(r, 0);
  cv::VideoWriter writer(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                         std::max(1.0, speedup / period), first.size());
  if (!writer.isOpened()) throw std::runtime_error("cannot write the replay video " + path);
  writer.write(first);
  for (size_t k = 1; k < r.snapshots.size(); ++k) writer.write(DrawSnapshot(r, k));
  return static_cast<int>(r.snapshots.size());
}

void PrintSummary(const MatchResult& r, std::ostream& out) {
  out << r.season << ", seed " << r.seed << ", strategy " << r.strategy << ", frames " << r.frames
      << "\n";
  if (!r.robot_io.empty()) out << "  ran on          " << r.robot_io << "\n";
  if (r.truth_known) {
    out << "  points          " << r.points << " (" << r.points_start << " at the start, +"
        << r.points - r.points_start << ")\n";
  } else {
    out << "  points          unknown (no referee off the simulator)\n";
  }
  out << "  deadline        " << Fixed(r.deadline_s, 0) << " s; last motion at "
      << Fixed(r.duration_s, 2) << " s; overrun " << Fixed(r.overrun_s, 2) << " s; refused actions "
      << r.refused << "\n";
  out << "  time            observe " << Fixed(r.observe_s, 1) << " s, drive "
      << Fixed(r.drive_s, 1) << " s, pick/score " << Fixed(r.score_s, 1) << " s, idle "
      << Fixed(r.idle_s, 1) << " s\n";
  out << "  pose ATE        "
      << (std::isnan(r.pose_ate_m) ? std::string("unknown") : Fixed(r.pose_ate_m, 4) + " m") << " ("
      << r.samples.size() << " filter updates, " << r.frames_taken << " frames"
      << (r.moving_frames > 0 ? " (" + std::to_string(r.moving_frames) + " while driving)" : "")
      << ", " << r.replans << " replans, " << r.relocalisations << " relocalisations)\n";
  if (r.consistency.updates > 0) {
    const PoseConsistency& c = r.consistency;
    int inside = 0;
    for (const AttemptCheck& a : r.attempts) inside += a.Inside();
    out << "  filter honesty  pose NEES in its 95 % band at " << c.in_band << " of " << c.updates
        << " updates, below (conservative) " << c.below << ", above (overconfident) " << c.above
        << "; picks/scores/knocks with the true error inside 3-sigma: " << inside << " of "
        << r.attempts.size() << "\n";
  }
  if (!r.attempts.empty()) {
    std::map<std::string, int> picks, scores, knocks;
    int n_picks = 0, n_scores = 0, n_knocks = 0;
    for (const AttemptCheck& a : r.attempts) {
      if (a.action == "PICK") ++picks[a.outcome], n_picks += a.outcome != "skipped";
      if (a.action == "SCORE") ++scores[a.outcome], ++n_scores;
      if (a.action == "KNOCK" || a.action == "PUSH") ++knocks[a.outcome], ++n_knocks;
    }
    out << "  picks           " << n_picks;
    for (const std::string& k : PickOutcomes()) out << ", " << k << " " << picks[k];
    out << "; releases " << n_scores;
    for (const std::string& k : ScoreOutcomes()) out << ", " << k << " " << scores[k];
    if (n_knocks > 0) {
      out << "; knocks " << n_knocks;
      for (const std::string& k : KnockOutcomes()) out << ", " << k << " " << knocks[k];
    }
    out << "\n";
  }
  int matched = 0;
  double sum = 0.0;
  for (const ObjectReport& o : r.objects) {
    if (o.matched) ++matched, sum += o.error_m * o.error_m;
  }
  out << "  objects mapped  " << r.objects.size();
  if (r.truth_known) {
    out << " (" << matched << " matched to truth";
    if (matched) out << ", RMS error " << Fixed(std::sqrt(sum / matched), 3) << " m";
    out << ")";
  }
  out << "\n";
  if (!r.board.empty()) {
    out << "  board, camera  ";
    for (const auto& [key, value] : r.board) out << " " << key << " " << Fixed(value, 0);
    out << "\n";
  }
  out << "  computed in     " << Fixed(r.wall_s, 2) << " s ("
      << Fixed(r.deadline_s / std::max(r.wall_s, 1e-6), 1) << "x real time)\n";
  out << "  timeline:\n";
  for (const TimelineEntry& t : r.timeline) {
    out << "    " << std::setw(6) << Fixed(t.t_s, 2) << "-" << std::setw(6) << std::left
        << Fixed(t.end_s, 2) << std::right << " " << std::setw(9) << std::left << t.action
        << std::right << (t.ok ? "   " : " x ") << t.detail << "\n";
  }
}

std::vector<std::string> WriteMatchFiles(const MatchResult& r, const std::string& dir, bool video) {
  const std::string prefix = dir.empty() || dir.back() == '/' ? dir : dir + "/";
  std::vector<std::string> written;
  {
    std::ofstream report(prefix + "report.json");
    report << ReportJson(r).dump(2) << "\n";
    if (!report) throw std::runtime_error("cannot write " + prefix + "report.json");
    written.push_back("report.json");
  }
  WriteTum(r, prefix + "trajectory.tum");
  written.push_back("trajectory.tum");
  if (!std::isnan(r.pose_ate_m)) {
    WriteTruthTum(r, prefix + "groundtruth.tum");
    written.push_back("groundtruth.tum");
  }
  if (!cv::imwrite(prefix + "map.png", DrawMatchMap(r)))
    throw std::runtime_error("cannot write " + prefix + "map.png");
  written.push_back("map.png");
  if (video && WriteReplay(r, prefix + "replay.avi") > 0) written.push_back("replay.avi");
  return written;
}

}  // namespace slamo::autonomy
