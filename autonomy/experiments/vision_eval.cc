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
#include "vision/field_gate.h"

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

// Moves a random object resting on the floor against another of the same type and colour,
// so touching groups appear in view as they do on a real field.
void MakeTouchingPair(platform::SimWorld* world, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<SimObject>& objects = world->objects;
  const auto on_floor = [](const SimObject& o) {
    return o.center_m.z() <= o.type->height_m / 2.0 + 1e-3;
  };
  for (int attempt = 0; attempt < 50; ++attempt) {
    SimObject& a = objects[static_cast<size_t>(unit(*rng) * objects.size())];
    SimObject& b = objects[static_cast<size_t>(unit(*rng) * objects.size())];
    if (&a == &b || a.type != b.type || a.colour != b.colour || !on_floor(a) || !on_floor(b))
      continue;
    const double angle = 2.0 * M_PI * unit(*rng);
    const double d = a.type->size_m * 1.001;
    const Eigen::Vector2d from = b.center_m.head<2>();
    const Eigen::Vector2d to(a.center_m.x() + d * std::cos(angle),
                             a.center_m.y() + d * std::sin(angle));
    // What rests on b (a stack of rings) goes with it: nothing is left floating.
    for (SimObject& o : objects) {
      if (&o != &b && o.center_m.z() > b.center_m.z() &&
          (o.center_m.head<2>() - from).norm() < b.type->size_m / 2.0) {
        o.center_m.head<2>() += to - from;
      }
    }
    b.center_m.head<2>() = to;
    return;
  }
}

// Arena: opponent robots (alternately red and blue) on free floor, most in front of the
// camera 1-3 m away, none on an object or on the robot.
void AddArenaOpponents(const field::SeasonConfig& season, const Pose2D& robot, int count,
                       platform::SimWorld* world, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  constexpr double kSize = 0.457;  // an 18 in robot, as tall as it is long
  for (int k = 0; k < count; ++k) {
    for (int attempt = 0; attempt < 200; ++attempt) {
      const double bearing = robot.theta_rad + (unit(*rng) - 0.5) * (attempt < 100 ? 1.2 : 6.3);
      const double range = 1.0 + 2.0 * unit(*rng);
      const Pose2D pose{robot.x_m + range * std::cos(bearing),
                        robot.y_m + range * std::sin(bearing), 2.0 * M_PI * unit(*rng)};
      if (!platform::FootprintIsFree(season, pose, kSize + 0.05, kSize + 0.05, kSize)) continue;
      const auto clear = [&](double x, double y, double r) {
        return std::hypot(x - pose.x_m, y - pose.y_m) > kSize / std::sqrt(2.0) + r;
      };
      bool free = clear(robot.x_m, robot.y_m, 0.35);
      for (const SimObject& o : world->objects)
        free = free && clear(o.center_m.x(), o.center_m.y(), o.type->size_m / 2.0);
      for (const platform::SimOpponent& o : world->opponents)
        free = free && clear(o.pose.x_m, o.pose.y_m, kSize / std::sqrt(2.0));
      if (!free) continue;
      platform::SimOpponent opponent;
      opponent.config.alliance = k % 2 ? field::Alliance::kBlue : field::Alliance::kRed;
      opponent.config.size_m = {kSize, kSize};
      opponent.pose = pose;
      world->opponents.push_back(opponent);
      break;
    }
  }
}

int Band(double range_m) { return std::min(3, static_cast<int>(range_m)); }

// The object id under most of a detection's pixels in the truth image, or 0 (background,
// landmarks, robots, or no majority).
int TruthIdUnder(const vision::Detection& d, const cv::Mat& ids) {
  const cv::Rect box = d.box & cv::Rect(0, 0, ids.cols, ids.rows);
  cv::Mat mask(box.size(), CV_8UC1, cv::Scalar(0));
  cv::drawContours(mask, std::vector<std::vector<cv::Point>>{d.contour}, 0, cv::Scalar(255),
                   cv::FILLED, cv::LINE_8, cv::noArray(), 0, -box.tl());
  std::map<int, int> votes;
  for (int v = 0; v < box.height; ++v) {
    for (int u = 0; u < box.width; ++u) {
      if (mask.at<uint8_t>(v, u)) ++votes[ids.at<uint16_t>(v + box.y, u + box.x)];
    }
  }
  int best_id = 0, best_votes = 0, total = 0;
  for (const auto& [id, n] : votes) {
    total += n;
    if (id > 0 && id < platform::kLandmarkIdBase && n > best_votes) best_id = id, best_votes = n;
  }
  return best_votes * 2 >= total ? best_id : 0;
}

// What a false detection lies on, by most of its pixels: objects of its own colour (a second
// detection on a found object, a piece of one, or one spanning two), an opponent robot, or
// anything else (structures, the field, the stands, objects of another colour).
enum class FalseOn { kPiece, kRobot, kOther };
FalseOn FalseDetectionOn(const vision::Detection& d, const cv::Mat& ids,
                         const std::map<int, const SimObject*>& object_of) {
  const cv::Rect box = d.box & cv::Rect(0, 0, ids.cols, ids.rows);
  cv::Mat mask(box.size(), CV_8UC1, cv::Scalar(0));
  cv::drawContours(mask, std::vector<std::vector<cv::Point>>{d.contour}, 0, cv::Scalar(255),
                   cv::FILLED, cv::LINE_8, cv::noArray(), 0, -box.tl());
  int piece = 0, robot = 0, total = 0;
  for (int v = 0; v < box.height; ++v) {
    for (int u = 0; u < box.width; ++u) {
      if (!mask.at<uint8_t>(v, u)) continue;
      const int id = ids.at<uint16_t>(v + box.y, u + box.x);
      ++total;
      if (id >= platform::kOpponentIdBase) {
        ++robot;
      } else if (id > 0 && id < platform::kLandmarkIdBase) {
        const auto it = object_of.find(id);
        piece += it != object_of.end() && it->second->colour == d.colour;
      }
    }
  }
  if (2 * piece > total) return FalseOn::kPiece;
  if (2 * robot > total) return FalseOn::kRobot;
  return FalseOn::kOther;
}

void Label(cv::Mat* image, const std::string& text, cv::Point at, const cv::Scalar& colour) {
  at.y = std::max(12, at.y);
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.4, colour, 1, cv::LINE_AA);
}

struct Picture {
  int badness = 0;  // false detections kept plus expected objects missed
  int frame = 0;
  cv::Mat image;
};

}  // namespace

double VisionMethodScore::Precision() const {
  const int all = true_positives + false_positives;
  return all ? static_cast<double>(true_positives) / all : 0.0;
}

double VisionMethodScore::RawPrecision() const {
  const int all = raw_true_positives + raw_false_positives;
  return all ? static_cast<double>(raw_true_positives) / all : 0.0;
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
  const vision::FieldBounds bounds = vision::FieldBoundsOf(season);
  vision::FieldGateOptions gate;
  gate.pose_sigma_m = options.pose_sigma_m;
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Picture> worst;

  for (int frame_index = 0; frame_index < options.frames; ++frame_index) {
    // A scene and a view of it.
    platform::SimWorld world = platform::CreateWorld(season, options.seed * 1000003 + frame_index);
    if (unit(rng) < options.touching_fraction) MakeTouchingPair(&world, &rng);
    const Pose2D pose = RandomView(season, robot, world, &rng);
    std::set<int> pile;
    std::string pile_colour;
    if (options.pile_max > 0) {
      // The season's smallest type (not a goal), a random colour, 1-2 m ahead.
      const field::ObjectType* type = nullptr;
      for (const field::ObjectType& t : season.object_types) {
        if (t.shape != field::ObjectShape::kCylinder && (!type || t.size_m < type->size_m))
          type = &t;
      }
      const int count = options.pile_min +
                        static_cast<int>(unit(rng) * (options.pile_max - options.pile_min + 1));
      pile_colour = type->colours[static_cast<size_t>(unit(rng) * type->colours.size())];
      const double reach = type->size_m * std::sqrt(count / 3.0) + type->size_m;
      const double range = 1.0 + reach + 0.6 * unit(rng);
      const double bearing = pose.theta_rad + (unit(rng) - 0.5) * 0.3;
      const Eigen::Vector2d centre(pose.x_m + range * std::cos(bearing),
                                   pose.y_m + range * std::sin(bearing));
      for (int id : platform::AddPile(*type, pile_colour, centre, std::min(count, options.pile_max),
                                      &world)) {
        pile.insert(id);
      }
    }
    platform::RenderOptions render;
    render.arena = options.arena;
    if (options.arena) AddArenaOpponents(season, pose, options.arena_opponents, &world, &rng);
    platform::SimRenderer renderer(season, robot.camera, render, options.seed + frame_index);
    platform::FrameTruth truth;
    const platform::RgbdFrame frame = renderer.Render(world, pose, 0.0, &truth);
    // The gate sees the pose as an estimate would give it.
    const Eigen::Vector3d gate_pose(pose.x_m + options.pose_sigma_m * normal(rng),
                                    pose.y_m + options.pose_sigma_m * normal(rng), pose.theta_rad);
    std::map<int, const SimObject*> object_of;
    for (const SimObject& o : world.objects) object_of[o.id] = &o;

    // What should be found: objects in range with enough visible pixels and most of their
    // disc in view; the rest in range with enough pixels are "hidden" (scored apart).
    std::map<int, const platform::ObjectTruth*> expected, hidden;
    for (const platform::ObjectTruth& o : truth.objects) {
      if (o.pixels < options.min_visible_px) continue;
      const double range = std::hypot(o.position_m.x() - pose.x_m, o.position_m.y() - pose.y_m);
      if (range > options.max_range_m) continue;
      const double radius_px =
          robot.camera.fx * season.FindObjectType(o.type)->size_m / 2.0 / o.position_cam_m.z();
      const bool mostly_visible =
          o.pixels >= options.min_visible_fraction * M_PI * radius_px * radius_px;
      (mostly_visible ? expected : hidden)[o.id] = &o;
    }
    // Touching groups (stacks too): same colour, masks within 2 px of each other.
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
      vision::DetectOptions detect = options.detect;
      detect.method = s.method;
      detect.separation = s.separation;
      detect.seed = options.seed;
      const std::vector<vision::Detection> found =
          vision::Detect(frame.colour, options.depth ? frame.depth_mm : cv::Mat(), setup, detect);
      std::set<int> matched;
      std::map<int, int> detections_on;  // object id -> kept detections of its colour on it
      std::vector<const vision::Detection*> kept, rejected, false_kept;
      std::vector<FalseOn> false_on;  // what each of false_kept lies on
      for (const vision::Detection& d : found) {
        const int id = TruthIdUnder(d, truth.ids);
        const SimObject* object = id ? object_of[id] : nullptr;
        const bool hit = object && object->colour == d.colour && matched.count(id) == 0;
        ++(hit ? s.raw_true_positives : s.raw_false_positives);
        const vision::GateVerdict verdict =
            vision::Judge(d, *setup.camera, gate_pose, bounds, gate, detect.measurement);
        if (verdict != vision::GateVerdict::kOnField) {
          ++s.rejected_by_geometry;
          s.rejected_structure += verdict == vision::GateVerdict::kStructure;
          s.rejected_objects += hit;
          rejected.push_back(&d);
          continue;
        }
        kept.push_back(&d);
        if (object && object->colour == d.colour) ++detections_on[id];
        if (!d.kind.empty()) {
          TypeScore& t = s.types[d.kind];
          ++t.detected;
          t.detected_right += hit && object->type->name == d.kind;
        }
        if (!hit) {
          ++s.false_positives;
          false_kept.push_back(&d);
          false_on.push_back(FalseDetectionOn(d, truth.ids, object_of));
          switch (false_on.back()) {
            case FalseOn::kPiece:
              ++s.false_pieces;
              break;
            case FalseOn::kRobot:
              ++s.false_on_robots;
              break;
            case FalseOn::kOther:
              ++s.false_other;
              break;
          }
          continue;
        }
        ++s.true_positives;
        matched.insert(id);
        if (expected.count(id) == 0) continue;  // hidden or far: right, but not expected
        TypeScore& t = s.types[object->type->name];
        t.typed += !d.kind.empty();
        t.typed_right += d.kind == object->type->name;
        // Centre and position errors.
        const Eigen::Vector3d& c = expected[id]->position_cam_m;
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
      if (!pile.empty()) {
        int visible = 0, detected = 0;
        for (const platform::ObjectTruth& o : truth.objects)
          visible += pile.count(o.id) && o.pixels >= options.min_visible_px;
        for (const vision::Detection* d : kept) {
          const cv::Point c(cvRound(d->centre_px.x), cvRound(d->centre_px.y));
          const bool inside = c.x >= 0 && c.y >= 0 && c.x < truth.ids.cols && c.y < truth.ids.rows;
          const int under = inside ? truth.ids.at<uint16_t>(c) : 0;
          detected += d->colour == pile_colour &&
                      (pile.count(under) > 0 || pile.count(TruthIdUnder(*d, truth.ids)) > 0);
        }
        if (visible > 0) {
          ++s.piles;
          s.pile_visible += visible;
          s.pile_detected += detected;
          s.piles_within_10pct += std::abs(detected - visible) <= 0.1 * visible;
          s.pile_abs_error_ratio_sum += std::abs(detected - visible) / static_cast<double>(visible);
        }
      }
      std::vector<int> missed_ids;
      for (const auto& [id, o] : expected) {
        const SimObject* object = object_of[id];
        const bool semi = object->type->material == field::Material::kSemiTransparent;
        const bool got = matched.count(id) > 0;
        if (!got) missed_ids.push_back(id);
        ++s.expected;
        s.found += got;
        (semi ? s.expected_semi : s.expected_solid)++;
        (semi ? s.found_semi : s.found_solid) += got;
        TypeScore& t = s.types[object->type->name];
        ++t.expected;
        t.found += got;
      }
      for (const auto& [id, o] : hidden) {
        ++s.expected_hidden;
        s.found_hidden += matched.count(id) > 0;
      }
      for (const auto& [root_id, members] : groups) {
        if (members.size() < 2) continue;
        ++s.groups;
        // Counted right: exactly one detection on each member (a member split in two, or a
        // fragment of one kept beside its detection, is a miscount).
        s.groups_counted += std::all_of(members.begin(), members.end(), [&](int id) {
          const auto it = detections_on.find(id);
          return it != detections_on.end() && it->second == 1;
        });
      }
      const int badness = static_cast<int>(false_kept.size() + missed_ids.size());
      if (options.picture_dir.empty() || s.name != options.picture_method || badness == 0 ||
          (static_cast<int>(worst.size()) >= options.picture_frames &&
           badness <= worst.back().badness)) {
        continue;
      }
      // The frame as the method saw it: detections kept (green; yellow when split), false
      // ones among them (magenta box, labelled with what they lie on), those the field gate
      // dropped (grey), and the expected objects missed (red boxes).
      std::vector<vision::Detection> shown;
      for (const vision::Detection* d : kept) shown.push_back(*d);
      cv::Mat out = vision::DrawDetections(frame.colour, shown);
      for (const vision::Detection* d : rejected) {
        cv::drawContours(out, std::vector<std::vector<cv::Point>>{d->contour}, 0,
                         cv::Scalar(150, 150, 150), 2, cv::LINE_AA);
        Label(&out, "off field", d->box.tl() + cv::Point(0, -3), cv::Scalar(190, 190, 190));
      }
      for (size_t k = 0; k < false_kept.size(); ++k) {
        const cv::Rect& box = false_kept[k]->box;
        cv::rectangle(out, box, cv::Scalar(255, 0, 255), 1);
        static const char* const kOn[] = {"false: piece", "false: robot", "false: other"};
        Label(&out, kOn[static_cast<int>(false_on[k])], cv::Point(box.x, box.br().y + 10),
              cv::Scalar(255, 0, 255));
      }
      for (int id : missed_ids) {
        cv::rectangle(out, expected[id]->box, cv::Scalar(0, 0, 255), 2);
        Label(&out, "missed " + expected[id]->colour + " " + expected[id]->type,
              expected[id]->box.tl() + cv::Point(0, -3), cv::Scalar(0, 0, 255));
      }
      worst.push_back({badness, frame_index, out});
      std::stable_sort(worst.begin(), worst.end(),
                       [](const Picture& a, const Picture& b) { return a.badness > b.badness; });
      if (static_cast<int>(worst.size()) > options.picture_frames) worst.pop_back();
    }
    if (progress) progress(frame_index + 1, options.frames);
  }
  for (size_t k = 0; k < worst.size(); ++k) {
    char name[96];
    std::snprintf(name, sizeof(name), "/worst_%02zu_frame_%03d.png", k + 1, worst[k].frame);
    cv::imwrite(options.picture_dir + name, worst[k].image);
  }
  return scores;
}

std::string FormatVisionTable(const std::vector<VisionMethodScore>& scores) {
  std::string out;
  char line[320];
  std::snprintf(line, sizeof(line),
                "%-19s %9s %8s %8s %9s %6s %6s %6s %6s %6s %6s %6s %6s %7s %7s %8s %9s  %s\n",
                "method", "precision", "no_gate", "rejected", "structure", "wrong", "false",
                "piece", "robot", "other", "recall", "solid", "semi", "hidden", "groups",
                "count_ok", "centre_px", "position error m: <1m  1-2m  2-3m  3m+");
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
    std::snprintf(line, sizeof(line),
                  "%-19s %9.3f %8.3f %8d %9d %6d %6d %6d %6d %6d %6.3f %6.3f %6.3f %7.3f %7d %8.3f "
                  "%9.2f  %s\n",
                  s.name.c_str(), s.Precision(), s.RawPrecision(), s.rejected_by_geometry,
                  s.rejected_structure, s.rejected_objects, s.false_positives, s.false_pieces,
                  s.false_on_robots, s.false_other, s.Recall(),
                  ratio(s.found_solid, s.expected_solid), ratio(s.found_semi, s.expected_semi),
                  ratio(s.found_hidden, s.expected_hidden), s.groups,
                  ratio(s.groups_counted, s.groups),
                  s.centre_errors ? s.centre_error_px_sum / s.centre_errors : 0.0, bands.c_str());
    out += line;
  }
  return out;
}

std::string FormatPileTable(const std::vector<VisionMethodScore>& scores) {
  std::string out;
  char line[256];
  if (scores.empty() || scores[0].piles == 0) return out;
  std::snprintf(line, sizeof(line), "%-19s %6s %11s %14s %12s %10s\n", "piles, method", "piles",
                "within_10%", "mean_abs_error", "visible_sum", "found_sum");
  out += line;
  for (const VisionMethodScore& s : scores) {
    std::snprintf(line, sizeof(line), "%-19s %6d %11.3f %14.3f %12d %10d\n", s.name.c_str(),
                  s.piles, static_cast<double>(s.piles_within_10pct) / s.piles,
                  s.pile_abs_error_ratio_sum / s.piles, s.pile_visible, s.pile_detected);
    out += line;
  }
  return out;
}

std::string FormatTypeTable(const VisionMethodScore& s) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof(line), "%-19s %9s %9s %8s %8s %6s %8s %10s\n",
                ("types, " + s.name).c_str(), "detected", "precision", "expected", "found",
                "recall", "typed", "type_right");
  out += line;
  for (const auto& [name, t] : s.types) {
    const auto ratio = [](int a, int b) { return b ? static_cast<double>(a) / b : 0.0; };
    std::snprintf(line, sizeof(line), "%-19s %9d %9.3f %8d %8d %6.3f %8d %10.3f\n", name.c_str(),
                  t.detected, ratio(t.detected_right, t.detected), t.expected, t.found,
                  ratio(t.found, t.expected), t.typed, ratio(t.typed_right, t.typed));
    out += line;
  }
  return out;
}

}  // namespace slamo::autonomy
