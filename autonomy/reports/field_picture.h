// Pictures of a season's field from above: tiles, walls, structures, goals, landmarks,
// starting tiles and objects in their colours, with a scale bar and a legend. The canvas's
// world-to-pixel transform is public so later pictures (maps, plans) draw on the same field.
#pragma once

#include <opencv2/core.hpp>

#include "field_configs/season_config.h"

namespace slamo::autonomy {

struct FieldPictureOptions {
  double px_per_m = 200.0;    // picture scale
  int margin_px = 40;         // around the field
  int legend_width_px = 420;  // panel on the right
  bool draw_objects = true;   // objects at their configured start (fixed or region)
};

class FieldCanvas {
 public:
  FieldCanvas(const field::SeasonConfig& season, const FieldPictureOptions& options);

  cv::Point ToPixel(double x_m, double y_m) const;
  int ToPixels(double length_m) const;
  cv::Mat& image() { return image_; }
  const FieldPictureOptions& options() const { return options_; }

  void DrawFloorAndWalls();
  void DrawStructures();
  void DrawGoals();
  void DrawLandmarks();
  void DrawStarts();
  void DrawObjects();
  void DrawScaleBar();
  void DrawLegend();

 private:
  cv::Scalar Colour(const std::string& name) const;  // BGR from the season palette
  void FillRotatedBox(field::Vec2 center, field::Vec2 size, double yaw_deg, cv::Scalar colour,
                      double alpha);

  const field::SeasonConfig& season_;
  FieldPictureOptions options_;
  cv::Mat image_;
};

// The whole picture: floor, walls, structures, goals, landmarks, starts, objects, scale bar
// and legend.
cv::Mat DrawFieldPicture(const field::SeasonConfig& season, const FieldPictureOptions& options);

}  // namespace slamo::autonomy
