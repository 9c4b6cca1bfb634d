#include "autonomy/experiments/vision_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "platform/field_geometry.h"
#include "platform/sim/sim_renderer.h"
#include "platform/sim/sim_world.h"

namespace slamo::autonomy {
namespace {

using platform::Pose2D;
using platform::SimObject;

// A pose where the robot fits, looking roughly at a random object on the floor.
Pose2D RandomView(const field::SeasonConfig& season, const field::RobotConfig& robot,
                  const platform::SimWorld& world, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double half = season.HalfSize() - 0.3;
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const Pose2D candidate{-half + 2 * half * unit(*rng), -half + 2 * half * unit(*rng), 0.0};
    const SimObject& target = world.objects[static_cast<size_t>(unit(*rng) * world.objects.size())];
    const double dx = target.center_m.x() - candidate.x_m, dy = target.center_m.y() - candidate.y_m;
    const double distance = std::hypot(dx, dy);
    if (distance < 0.8 || distance > 3.5) continue;
    Pose2D pose = candidate;
    pose.theta_rad = std::atan2(dy, dx) + (unit(*rng) - 0.5) * 0.8;
    if (platform::FootprintIsFree(season, pose, robot.length_m, robot.width_m, robot.height_m))
      return pose;
  }
  return Pose2D{-1.5, 0.0, 0.0};
}

// Moves a random floor ball against another of the same type and colour, so touching groups
// appear in view as they do on a real field.
void MakeTouchingPair(platform::SimWorld* world, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<SimObject>& objects = world->objects;
  for (int attempt = 0; attempt < 50; ++attempt) {
    SimObject& a = objects[static_cast<size_t>(unit(*rng) * objects.size())];
    SimObject& b = objects[static_cast<size_t>(unit(*rng) * objects.size())];
    if (&a == &b || a.type != b.type || a.colour != b.colour) continue;
    const double angle = 2.0 * M_PI * unit(*rng);
    const double d = a.type->size_m * 1.001;
    b.center_m.x() = a.center_m.x() + d * std::cos(angle);
    b.center_m.y() = a.center_m.y() + d * std::sin(angle);
    return;
  }
}

int Band(double range_m) { return std::min(3, static_cast<int>(range_m)); }

}  // namespace

double VisionMethodScore::Precision() const {
  const int all = true_positives + false_positives;
  return all ? static_cast<double>(true_positives) / all : 0.0;
}

double VisionMethodScore::Recall() const {
  return expected ? static_cast<double>(found) / expected : 0.0;
}

std::vector<VisionMethodScore> EvaluateVision(const field::SeasonConfig& season,
                                              const field::RobotConfig& robot,
                                              const VisionEvalOptions& options,
                                              const std::function<void(int, int)>& progress) {
  std::vector<VisionMethodScore> scores;
  for (const vision::DetectMethod method :
       {vision::DetectMethod::kThreshold, vision::DetectMethod::kKMeans}) {
    for (const vision::SeparationMethod separation :
         {vision::SeparationMethod::kConcaveDefects, vision::SeparationMethod::kWatershed,
          vision::SeparationMethod::kNone}) {
      VisionMethodScore s;
      s.method = method;
      s.separation = separation;
      s.name = std::string(vision::ToString(method)) + "+" +
               (separation == vision::SeparationMethod::kConcaveDefects ? "defects"
                : separation == vision::SeparationMethod::kWatershed    ? "watershed"
                                                                        : "none");
      scores.push_back(s);
    }
  }
  const vision::DetectorSetup setup = vision::ObjectDetectorSetup(season, &robot.camera);
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);

  for (int frame_index = 0; frame_index < options.frames; ++frame_index) {
    // A scene and a view of it.
    platform::SimWorld world = platform::CreateWorld(season, options.seed * 1000003 + frame_index);
    if (unit(rng) < options.touching_fraction) MakeTouchingPair(&world, &rng);
    const Pose2D pose = RandomView(season, robot, world, &rng);
    platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{},
                                   options.seed + frame_index);
    platform::FrameTruth truth;
    const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, &truth);

    // What should be found: objects with enough visible pixels and most of their disc in
    // view; the rest with enough pixels are "hidden" (scored apart).
    std::map<int, const platform::ObjectTruth*> expected, hidden;
    for (const platform::ObjectTruth& o : truth.objects) {
      if (o.pixels < options.min_visible_px) continue;
      const double radius_px =
          robot.camera.fx * season.FindObjectType(o.type)->size_m / 2.0 / o.position_cam_m.z();
      const bool mostly_visible =
          o.pixels >= options.min_visible_fraction * M_PI * radius_px * radius_px;
      (mostly_visible ? expected : hidden)[o.id] = &o;
    }
    // Touching groups: same colour, masks within 2 px of each other in the image.
    std::map<int, cv::Mat> dilated;
    for (const auto& [id, o] : expected) {
      cv::dilate(truth.ids == id, dilated[id], cv::Mat(), cv::Point(-1, -1), 2);
    }
    std::map<int, int> group_of;
    for (const auto& [id, o] : expected) group_of[id] = id;
    const auto root = [&](int id) {
      while (group_of[id] != id) id = group_of[id];
      return id;
    };
    for (const auto& [a, oa] : expected) {
      for (const auto& [b, ob] : expected) {
        if (a < b && oa->colour == ob->colour &&
            cv::countNonZero(dilated[a] & (truth.ids == b)) > 0) {
          group_of[root(b)] = root(a);
        }
      }
    }
    std::map<int, std::vector<int>> groups;
    for (const auto& [id, o] : expected) groups[root(id)].push_back(id);

    for (VisionMethodScore& s : scores) {
      const bool picture = !options.picture_dir.empty() && frame_index < options.picture_frames &&
                           s.name == options.picture_method;
      std::vector<int> missed_ids;
      vision::DetectOptions detect;
      detect.method = s.method;
      detect.separation = s.separation;
      detect.seed = options.seed;
      const std::vector<vision::Detection> found =
          vision::Detect(frame.colour, frame.depth_mm, setup, detect);
      std::set<int> matched;
      for (const vision::Detection& d : found) {
        // The truth object under most of the detection.
        cv::Mat mask(frame.colour.size(), CV_8UC1, cv::Scalar(0));
        cv::drawContours(mask, std::vector<std::vector<cv::Point>>{d.contour}, 0, cv::Scalar(255),
                         cv::FILLED);
        std::map<int, int> votes;
        for (int v = d.box.y; v < d.box.y + d.box.height; ++v) {
          for (int u = d.box.x; u < d.box.x + d.box.width; ++u) {
            if (mask.at<uint8_t>(v, u)) ++votes[truth.ids.at<uint16_t>(v, u)];
          }
        }
        int best_id = 0, best_votes = 0, total = 0;
        for (const auto& [id, n] : votes) {
          total += n;
          if (id > 0 && id < platform::kLandmarkIdBase && n > best_votes)
            best_id = id, best_votes = n;
        }
        const SimObject* object = nullptr;
        for (const SimObject& o : world.objects) {
          if (o.id == best_id) object = &o;
        }
        const bool hit = object && best_votes * 2 >= total && object->colour == d.colour &&
                         matched.count(best_id) == 0;
        if (!hit) {
          ++s.false_positives;
          continue;
        }
        ++s.true_positives;
        matched.insert(best_id);
        if (expected.count(best_id) == 0) continue;  // hidden: right, but not expected
        // Centre and position errors.
        const auto it =
            std::find_if(truth.objects.begin(), truth.objects.end(),
                         [&](const platform::ObjectTruth& o) { return o.id == best_id; });
        const Eigen::Vector3d& c = it->position_cam_m;
        const cv::Point2d projected(robot.camera.fx * c.x() / c.z() + robot.camera.cx,
                                    robot.camera.fy * c.y() / c.z() + robot.camera.cy);
        s.centre_error_px_sum += cv::norm(projected - d.centre_px);
        ++s.centre_errors;
        if (d.measurement) {
          const Eigen::Vector3d& p = d.measurement->position_robot_m;
          const double wx =
              pose.x_m + std::cos(pose.theta_rad) * p.x() - std::sin(pose.theta_rad) * p.y();
          const double wy =
              pose.y_m + std::sin(pose.theta_rad) * p.x() + std::cos(pose.theta_rad) * p.y();
          const double range =
              std::hypot(object->center_m.x() - pose.x_m, object->center_m.y() - pose.y_m);
          auto& band = s.position_error_m[Band(range)];
          band.first += std::hypot(wx - object->center_m.x(), wy - object->center_m.y());
          ++band.second;
        }
      }
      for (const auto& [id, o] : expected) {
        if (matched.count(id) == 0) missed_ids.push_back(id);
        const SimObject* object = nullptr;
        for (const SimObject& w : world.objects) {
          if (w.id == id) object = &w;
        }
        const bool semi = object->type->material == field::Material::kSemiTransparent;
        const bool got = matched.count(id) > 0;
        ++s.expected;
        s.found += got;
        (semi ? s.expected_semi : s.expected_solid)++;
        (semi ? s.found_semi : s.found_solid) += got;
      }
      for (const auto& [id, o] : hidden) {
        ++s.expected_hidden;
        s.found_hidden += matched.count(id) > 0;
      }
      for (const auto& [root_id, members] : groups) {
        if (members.size() < 2) continue;
        ++s.groups;
        s.groups_counted += std::all_of(members.begin(), members.end(),
                                        [&](int id) { return matched.count(id) > 0; });
      }
      if (picture) {
        // Detections (green; yellow when split) and the expected objects missed (red boxes).
        cv::Mat out = vision::DrawDetections(frame.colour, found);
        for (int id : missed_ids) {
          cv::rectangle(out, expected[id]->box, cv::Scalar(0, 0, 255), 2);
          cv::putText(out, "missed " + expected[id]->colour + " " + expected[id]->type,
                      expected[id]->box.tl() + cv::Point(0, -3), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                      cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
        }
        char name[64];
        std::snprintf(name, sizeof(name), "/frame_%03d.png", frame_index);
        cv::imwrite(options.picture_dir + name, out);
      }
    }
    if (progress) progress(frame_index + 1, options.frames);
  }
  return scores;
}

std::string FormatVisionTable(const std::vector<VisionMethodScore>& scores) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof(line), "%-18s %9s %6s %6s %6s %7s %7s %9s %9s  %s\n", "method",
                "precision", "recall", "solid", "semi", "hidden", "groups", "count_ok", "centre_px",
                "position error m: <1m  1-2m  2-3m  3m+");
  out += line;
  for (const VisionMethodScore& s : scores) {
    const auto ratio = [](int a, int b) { return b ? static_cast<double>(a) / b : 0.0; };
    std::string bands;
    for (int b = 0; b < 4; ++b) {
      const auto it = s.position_error_m.find(b);
      char cell[32];
      if (it == s.position_error_m.end() || it->second.second == 0) {
        std::snprintf(cell, sizeof(cell), "%7s", "-");
      } else {
        std::snprintf(cell, sizeof(cell), "%7.3f", it->second.first / it->second.second);
      }
      bands += cell;
    }
    std::snprintf(line, sizeof(line), "%-18s %9.3f %6.3f %6.3f %6.3f %7.3f %7d %9.3f %9.2f  %s\n",
                  s.name.c_str(), s.Precision(), s.Recall(), ratio(s.found_solid, s.expected_solid),
                  ratio(s.found_semi, s.expected_semi), ratio(s.found_hidden, s.expected_hidden),
                  s.groups, ratio(s.groups_counted, s.groups),
                  s.centre_errors ? s.centre_error_px_sum / s.centre_errors : 0.0, bands.c_str());
    out += line;
  }
  return out;
}

}  // namespace slamo::autonomy
