// The replay video: the map from above and, beside it, what the robot's camera saw.
#include "autonomy/reports/match_report.h"

#include <set>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "autonomy/io/sim_io.h"
#include "autonomy/reports/field_picture.h"
#include "field_configs/loader.h"

namespace slamo::autonomy {
namespace {

cv::Vec3b Bgr(const field::SeasonConfig& season, const std::string& colour) {
  const field::Rgb c = season.colours.at(colour);
  return cv::Vec3b(c.b, c.g, c.r);
}

// A 256x212 black frame with a tracked red ball and a detection the field gate dropped: each is
// boxed where its detection is, the tracked one in the season's red and labelled on a red strip
// above it, the dropped one in grey; inside the boxes the frame shows through.
TEST(CameraPanel, BoxesAndLabelsEachDetectionWhereItWasSeen) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  auto view = std::make_shared<CameraView>();
  view->t_s = 1.0;
  view->image = cv::Mat(212, 256, CV_8UC3, cv::Scalar(0, 0, 0));
  CameraView::Seen ball;
  ball.box = cv::Rect2d(100, 100, 20, 20);
  ball.kind = "buckyball";
  ball.colour = "red";
  ball.range_m = 1.5;
  ball.use = mapping::DetectionUse::kTracked;
  CameraView::Seen stands = ball;
  stands.box = cv::Rect2d(30, 150, 20, 20);
  stands.colour = "blue";
  stands.use = mapping::DetectionUse::kOffField;
  view->seen = {ball, stands};
  Snapshot s;
  s.camera = view;
  // 600 high: the frame fills the 512 px wide area at twice its size, from (10, 45).
  const cv::Mat panel = DrawCameraPanel(season, s, cv::Size(kCameraPanelWidth, 600));
  ASSERT_EQ(panel.size(), cv::Size(kCameraPanelWidth, 600));
  const auto at = [&](int x, int y) { return panel.at<cv::Vec3b>(y, x); };

  // The ball's box: (210, 245) to (250, 285), two pixels wide, in red.
  EXPECT_EQ(at(230, 245), Bgr(season, "red"));  // top edge
  EXPECT_EQ(at(210, 265), Bgr(season, "red"));  // left edge
  EXPECT_EQ(at(250, 265), Bgr(season, "red"));  // right edge
  EXPECT_EQ(at(230, 265), cv::Vec3b(0, 0, 0));  // inside: the frame
  // Its label on a red strip just above the box, with white text in it.
  EXPECT_EQ(at(211, 242), Bgr(season, "red"));
  const cv::Mat strip = panel(cv::Rect(210, 228, 120, 16));
  cv::Mat white;
  cv::inRange(strip, cv::Scalar(200, 200, 200), cv::Scalar(255, 255, 255), white);
  EXPECT_GT(cv::countNonZero(white), 20);
  // The dropped detection: (70, 345) to (110, 385), grey, not blue.
  EXPECT_EQ(at(90, 345), cv::Vec3b(150, 150, 150));
  EXPECT_EQ(at(70, 365), cv::Vec3b(150, 150, 150));
  EXPECT_EQ(at(90, 365), cv::Vec3b(0, 0, 0));
  // Nowhere is there the season's blue: a dropped detection is not drawn in its colour.
  cv::Mat blue;
  cv::inRange(panel, Bgr(season, "blue"), Bgr(season, "blue"), blue);
  EXPECT_EQ(cv::countNonZero(blue), 0);
}

TEST(CameraPanel, BeforeTheFirstFrameSaysSo) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const cv::Mat panel = DrawCameraPanel(season, Snapshot{}, cv::Size(kCameraPanelWidth, 512));
  // The placeholder's text, grey, in the middle of the (empty) frame area.
  cv::Mat grey;
  cv::inRange(panel(cv::Rect(20, 230, 300, 40)), cv::Scalar(140, 140, 140),
              cv::Scalar(160, 160, 160), grey);
  EXPECT_GT(cv::countNonZero(grey), 50);
}

// A short dry run with snapshots: every replay frame is the map and the camera panel; before
// the first look the panel is the placeholder, after it the frame with its detections, one
// small frame kept per look and shared by the snapshots that show it.
TEST(Replay, FramesShowTheCameraBesideTheMap) {
  field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  season.rules.autonomous_s = 6.0;
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  MatchSetup setup;
  const MatchResult r = RunMatch(season, robot, setup, 3);
  ASSERT_GE(r.snapshots.size(), 4u);
  EXPECT_FALSE(r.snapshots.front().camera) << "the first snapshot is before any frame";

  FieldPictureOptions map_options;
  map_options.px_per_m = 110.0;
  const cv::Size map_size = FieldCanvas(r.field, map_options).image().size();
  std::set<const CameraView*> views;
  size_t with_camera = 0, first_seen = r.snapshots.size();
  int detections = 0;
  for (size_t k = 0; k < r.snapshots.size(); ++k) {
    const Snapshot& s = r.snapshots[k];
    if (!s.camera) continue;
    first_seen = std::min(first_seen, k);
    ++with_camera;
    if (views.insert(s.camera.get()).second) detections += static_cast<int>(s.camera->seen.size());
    EXPECT_EQ(s.camera->image.type(), CV_8UC3);
    EXPECT_EQ(s.camera->image.cols, kCameraViewWidth);
  }
  ASSERT_LT(first_seen, r.snapshots.size()) << "the run observes";
  EXPECT_LT(views.size(), with_camera) << "snapshots of the same frame share it";
  EXPECT_GT(detections, 0) << "the first look at toss_up sees balls";

  const cv::Mat before = DrawSnapshot(r, 0);
  const cv::Mat after = DrawSnapshot(r, first_seen);
  EXPECT_EQ(before.size(), cv::Size(map_size.width + kCameraPanelWidth, map_size.height));
  EXPECT_EQ(after.size(), before.size());
  // The frame area of the panel: a rendered field, not the placeholder's blank.
  // (Inside the placeholder's outline, above its text.)
  const cv::Rect frame_area(map_size.width + 20, 60, kCameraViewWidth, 150);
  cv::Scalar mean, stddev;
  cv::meanStdDev(after(frame_area), mean, stddev);
  EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 15.0);
  cv::meanStdDev(before(frame_area), mean, stddev);
  EXPECT_LT(stddev[0] + stddev[1] + stddev[2], 15.0);

  // The video's frames are as wide.
  const std::string path = ::testing::TempDir() + "/replay_with_camera.avi";
  ASSERT_EQ(WriteReplay(r, path), static_cast<int>(r.snapshots.size()));
  cv::VideoCapture video(path, cv::CAP_OPENCV_MJPEG);
  ASSERT_TRUE(video.isOpened());
  cv::Mat frame;
  ASSERT_TRUE(video.read(frame));
  EXPECT_EQ(frame.size(), before.size());
}

}  // namespace
}  // namespace slamo::autonomy
