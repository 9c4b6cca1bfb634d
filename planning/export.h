// Export of a planned route as a LemLib path file, as PATH.JERRYIO writes it (the path editor
// VEX teams use, https://path.jerryio.com), so a team can open, edit and follow the route
// with LemLib's pure pursuit (chassis.follow("path.txt", ...)).
//
// The format is PATH.JERRYIO's "LemLib v0.4.x (inch, byte-voltage)", read from its exporter
// (github.com/Jerrylum/path.jerryio, src/format/LemLibFormatV0_4.tsx, exportFile()) and
// LemLib's reader (lemlib/chassis/pursuit.cpp: lines split on ", " up to "endData"):
//
//   x, y, speed          one line per point, inches, speed in motor units 0..127; the speed
//   ...                  falls to 0 at the end; a last "ghost" point 20 in beyond the end
//   endData              at speed 0 (LemLib's stopping aid)
//   127                  maximum deceleration rate (speed units per inch)
//   100                  maximum speed
//   200                  multiplier (unused)
//   x0, y0, x1, y1, x2, y2, x3, y3     one line per segment, its Bezier control points
//                                      (a straight segment: start, middle, middle, end)
//   #PATH.JERRYIO-DATA {...}           the editor's own JSON (segments, settings)
//
// Coordinates: our field frame (metres, origin at the field's centre, x and y along the
// field) divided by 0.0254 is PATH.JERRYIO's "VEX Gaming Positioning System" frame (inches,
// origin at the centre). Headings in the JSON are PATH.JERRYIO's: degrees clockwise from +y.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace slamo::planning {

inline constexpr double kMetresPerInch = 0.0254;

struct LemLibExportOptions {
  double point_spacing_in = 2.0;    // PATH.JERRYIO's default point density, inches
  double max_speed = 100.0;         // motor units, 0..127
  double min_speed = 20.0;          // floor of the deceleration ramp, motor units
  double max_deceleration = 127.0;  // speed units per inch of path
  std::string name = "slamo";       // the path's name in the editor
  double robot_width_in = 18.0;     // the robot drawn in the editor, inches
  double robot_length_in = 18.0;
  double start_heading_deg = 0.0;  // our convention: degrees counter-clockwise from +x
  double goal_heading_deg = 0.0;
};

struct LemLibPoint {
  double x_in = 0.0;
  double y_in = 0.0;
  double speed = 0.0;
};

// A field-frame point (metres) in PATH.JERRYIO's frame (inches).
Eigen::Vector2d FieldToInches(const Eigen::Vector2d& p_m);

// The points of the file: along each segment its start and then every point_spacing_in,
// the path's end, then the ghost point. Speeds: max_speed, ramped down towards the end at
// max_deceleration (never below min_speed), 0 at the end and the ghost point. Empty for a
// path of fewer than two points.
std::vector<LemLibPoint> LemLibPoints(const std::vector<Eigen::Vector2d>& path_m,
                                      const LemLibExportOptions& options = {});

// The whole file. Throws std::invalid_argument for a path of fewer than two points.
std::string LemLibPathFile(const std::vector<Eigen::Vector2d>& path_m,
                           const LemLibExportOptions& options = {});

// Writes LemLibPathFile() to `file`; throws std::runtime_error when it cannot.
void WriteLemLibPath(const std::string& file, const std::vector<Eigen::Vector2d>& path_m,
                     const LemLibExportOptions& options = {});

}  // namespace slamo::planning
