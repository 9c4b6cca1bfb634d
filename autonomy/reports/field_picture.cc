#include "autonomy/reports/field_picture.h"

#include <cmath>
#include <map>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace slamo::autonomy {
namespace {

using field::Alliance;
using field::SolidShape;
using field::Vec2;

const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kAllianceRed(40, 30, 210);
const cv::Scalar kAllianceBlue(210, 80, 30);
const cv::Scalar kNeutral(235, 235, 235);

cv::Scalar AllianceColour(Alliance alliance) {
  switch (alliance) {
    case Alliance::kRed:
      return kAllianceRed;
    case Alliance::kBlue:
      return kAllianceBlue;
    case Alliance::kNone:
      break;
  }
  return kNeutral;
}

void Text(cv::Mat& image, const std::string& text, cv::Point at, double scale,
          cv::Scalar colour = kBlack, int thickness = 1) {
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, thickness, cv::LINE_AA);
}

// Text with a dark halo so it reads on any background.
void Label(cv::Mat& image, const std::string& text, cv::Point at, double scale = 0.4) {
  Text(image, text, at, scale, kBlack, 3);
  Text(image, text, at, scale, kWhite, 1);
}

void DashedRectangle(cv::Mat& image, cv::Point a, cv::Point b, cv::Scalar colour) {
  const std::vector<cv::Point> corners{a, {b.x, a.y}, b, {a.x, b.y}};
  for (size_t i = 0; i < corners.size(); ++i) {
    const cv::Point p = corners[i];
    const cv::Point q = corners[(i + 1) % corners.size()];
    const double length = cv::norm(q - p);
    const int dashes = std::max(1, static_cast<int>(length / 8.0));
    for (int d = 0; d < dashes; d += 2) {
      const cv::Point s = p + (q - p) * (static_cast<double>(d) / dashes);
      const cv::Point e = p + (q - p) * (std::min(d + 1.0, static_cast<double>(dashes)) / dashes);
      cv::line(image, s, e, colour, 2, cv::LINE_AA);
    }
  }
}

}  // namespace

FieldCanvas::FieldCanvas(const field::SeasonConfig& season, const FieldPictureOptions& options)
    : season_(season), options_(options) {
  const int field_px = ToPixels(season.field.size_m);
  image_ = cv::Mat(field_px + 2 * options.margin_px + 30,
                   field_px + 2 * options.margin_px + options.legend_width_px, CV_8UC3,
                   cv::Scalar(250, 250, 250));
}

cv::Point FieldCanvas::ToPixel(double x_m, double y_m) const {
  const double half = season_.HalfSize();
  return cv::Point(
      static_cast<int>(std::lround(options_.margin_px + (x_m + half) * options_.px_per_m)),
      static_cast<int>(std::lround(options_.margin_px + (half - y_m) * options_.px_per_m)));
}

int FieldCanvas::ToPixels(double length_m) const {
  return static_cast<int>(std::lround(length_m * options_.px_per_m));
}

cv::Scalar FieldCanvas::Colour(const std::string& name) const {
  const auto it = season_.colours.find(name);
  if (it == season_.colours.end()) return cv::Scalar(128, 128, 128);
  return cv::Scalar(it->second.b, it->second.g, it->second.r);
}

void FieldCanvas::FillRotatedBox(Vec2 center, Vec2 size, double yaw_deg, cv::Scalar colour,
                                 double alpha) {
  const double yaw = yaw_deg * M_PI / 180.0;
  const double c = std::cos(yaw);
  const double s = std::sin(yaw);
  std::vector<cv::Point> corners;
  for (const auto& [u, v] :
       std::vector<std::pair<double, double>>{{1, 1}, {-1, 1}, {-1, -1}, {1, -1}}) {
    const double lx = u * size.x / 2.0;
    const double ly = v * size.y / 2.0;
    corners.push_back(ToPixel(center.x + c * lx - s * ly, center.y + s * lx + c * ly));
  }
  if (alpha >= 1.0) {
    cv::fillConvexPoly(image_, corners, colour, cv::LINE_AA);
  } else {
    cv::Mat overlay = image_.clone();
    cv::fillConvexPoly(overlay, corners, colour, cv::LINE_AA);
    cv::addWeighted(overlay, alpha, image_, 1.0 - alpha, 0.0, image_);
  }
  cv::polylines(image_, corners, true, colour * 0.6, 1, cv::LINE_AA);
}

void FieldCanvas::DrawFloorAndWalls() {
  const double half = season_.HalfSize();
  const cv::Scalar tile = Colour(season_.field.tile_colour);
  cv::rectangle(image_, ToPixel(-half, half), ToPixel(half, -half), tile, cv::FILLED);
  // Tile seams.
  const int tiles =
      static_cast<int>(std::floor(season_.field.size_m / season_.field.tile_m + 1e-6));
  for (int i = 1; i < tiles; ++i) {
    const double at = -half + i * season_.field.tile_m;
    cv::line(image_, ToPixel(at, -half), ToPixel(at, half), tile * 0.75, 1);
    cv::line(image_, ToPixel(-half, at), ToPixel(half, at), tile * 0.75, 1);
  }
  const int wall_px = std::max(2, ToPixels(season_.field.wall_thickness_m));
  const double out = half + season_.field.wall_thickness_m / 2.0;
  cv::rectangle(image_, ToPixel(-out, out), ToPixel(out, -out), Colour(season_.field.wall_colour),
                wall_px);
  // Axes at the origin.
  const cv::Point o = ToPixel(0, 0);
  cv::arrowedLine(image_, o, ToPixel(0.3, 0), kWhite, 1, cv::LINE_AA, 0, 0.2);
  cv::arrowedLine(image_, o, ToPixel(0, 0.3), kWhite, 1, cv::LINE_AA, 0, 0.2);
  Label(image_, "x", ToPixel(0.32, -0.03), 0.35);
  Label(image_, "y", ToPixel(0.02, 0.35), 0.35);
}

void FieldCanvas::DrawStructures() {
  for (const field::Structure& s : season_.structures) {
    const cv::Scalar colour = Colour(s.colour);
    // Solid: blocks robots; faded: robots drive over it; pale: robots pass under it.
    const double alpha = s.blocks_robot ? 1.0 : s.PassUnder() ? 0.3 : 0.55;
    if (s.shape == SolidShape::kBox) {
      FillRotatedBox(s.center_m, s.size_m, s.yaw_deg, colour, alpha);
    } else {
      const int r = std::max(2, ToPixels(s.radius_m));
      cv::circle(image_, ToPixel(s.center_m.x, s.center_m.y), r, colour, cv::FILLED, cv::LINE_AA);
      cv::circle(image_, ToPixel(s.center_m.x, s.center_m.y), r, colour * 0.6, 1, cv::LINE_AA);
    }
  }
}

void FieldCanvas::DrawGoals() {
  for (const field::Goal& g : season_.goals) {
    const cv::Scalar colour = AllianceColour(g.alliance);
    const cv::Point center = ToPixel(g.center_m.x, g.center_m.y);
    if (g.shape == SolidShape::kTriangle) {
      std::vector<cv::Point> corners;
      for (const Vec2& v : g.vertices_m) corners.push_back(ToPixel(v.x, v.y));
      cv::polylines(image_, corners, true, colour, 2, cv::LINE_AA);
    } else if (g.shape == SolidShape::kBox && g.yaw_deg != 0.0) {
      // A rotated goal or zone: its outline, turned.
      const double yaw = g.yaw_deg * M_PI / 180.0;
      std::vector<cv::Point> corners;
      for (const auto& [u, v] :
           std::vector<std::pair<double, double>>{{1, 1}, {-1, 1}, {-1, -1}, {1, -1}}) {
        const double lx = u * g.size_m.x / 2.0, ly = v * g.size_m.y / 2.0;
        corners.push_back(ToPixel(g.center_m.x + std::cos(yaw) * lx - std::sin(yaw) * ly,
                                  g.center_m.y + std::sin(yaw) * lx + std::cos(yaw) * ly));
      }
      cv::polylines(image_, corners, true, colour, g.kind == field::GoalKind::kGoal ? 3 : 2,
                    cv::LINE_AA);
    } else if (g.kind == field::GoalKind::kZone && g.shape == SolidShape::kBox) {
      const Vec2 half{g.size_m.x / 2.0, g.size_m.y / 2.0};
      DashedRectangle(image_, ToPixel(g.center_m.x - half.x + 0.02, g.center_m.y + half.y - 0.02),
                      ToPixel(g.center_m.x + half.x - 0.02, g.center_m.y - half.y + 0.02), colour);
    } else if (g.shape == SolidShape::kBox) {
      cv::rectangle(image_, ToPixel(g.center_m.x - g.size_m.x / 2, g.center_m.y + g.size_m.y / 2),
                    ToPixel(g.center_m.x + g.size_m.x / 2, g.center_m.y - g.size_m.y / 2), colour,
                    3);
    } else {
      cv::circle(image_, center, ToPixels(g.radius_m) + 3, colour, 3, cv::LINE_AA);
    }
    // Label a zone at its top-left inner corner, a goal beside it.
    const cv::Point at =
        g.shape == SolidShape::kTriangle ? center + cv::Point(-20, 4)
        : g.kind == field::GoalKind::kZone && g.shape == SolidShape::kBox
            ? ToPixel(g.center_m.x - g.size_m.x / 2.0 + 0.05, g.center_m.y + g.size_m.y / 2.0 - 0.1)
            : center + cv::Point(ToPixels(g.radius_m + g.size_m.x / 2.0) + 6, 4);
    Label(image_, g.name, at, 0.38);
  }
}

void FieldCanvas::DrawLandmarks() {
  int index = 0;
  for (const field::Landmark& l : season_.landmarks) {
    const cv::Point p = ToPixel(l.position_m.x, l.position_m.y);
    const int r = std::max(5, ToPixels(l.size_m / 2.0));
    const std::vector<cv::Point> diamond{p + cv::Point(0, -r - 3), p + cv::Point(r + 3, 0),
                                         p + cv::Point(0, r + 3), p + cv::Point(-r - 3, 0)};
    cv::fillConvexPoly(image_, diamond, Colour(l.colour), cv::LINE_AA);
    cv::polylines(image_, diamond, true, kBlack, 1, cv::LINE_AA);
    const std::string name = l.id ? *l.id : "L" + std::to_string(index + 1);
    Label(image_, name, p + cv::Point(r + 5, -r - 2), 0.35);
    ++index;
  }
}

void FieldCanvas::DrawStarts() {
  const double tile = season_.field.tile_m;
  for (const field::StartTile& s : season_.starts) {
    const cv::Scalar colour = AllianceColour(s.alliance);
    cv::rectangle(image_, ToPixel(s.center_m.x - tile / 2 + 0.02, s.center_m.y + tile / 2 - 0.02),
                  ToPixel(s.center_m.x + tile / 2 - 0.02, s.center_m.y - tile / 2 + 0.02), colour,
                  3);
    const double heading = s.heading_deg * M_PI / 180.0;
    cv::arrowedLine(
        image_, ToPixel(s.center_m.x, s.center_m.y),
        ToPixel(s.center_m.x + 0.2 * std::cos(heading), s.center_m.y + 0.2 * std::sin(heading)),
        colour, 2, cv::LINE_AA, 0, 0.3);
  }
}

void FieldCanvas::DrawObjects() {
  for (const field::ObjectPlacement& p : season_.objects) {
    const field::ObjectType* type = season_.FindObjectType(p.type);
    if (!type) continue;
    const cv::Scalar colour = Colour(p.colour);
    if (p.region) {
      DashedRectangle(image_, ToPixel(p.region->min_m.x, p.region->max_m.y),
                      ToPixel(p.region->max_m.x, p.region->min_m.y), colour);
      continue;
    }
    const cv::Point c = ToPixel(p.position_m->x, p.position_m->y);
    const int r = std::max(3, ToPixels(type->size_m / 2.0));
    if (type->material == field::Material::kSemiTransparent) {
      cv::Mat overlay = image_.clone();
      cv::circle(overlay, c, r, colour, cv::FILLED, cv::LINE_AA);
      cv::addWeighted(overlay, type->opacity, image_, 1.0 - type->opacity, 0.0, image_);
      cv::circle(image_, c, r, colour, 2, cv::LINE_AA);
      cv::circle(image_, c + cv::Point(-r / 3, -r / 3), std::max(2, r / 6), kWhite, cv::FILLED,
                 cv::LINE_AA);
    } else if (type->shape == field::ObjectShape::kCube ||
               type->shape == field::ObjectShape::kHollowBlock) {
      cv::rectangle(image_, c - cv::Point(r, r), c + cv::Point(r, r), colour, cv::FILLED,
                    cv::LINE_AA);
      cv::rectangle(image_, c - cv::Point(r, r), c + cv::Point(r, r), kBlack, 1, cv::LINE_AA);
    } else if (type->shape == field::ObjectShape::kTorus) {
      cv::circle(image_, c, r, colour, std::max(2, r / 2), cv::LINE_AA);
    } else if (type->shape == field::ObjectShape::kStar) {
      std::vector<cv::Point> star;
      for (int i = 0; i < 10; ++i) {
        const double a = M_PI / 2 + i * M_PI / 5;
        const double rr = (i % 2 == 0) ? r : r * 0.45;
        star.emplace_back(c.x + static_cast<int>(rr * std::cos(a)),
                          c.y - static_cast<int>(rr * std::sin(a)));
      }
      cv::fillPoly(image_, std::vector<std::vector<cv::Point>>{star}, colour, cv::LINE_AA);
      cv::polylines(image_, star, true, kBlack, 1, cv::LINE_AA);
    } else if (type->shape == field::ObjectShape::kTriball) {
      std::vector<cv::Point> tri;
      for (int i = 0; i < 3; ++i) {
        const double a = M_PI / 2 + i * 2 * M_PI / 3;
        tri.emplace_back(c.x + static_cast<int>(r * std::cos(a)),
                         c.y - static_cast<int>(r * std::sin(a)));
      }
      cv::fillConvexPoly(image_, tri, colour, cv::LINE_AA);
      cv::circle(image_, c, r * 2 / 3, colour, cv::FILLED, cv::LINE_AA);
      cv::polylines(image_, tri, true, kBlack, 1, cv::LINE_AA);
    } else {
      cv::circle(image_, c, r, colour, cv::FILLED, cv::LINE_AA);
      cv::circle(image_, c, r, kBlack, 1, cv::LINE_AA);
    }
    // A stack is drawn bottom first, so its top object shows; its height beside it. An
    // object raised on a structure says so.
    if (p.stack_size > 1 && p.stack_level == p.stack_size - 1) {
      Label(image_, "x" + std::to_string(p.stack_size), c + cv::Point(r - 2, -r + 2), 0.33);
    } else if (p.stack_size == 1 && p.z_m > 0.0) {
      Label(image_, "on top", c + cv::Point(r - 2, -r + 2), 0.33);
    }
  }
  // Region labels last, so objects do not cover them; placements sharing a region share a
  // label, one line each.
  std::map<std::vector<double>, int> lines_in_region;
  for (const field::ObjectPlacement& p : season_.objects) {
    if (!p.region) continue;
    const std::vector<double> key{p.region->min_m.x, p.region->min_m.y, p.region->max_m.x,
                                  p.region->max_m.y};
    const int line = lines_in_region[key]++;
    Label(image_, std::to_string(p.count) + "x " + p.colour + " " + p.type + " (random)",
          ToPixel(p.region->min_m.x + 0.03, p.region->min_m.y + 0.05) - cv::Point(0, 14 * line),
          0.36);
  }
}

void FieldCanvas::DrawScaleBar() {
  const double half = season_.HalfSize();
  const cv::Point start = ToPixel(-half, -half) + cv::Point(0, 28);
  const int one_m = ToPixels(1.0);
  cv::rectangle(image_, start, start + cv::Point(one_m / 2, 6), kBlack, cv::FILLED);
  cv::rectangle(image_, start + cv::Point(one_m / 2, 0), start + cv::Point(one_m, 6), kBlack, 1);
  Text(image_, "0", start + cv::Point(-4, -4), 0.4);
  Text(image_, "0.5", start + cv::Point(one_m / 2 - 10, -4), 0.4);
  Text(image_, "1 m", start + cv::Point(one_m - 8, -4), 0.4);
  std::ostringstream size;
  size << "field " << season_.field.size_m << " m square, tiles " << season_.field.tile_m << " m";
  Text(image_, size.str(), start + cv::Point(one_m + 30, 6), 0.4);
}

void FieldCanvas::DrawLegend() {
  const int x0 = ToPixels(season_.field.size_m) + 2 * options_.margin_px;
  int y = options_.margin_px;
  const auto line = [&](const std::string& text, double scale = 0.45, int thickness = 1) {
    Text(image_, text, cv::Point(x0 + 34, y), scale, kBlack, thickness);
    y += 22;
  };
  Text(image_, season_.name + " (" + season_.years + ")", cv::Point(x0, y), 0.7, kBlack, 2);
  y += 26;
  std::ostringstream rules;
  rules << "autonomous " << season_.rules.autonomous_s << " s, bonus "
        << season_.rules.autonomous_bonus;
  Text(image_, rules.str(), cv::Point(x0, y), 0.45);
  y += 30;

  Text(image_, "Objects", cv::Point(x0, y), 0.5, kBlack, 2);
  y += 22;
  std::map<std::pair<std::string, std::string>, int> counts;
  for (const field::ObjectPlacement& p : season_.objects) counts[{p.type, p.colour}] += p.count;
  for (const auto& [key, count] : counts) {
    const field::ObjectType* type = season_.FindObjectType(key.first);
    cv::circle(image_, cv::Point(x0 + 14, y - 5), 8, Colour(key.second), cv::FILLED, cv::LINE_AA);
    cv::circle(image_, cv::Point(x0 + 14, y - 5), 8, kBlack, 1, cv::LINE_AA);
    std::ostringstream text;
    text << count << " " << key.second << " " << key.first << " (" << field::ToString(type->shape)
         << ", " << type->size_m << " m";
    if (type->material == field::Material::kSemiTransparent) text << ", semi-transparent";
    text << ")";
    line(text.str(), 0.4);
  }
  DashedRectangle(image_, cv::Point(x0 + 4, y - 12), cv::Point(x0 + 24, y), cv::Scalar(80, 80, 80));
  line("random start region (seeded)", 0.4);
  y += 8;

  Text(image_, "Landmarks", cv::Point(x0, y), 0.5, kBlack, 2);
  y += 22;
  std::map<std::string, int> landmark_colours;
  for (const field::Landmark& l : season_.landmarks) landmark_colours[l.colour]++;
  for (const auto& [colour, count] : landmark_colours) {
    const cv::Point p(x0 + 14, y - 5);
    const std::vector<cv::Point> diamond{p + cv::Point(0, -8), p + cv::Point(8, 0),
                                         p + cv::Point(0, 8), p + cv::Point(-8, 0)};
    cv::fillConvexPoly(image_, diamond, Colour(colour), cv::LINE_AA);
    cv::polylines(image_, diamond, true, kBlack, 1, cv::LINE_AA);
    line(std::to_string(count) + " " + colour + " marker" + (count > 1 ? "s" : ""), 0.4);
  }
  y += 8;

  Text(image_, "Goals and zones", cv::Point(x0, y), 0.5, kBlack, 2);
  y += 22;
  for (const field::Goal& g : season_.goals) {
    std::ostringstream text;
    text << g.name << ":";
    for (const auto& [type, points] : g.points) text << " " << type << " " << points;
    cv::rectangle(image_, cv::Point(x0 + 6, y - 12), cv::Point(x0 + 22, y),
                  AllianceColour(g.alliance), 2);
    line(text.str(), 0.38);
  }
  y += 8;
  Text(image_, "Field", cv::Point(x0, y), 0.5, kBlack, 2);
  y += 22;
  cv::rectangle(image_, cv::Point(x0 + 6, y - 12), cv::Point(x0 + 22, y), kAllianceRed, 2);
  line("starting tile (arrow: heading)", 0.4);
  cv::rectangle(image_, cv::Point(x0 + 6, y - 12), cv::Point(x0 + 22, y), cv::Scalar(150, 150, 150),
                cv::FILLED);
  line("structure (faded: drive over; pale: pass under)", 0.4);
}

cv::Mat DrawFieldPicture(const field::SeasonConfig& season, const FieldPictureOptions& options) {
  FieldCanvas canvas(season, options);
  canvas.DrawFloorAndWalls();
  canvas.DrawGoals();
  canvas.DrawStructures();
  canvas.DrawStarts();
  canvas.DrawLandmarks();
  if (options.draw_objects) canvas.DrawObjects();
  canvas.DrawScaleBar();
  canvas.DrawLegend();
  return canvas.image();
}

}  // namespace slamo::autonomy
