#include <gtest/gtest.h>

#include "autonomy/reports/field_picture.h"
#include "field_configs/loader.h"

namespace slamo::autonomy {
namespace {

cv::Vec3b At(const cv::Mat& image, cv::Point p) { return image.at<cv::Vec3b>(p); }

// The picture puts things where the config says, in the config's colours.
TEST(FieldPictureTest, DrawsObjectsAndLandmarksAtTheirPositions) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  FieldPictureOptions options;
  FieldCanvas canvas(season, options);
  const cv::Mat picture = DrawFieldPicture(season, options);
  EXPECT_EQ(picture.cols, canvas.ToPixels(3.566) + 2 * options.margin_px + options.legend_width_px);

  // A fixed red buckyball (a preload) at (-0.8955, 1.40): its centre pixel is the palette's red.
  const field::Rgb red = season.colours.at("red");
  const cv::Vec3b ball = At(picture, canvas.ToPixel(-0.8955, 1.40));
  EXPECT_EQ(ball, cv::Vec3b(red.b, red.g, red.r));

  // The first landmark's centre is its colour.
  const field::Landmark& l = season.landmarks.front();
  const field::Rgb lc = season.colours.at(l.colour);
  EXPECT_EQ(At(picture, canvas.ToPixel(l.position_m.x, l.position_m.y)),
            cv::Vec3b(lc.b, lc.g, lc.r));

  // An empty tile centre is the tile colour.
  const field::Rgb tile = season.colours.at(season.field.tile_colour);
  EXPECT_EQ(At(picture, canvas.ToPixel(-1.4925, -0.2985)), cv::Vec3b(tile.b, tile.g, tile.r));
}

TEST(FieldPictureTest, EverySeasonDraws) {
  for (const std::string& name : field::ListSeasons()) {
    SCOPED_TRACE(name);
    const cv::Mat picture = DrawFieldPicture(field::LoadSeasonConfig(name), FieldPictureOptions{});
    EXPECT_FALSE(picture.empty());
  }
}

}  // namespace
}  // namespace slamo::autonomy
