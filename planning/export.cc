#include "planning/export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "platform/drive_base.h"

namespace slamo::planning {
namespace {

using platform::kPi;
// LemLib's path generator puts the ghost point 20 inches past the end.
constexpr double kGhostDistanceIn = 20.0;

// Three decimals, as PATH.JERRYIO writes numbers.
std::string Number(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.3f", std::abs(value) < 5e-4 ? 0.0 : value);
  return text;
}

// Up to six significant digits, no trailing zeros (the header lines after endData).
std::string Compact(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

// Our heading (counter-clockwise from +x) as PATH.JERRYIO's (clockwise from +y), [0, 360).
double EditorHeading(double heading_deg) {
  double h = std::fmod(90.0 - heading_deg, 360.0);
  if (h < 0) h += 360.0;
  return h;
}

// PATH.JERRYIO's ids are 10 letters or digits.
std::string Uid(const char* kind, size_t n) {
  char text[16];
  std::snprintf(text, sizeof(text), "slamo%s%04zu", kind, n % 10000);
  return text;
}

std::string EndPoint(const Eigen::Vector2d& p_in, double heading_deg, size_t n) {
  std::ostringstream out;
  out << "{\"uid\":\"" << Uid("E", n) << "\",\"x\":" << Number(p_in.x())
      << ",\"y\":" << Number(p_in.y())
      << ",\"lock\":false,\"visible\":true,\"heading\":" << Number(heading_deg)
      << ",\"__type\":\"end-point\"}";
  return out.str();
}

}  // namespace

Eigen::Vector2d FieldToInches(const Eigen::Vector2d& p_m) { return p_m / kMetresPerInch; }

std::vector<LemLibPoint> LemLibPoints(const std::vector<Eigen::Vector2d>& path_m,
                                      const LemLibExportOptions& options) {
  std::vector<LemLibPoint> points;
  if (path_m.size() < 2) return points;
  const double spacing_in = options.point_spacing_in > 0 ? options.point_spacing_in : 2.0;
  for (size_t i = 1; i < path_m.size(); ++i) {
    const Eigen::Vector2d a = FieldToInches(path_m[i - 1]), b = FieldToInches(path_m[i]);
    const double length_in = (b - a).norm();
    if (length_in < 1e-9) continue;
    for (double s = 0.0; s < length_in - 1e-9; s += spacing_in) {
      const Eigen::Vector2d p = a + (b - a) * (s / length_in);
      points.push_back({p.x(), p.y(), options.max_speed});
    }
  }
  const Eigen::Vector2d end = FieldToInches(path_m.back());
  points.push_back({end.x(), end.y(), 0.0});
  // Ramp down from the end: v = sqrt(v_next^2 + 2 a d), as PATH.JERRYIO does.
  for (size_t k = points.size() - 1; k-- > 0;) {
    const double d =
        std::hypot(points[k + 1].x_in - points[k].x_in, points[k + 1].y_in - points[k].y_in);
    const double ramp =
        std::sqrt(points[k + 1].speed * points[k + 1].speed + 2 * options.max_deceleration * d);
    points[k].speed = std::max(std::min(points[k].speed, ramp), options.min_speed);
  }
  // The ghost point, along the last segment.
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
  for (size_t i = path_m.size() - 1; i > 0; --i) {
    const Eigen::Vector2d d = path_m[i] - path_m[i - 1];
    if (d.norm() > 1e-9) {
      direction = d.normalized();
      break;
    }
  }
  const Eigen::Vector2d ghost = end + kGhostDistanceIn * direction;
  points.push_back({ghost.x(), ghost.y(), 0.0});
  return points;
}

std::string LemLibPathFile(const std::vector<Eigen::Vector2d>& path_m,
                           const LemLibExportOptions& options) {
  if (path_m.size() < 2) throw std::invalid_argument("LemLibPathFile: a path needs two points");
  std::ostringstream out;
  for (const LemLibPoint& p : LemLibPoints(path_m, options)) {
    out << Number(p.x_in) << ", " << Number(p.y_in) << ", " << Number(p.speed) << "\n";
  }
  out << "endData\n"
      << Compact(options.max_deceleration) << "\n"
      << Compact(options.max_speed) << "\n200\n";
  // Segments: straight lines, written as PATH.JERRYIO writes a linear segment.
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> segments;
  for (size_t i = 1; i < path_m.size(); ++i) {
    if ((path_m[i] - path_m[i - 1]).norm() < 1e-9) continue;
    segments.emplace_back(FieldToInches(path_m[i - 1]), FieldToInches(path_m[i]));
  }
  for (const auto& [a, b] : segments) {
    const Eigen::Vector2d c = (a + b) / 2;
    out << Number(a.x()) << ", " << Number(a.y()) << ", " << Number(c.x()) << ", " << Number(c.y())
        << ", " << Number(c.x()) << ", " << Number(c.y()) << ", " << Number(b.x()) << ", "
        << Number(b.y()) << "\n";
  }
  // The editor's data: the same segments, so PATH.JERRYIO opens the route for editing.
  out << "#PATH.JERRYIO-DATA {\"appVersion\":\"0.8.3\",\"format\":\"LemLib v0.4.x (inch, "
         "byte-voltage)\",\"gc\":{\"robotWidth\":"
      << Number(options.robot_width_in) << ",\"robotHeight\":" << Number(options.robot_length_in)
      << ",\"robotIsHolonomic\":false,\"showRobot\":false,\"uol\":2.54,\"pointDensity\":"
      << Number(options.point_spacing_in)
      << ",\"controlMagnetDistance\":1.968503937007874,\"fieldImage\":{\"displayName\":\"VRC "
         "Field Perimeter\",\"signature\":\"VRC Field Perimeter\",\"origin\":{\"__type\":"
         "\"built-in\"}},\"coordinateSystem\":\"VEX Gaming Positioning System\"},\"paths\":[{"
         "\"segments\":[";
  for (size_t i = 0; i < segments.size(); ++i) {
    const auto& [a, b] = segments[i];
    const double a_heading =
        i == 0 ? options.start_heading_deg : std::atan2(b.y() - a.y(), b.x() - a.x()) * 180.0 / kPi;
    const double b_heading = i + 1 == segments.size()
                                 ? options.goal_heading_deg
                                 : std::atan2(b.y() - a.y(), b.x() - a.x()) * 180.0 / kPi;
    out << (i ? "," : "") << "{\"controls\":[" << EndPoint(a, EditorHeading(a_heading), 2 * i)
        << "," << EndPoint(b, EditorHeading(b_heading), 2 * i + 1)
        << "],\"speedProfiles\":[],\"lookaheadKeyframes\":[],\"uid\":\"" << Uid("S", i) << "\"}";
  }
  out << "],\"pc\":{\"speedLimit\":{\"minLimit\":{\"value\":0,\"label\":\"0\"},\"maxLimit\":{"
         "\"value\":127,\"label\":\"127\"},\"step\":1,\"from\":"
      << Number(options.min_speed) << ",\"to\":" << Number(options.max_speed)
      << "},\"bentRateApplicableRange\":{\"minLimit\":{\"value\":0,\"label\":\"0\"},"
         "\"maxLimit\":{\"value\":1,\"label\":\"1\"},\"step\":0.001,\"from\":0,\"to\":0.1},"
         "\"maxDecelerationRate\":"
      << Number(options.max_deceleration) << "},\"name\":\"";
  for (char ch : options.name) {
    if (ch == '"' || ch == '\\') out << '\\';
    if (static_cast<unsigned char>(ch) >= 0x20) out << ch;
  }
  out << "\",\"uid\":\"slamoPath0\",\"lock\":false,\"visible\":true}]}\n";
  return out.str();
}

void WriteLemLibPath(const std::string& file, const std::vector<Eigen::Vector2d>& path_m,
                     const LemLibExportOptions& options) {
  const std::string text = LemLibPathFile(path_m, options);
  std::ofstream out(file, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error(file + ": cannot write the path file");
}

}  // namespace slamo::planning
