#include "vision/separation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "vision/contour_fill.h"

namespace slamo::vision {
namespace {

constexpr SeparationMethod kAllMethods[] = {
    SeparationMethod::kNone, SeparationMethod::kConcaveDefects, SeparationMethod::kWatershed};

struct Ball {
  cv::Point2d centre;
  int radius_px;
};

cv::Mat DrawBalls(const std::vector<Ball>& balls, cv::Size size = {800, 600}) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  for (const Ball& b : balls) {
    cv::circle(mask, cv::Point(cvRound(b.centre.x), cvRound(b.centre.y)), b.radius_px,
               cv::Scalar(255), cv::FILLED);
  }
  return mask;
}

// Two balls on a horizontal line overlapping by `overlap` x the smaller one's diameter.
std::vector<Ball> Pair(int radius_1, int radius_2, double overlap) {
  const double gap = radius_1 + radius_2 - overlap * 2.0 * std::min(radius_1, radius_2);
  return {{{250.0, 300.0}, radius_1}, {{250.0 + gap, 300.0}, radius_2}};
}

// A ball piece is the ball minus caps shallower than its radius, so its minimum enclosing
// circle is the ball itself: a centre estimate that ignores where the cut went.
std::vector<cv::Point2d> Centres(const SeparationResult& result) {
  std::vector<cv::Point2d> centres;
  for (const auto& piece : result.pieces) {
    cv::Point2f centre;
    float radius = 0.0f;
    cv::minEnclosingCircle(piece, centre, radius);
    centres.emplace_back(centre.x, centre.y);
  }
  return centres;
}

// The largest distance between a found centre and its true centre, under the best matching.
double MaxCentreError(const SeparationResult& result, const std::vector<Ball>& balls) {
  const std::vector<cv::Point2d> found = Centres(result);
  if (found.size() != balls.size()) return std::numeric_limits<double>::infinity();
  std::vector<int> order(balls.size());
  for (int i = 0; i < static_cast<int>(order.size()); ++i) order[i] = i;
  double best = std::numeric_limits<double>::infinity();
  do {
    double worst = 0.0;
    for (size_t i = 0; i < found.size(); ++i) {
      const cv::Point2d d = found[i] - balls[order[i]].centre;
      worst = std::max(worst, std::hypot(d.x, d.y));
    }
    best = std::min(best, worst);
  } while (std::next_permutation(order.begin(), order.end()));
  return best;
}

std::string Name(SeparationMethod method) {
  switch (method) {
    case SeparationMethod::kNone:
      return "none";
    case SeparationMethod::kConcaveDefects:
      return "defects";
    case SeparationMethod::kWatershed:
      return "watershed";
  }
  return "?";
}

TEST(SeparationTest, OneBallIsOnePieceForEveryMethod) {
  for (int radius : {12, 40, 100}) {
    const std::vector<Ball> ball = {{{400.0, 300.0}, radius}};
    for (SeparationMethod method : kAllMethods) {
      const SeparationResult result = SeparateTouching(DrawBalls(ball), method);
      ASSERT_EQ(result.pieces.size(), 1u) << Name(method) << " radius " << radius;
      EXPECT_LT(MaxCentreError(result, ball), 1.5) << Name(method) << " radius " << radius;
      EXPECT_EQ(result.cuts, 0);
    }
  }
}

TEST(SeparationTest, DefectsSplitTwoEqualBallsFromTouchingToFortyPercentOverlap) {
  for (int radius : {40, 100}) {
    for (int percent = 0; percent <= 40; percent += 5) {
      const std::vector<Ball> balls = Pair(radius, radius, percent / 100.0);
      const SeparationResult result =
          SeparateTouching(DrawBalls(balls), SeparationMethod::kConcaveDefects);
      ASSERT_EQ(result.pieces.size(), 2u) << "radius " << radius << " overlap " << percent;
      EXPECT_LE(MaxCentreError(result, balls), 3.0)
          << "radius " << radius << " overlap " << percent;
      EXPECT_EQ(result.passes, 1);
      EXPECT_EQ(result.cuts, 1);
    }
  }
}

// The baseline's markers are the distance transform above 0.6 x its maximum. For two equal
// balls of radius r the ridge between the centres stays above 0.6 r once the neck's half
// width sqrt(r^2 - (d/2)^2) exceeds 0.6 r, i.e. from 20 % overlap of the diameter on: the
// two markers merge and watershed returns one piece. The thesis's complaint, reproduced.
TEST(SeparationTest, WatershedSplitsTwoEqualBallsOnlyBelowTwentyPercentOverlap) {
  for (int percent = 5; percent <= 40; percent += 5) {
    const std::vector<Ball> balls = Pair(100, 100, percent / 100.0);
    const SeparationResult result =
        SeparateTouching(DrawBalls(balls), SeparationMethod::kWatershed);
    if (percent < 20) {
      ASSERT_EQ(result.pieces.size(), 2u) << "overlap " << percent;
      EXPECT_LE(MaxCentreError(result, balls), 3.0) << "overlap " << percent;
    } else {
      EXPECT_EQ(result.pieces.size(), 1u) << "overlap " << percent;
    }
  }
}

TEST(SeparationTest, NoneKeepsTouchingBallsAsOneBlob) {
  const SeparationResult result =
      SeparateTouching(DrawBalls(Pair(80, 80, 0.1)), SeparationMethod::kNone);
  EXPECT_EQ(result.pieces.size(), 1u);
  EXPECT_EQ(result.passes, 0);
}

TEST(SeparationTest, TwoBallsOfDifferentSizes) {
  // 100 px and 60 px, overlapping by 20 % of the small one's diameter.
  const std::vector<Ball> balls = Pair(100, 60, 0.2);
  const SeparationResult defects =
      SeparateTouching(DrawBalls(balls), SeparationMethod::kConcaveDefects);
  ASSERT_EQ(defects.pieces.size(), 2u);
  EXPECT_LE(MaxCentreError(defects, balls), 3.0);

  // Watershed: the small ball's peak (60) is just above 0.6 x the large one's (100), so it
  // gets a marker and the pair splits, but the flood meets halfway between the markers
  // rather than on the chord through the necks: the small ball loses more than its cap and
  // its centre is off by about 3 px.
  const SeparationResult watershed =
      SeparateTouching(DrawBalls(balls), SeparationMethod::kWatershed);
  ASSERT_EQ(watershed.pieces.size(), 2u);
  EXPECT_LE(MaxCentreError(watershed, balls), 4.0);

  // With a 50 px ball its peak is below 0.6 x 100: no marker, and watershed gives one piece
  // even for balls that only just touch. Defects still split them.
  const std::vector<Ball> small_pair = Pair(100, 50, 0.1);
  EXPECT_EQ(SeparateTouching(DrawBalls(small_pair), SeparationMethod::kWatershed).pieces.size(),
            1u);
  const SeparationResult small_defects =
      SeparateTouching(DrawBalls(small_pair), SeparationMethod::kConcaveDefects);
  ASSERT_EQ(small_defects.pieces.size(), 2u);
  EXPECT_LE(MaxCentreError(small_defects, small_pair), 3.0);
}

std::vector<Ball> Row(int count, int radius, double overlap) {
  std::vector<Ball> balls;
  for (int i = 0; i < count; ++i) {
    balls.push_back({{150.0 + i * 2.0 * radius * (1.0 - overlap), 300.0}, radius});
  }
  return balls;
}

TEST(SeparationTest, ThreeInARowNeedTwoPasses) {
  for (int percent : {0, 10, 25, 40}) {
    const std::vector<Ball> balls = Row(3, 80, percent / 100.0);
    const SeparationResult result =
        SeparateTouching(DrawBalls(balls), SeparationMethod::kConcaveDefects);
    ASSERT_EQ(result.pieces.size(), 3u) << "overlap " << percent;
    EXPECT_LE(MaxCentreError(result, balls), 3.0) << "overlap " << percent;
    EXPECT_GE(result.passes, 2) << "overlap " << percent;
    EXPECT_EQ(result.cuts, 2) << "overlap " << percent;
  }
  // Watershed: three pieces while the necks are narrow, one once the markers merge.
  EXPECT_EQ(
      SeparateTouching(DrawBalls(Row(3, 80, 0.1)), SeparationMethod::kWatershed).pieces.size(), 3u);
  EXPECT_EQ(
      SeparateTouching(DrawBalls(Row(3, 80, 0.25)), SeparationMethod::kWatershed).pieces.size(),
      1u);
}

TEST(SeparationTest, OnePassLeavesTheThirdBallAttached) {
  SeparationOptions options;
  options.max_passes = 1;
  const SeparationResult result =
      SeparateTouching(DrawBalls(Row(3, 80, 0.1)), SeparationMethod::kConcaveDefects, options);
  EXPECT_EQ(result.pieces.size(), 2u);
  EXPECT_EQ(result.passes, 1);
}

TEST(SeparationTest, FourInARow) {
  const std::vector<Ball> balls = Row(4, 60, 0.15);
  const SeparationResult result =
      SeparateTouching(DrawBalls(balls), SeparationMethod::kConcaveDefects);
  ASSERT_EQ(result.pieces.size(), 4u);
  EXPECT_LE(MaxCentreError(result, balls), 3.0);
  EXPECT_GE(result.passes, 2);
}

std::vector<Ball> Triangle(int radius, double overlap) {
  const double side = 2.0 * radius * (1.0 - overlap);
  return {{{400.0 - side / 2.0, 380.0}, radius},
          {{400.0 + side / 2.0, 380.0}, radius},
          {{400.0, 380.0 - side * std::sqrt(3.0) / 2.0}, radius}};
}

// A compact cluster is cut with a V through its centre along two necks, which follows the
// boundaries between the balls. Three tangent balls enclose a gap that is filled before
// cutting; its pixels go to the pieces, so the centres there are looser.
TEST(SeparationTest, TriangleClusterOfThree) {
  for (int percent : {0, 10, 20, 30}) {
    const std::vector<Ball> balls = Triangle(80, percent / 100.0);
    const SeparationResult result =
        SeparateTouching(DrawBalls(balls), SeparationMethod::kConcaveDefects);
    ASSERT_EQ(result.pieces.size(), 3u) << "overlap " << percent;
    EXPECT_LE(MaxCentreError(result, balls), percent == 0 ? 6.0 : 3.0) << "overlap " << percent;
    EXPECT_EQ(result.passes, 2) << "overlap " << percent;
  }
  EXPECT_EQ(
      SeparateTouching(DrawBalls(Triangle(80, 0.1)), SeparationMethod::kWatershed).pieces.size(),
      3u);
  EXPECT_EQ(
      SeparateTouching(DrawBalls(Triangle(80, 0.3)), SeparationMethod::kWatershed).pieces.size(),
      1u);
}

// Two balls whose lower half is hidden behind an occluder: the bottom outline is straight,
// only the upper defect is left, and the single-defect rule cuts straight down from it.
TEST(SeparationTest, OcclusionLeavesOneDefectAndTheSingleDefectRuleCuts) {
  const std::vector<Ball> balls = Pair(80, 80, 0.2);
  cv::Mat mask = DrawBalls(balls);
  cv::rectangle(mask, cv::Point(0, 300 + 40), cv::Point(799, 599), cv::Scalar(0), cv::FILLED);
  const SeparationResult result = SeparateTouching(mask, SeparationMethod::kConcaveDefects);
  ASSERT_EQ(result.pieces.size(), 2u);
  EXPECT_EQ(result.cuts, 1);
  // The cut is at the neck, halfway between the centres.
  const double neck_x = 0.5 * (balls[0].centre.x + balls[1].centre.x);
  std::vector<cv::Rect> boxes = {cv::boundingRect(result.pieces[0]),
                                 cv::boundingRect(result.pieces[1])};
  std::sort(boxes.begin(), boxes.end(),
            [](const cv::Rect& a, const cv::Rect& b) { return a.x < b.x; });
  EXPECT_NEAR(boxes[0].br().x, neck_x, 3.0);
  EXPECT_NEAR(boxes[1].x, neck_x, 3.0);
  EXPECT_NEAR(boxes[0].x, balls[0].centre.x - 80, 2.0);
  EXPECT_NEAR(boxes[1].br().x, balls[1].centre.x + 80, 2.0);
}

// Thesis figure 5-6(a): two red balls touching a blue one. The red mask is the two red balls
// minus the blue disc, which leaves an extra concavity; the pair rule still cuts the neck.
TEST(SeparationTest, ABallOfAnotherColourBitingIntoThePairAddsNoCut) {
  const std::vector<Ball> balls = Pair(80, 80, 0.15);
  cv::Mat mask = DrawBalls(balls);
  cv::circle(mask, cv::Point(230, 420), 70, cv::Scalar(0), cv::FILLED);
  const SeparationResult result = SeparateTouching(mask, SeparationMethod::kConcaveDefects);
  ASSERT_EQ(result.pieces.size(), 2u);
  EXPECT_EQ(result.cuts, 1);
}

// A lone ball with a slot cut into it (something thin in front of it) has one deep defect
// but is not elongated: it stays one piece.
TEST(SeparationTest, ANotchedSingleBallIsNotCut) {
  cv::Mat mask = DrawBalls({{{400.0, 300.0}, 80}});
  cv::rectangle(mask, cv::Point(400 + 30, 300 - 6), cv::Point(499, 300 + 6), cv::Scalar(0),
                cv::FILLED);
  const SeparationResult result = SeparateTouching(mask, SeparationMethod::kConcaveDefects);
  EXPECT_EQ(result.pieces.size(), 1u);
  EXPECT_EQ(result.cuts, 0);
}

TEST(SeparationTest, SeparateBlobsAreEachSeparatedAndSmallBlobsKept) {
  std::vector<Ball> balls = Pair(70, 70, 0.15);
  balls.push_back({{650.0, 150.0}, 10});  // far smaller than the pair, but a blob of its own
  balls.push_back({{650.0, 450.0}, 60});
  const SeparationResult result =
      SeparateTouching(DrawBalls(balls), SeparationMethod::kConcaveDefects);
  ASSERT_EQ(result.pieces.size(), 4u);
  EXPECT_LE(MaxCentreError(result, balls), 3.0);
}

// Thesis 5.2.3 / figure 5-4: seen from a low angle, a near ball (large, low in the image)
// hides part of a far one (smaller, higher). Ellipses, overlapping by 45 % of the small one's
// height.
TEST(SeparationTest, LowAngleOverlapDefeatsWatershedButNotDefects) {
  cv::Mat mask = cv::Mat::zeros(600, 600, CV_8UC1);
  // The near ellipse's top is at y = 245; the far one reaches 54 px (45 % of 120) below it.
  const cv::Point near_centre(300, 330), far_centre(315, 245 + 54 - 60);
  cv::ellipse(mask, near_centre, cv::Size(100, 85), 0, 0, 360, cv::Scalar(255), cv::FILLED);
  cv::ellipse(mask, far_centre, cv::Size(70, 60), 0, 0, 360, cv::Scalar(255), cv::FILLED);

  EXPECT_EQ(SeparateTouching(mask, SeparationMethod::kNone).pieces.size(), 1u);
  // The distance-transform ridge through the wide neck stays above 0.6 x the peak: one marker.
  EXPECT_EQ(SeparateTouching(mask, SeparationMethod::kWatershed).pieces.size(), 1u);
  // The two side defects survive and their cut is horizontal, across the vertical long side.
  const SeparationResult defects = SeparateTouching(mask, SeparationMethod::kConcaveDefects);
  ASSERT_EQ(defects.pieces.size(), 2u);
  std::vector<cv::Rect> boxes = {cv::boundingRect(defects.pieces[0]),
                                 cv::boundingRect(defects.pieces[1])};
  std::sort(boxes.begin(), boxes.end(),
            [](const cv::Rect& a, const cv::Rect& b) { return a.y < b.y; });
  // The far (upper) piece spans the far ellipse's width; the near piece the near one's.
  EXPECT_NEAR(boxes[0].width, 141, 4);
  EXPECT_NEAR(boxes[1].width, 201, 4);
  EXPECT_NEAR(boxes[0].y, far_centre.y - 60, 2);
  EXPECT_NEAR(boxes[1].br().y, near_centre.y + 86, 2);
}

// Where the concave-defect method stops: once two equal balls overlap by more than about half
// a diameter, the necks are shallower than 0.12 x the blob's equivalent radius and the blob
// is taken for one object. Watershed has long merged them by then.
TEST(SeparationTest, BallsOverlappingByMoreThanHalfAreOnePieceForEveryMethod) {
  const cv::Mat mask = DrawBalls(Pair(100, 100, 0.55));
  for (SeparationMethod method : kAllMethods) {
    EXPECT_EQ(SeparateTouching(mask, method).pieces.size(), 1u) << Name(method);
  }
}

TEST(SeparationTest, SelfTouchingContoursDoNotCrash) {
  // A ring: its outer contour is a circle, the hole is ignored.
  cv::Mat ring = cv::Mat::zeros(400, 400, CV_8UC1);
  cv::circle(ring, cv::Point(200, 200), 100, cv::Scalar(255), 12);
  // Two balls joined by a one-pixel bridge: the contour runs along the bridge twice.
  cv::Mat bridge = DrawBalls({{{200.0, 300.0}, 60}, {{500.0, 300.0}, 60}});
  cv::line(bridge, cv::Point(260, 300), cv::Point(440, 300), cv::Scalar(255), 1);
  // A figure eight of two rings touching at a point, and a comb of one-pixel teeth.
  cv::Mat eight = cv::Mat::zeros(400, 600, CV_8UC1);
  cv::circle(eight, cv::Point(200, 200), 80, cv::Scalar(255), 3);
  cv::circle(eight, cv::Point(361, 200), 80, cv::Scalar(255), 3);
  cv::Mat comb = cv::Mat::zeros(200, 200, CV_8UC1);
  cv::rectangle(comb, cv::Point(20, 20), cv::Point(180, 40), cv::Scalar(255), cv::FILLED);
  for (int x = 20; x <= 180; x += 3) {
    cv::line(comb, cv::Point(x, 40), cv::Point(x, 180), cv::Scalar(255), 1);
  }
  for (const cv::Mat* mask : {&ring, &bridge, &eight, &comb}) {
    for (SeparationMethod method : kAllMethods) {
      EXPECT_NO_THROW(SeparateTouching(*mask, method)) << Name(method);
    }
  }
  // The ring is one object; the bridged balls are cut at the bridge (the 1-px bridge itself
  // falls below the minimum piece area).
  EXPECT_EQ(SeparateTouching(ring, SeparationMethod::kConcaveDefects).pieces.size(), 1u);
  EXPECT_EQ(SeparateTouching(bridge, SeparationMethod::kConcaveDefects).pieces.size(), 2u);
}

// Random blobs, speckle and lines: every method returns without throwing, and every piece
// it returns lies on the mask.
TEST(SeparationTest, RandomMasksDoNotCrash) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> x(0, 319), y(0, 239), radius(1, 60), count(1, 12);
  for (int trial = 0; trial < 60; ++trial) {
    cv::Mat mask = cv::Mat::zeros(240, 320, CV_8UC1);
    for (int i = count(rng); i > 0; --i) {
      cv::circle(mask, cv::Point(x(rng), y(rng)), radius(rng), cv::Scalar(255), cv::FILLED);
      cv::circle(mask, cv::Point(x(rng), y(rng)), radius(rng) / 3, cv::Scalar(0), cv::FILLED);
      cv::line(mask, cv::Point(x(rng), y(rng)), cv::Point(x(rng), y(rng)), cv::Scalar(trial % 2),
               1 + trial % 3);
    }
    for (SeparationMethod method : kAllMethods) {
      SeparationResult result;
      ASSERT_NO_THROW(result = SeparateTouching(mask, method)) << "trial " << trial;
      for (const auto& piece : result.pieces) {
        ASSERT_FALSE(piece.empty());
        const cv::Rect box = cv::boundingRect(piece);
        EXPECT_TRUE((box & cv::Rect(0, 0, mask.cols, mask.rows)) == box);
      }
    }
  }
}

TEST(SeparationTest, AnEmptyMaskGivesNoPieces) {
  const cv::Mat mask = cv::Mat::zeros(100, 100, CV_8UC1);
  for (SeparationMethod method : kAllMethods) {
    const SeparationResult result = SeparateTouching(mask, method);
    EXPECT_TRUE(result.pieces.empty()) << Name(method);
    EXPECT_EQ(result.passes, 0);
    EXPECT_EQ(result.cuts, 0);
  }
}

TEST(SeparationTest, AnyNonZeroValueIsObject) {
  cv::Mat mask = DrawBalls(Pair(60, 60, 0.1));
  mask.setTo(1, mask != 0);
  EXPECT_EQ(SeparateTouching(mask, SeparationMethod::kConcaveDefects).pieces.size(), 2u);
  EXPECT_EQ(SeparateTouching(mask, SeparationMethod::kWatershed).pieces.size(), 2u);
}

TEST(SeparationTest, BadMasksThrowInvalidArgument) {
  const cv::Mat empty;
  const cv::Mat colour = cv::Mat::zeros(10, 10, CV_8UC3);
  const cv::Mat floating = cv::Mat::zeros(10, 10, CV_32FC1);
  const cv::Mat wide = cv::Mat::zeros(10, 10, CV_16UC1);
  for (SeparationMethod method : kAllMethods) {
    EXPECT_THROW(SeparateTouching(empty, method), std::invalid_argument);
    EXPECT_THROW(SeparateTouching(colour, method), std::invalid_argument);
    EXPECT_THROW(SeparateTouching(floating, method), std::invalid_argument);
    EXPECT_THROW(SeparateTouching(wide, method), std::invalid_argument);
  }
  try {
    SeparateTouching(colour, SeparationMethod::kConcaveDefects);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("3 channels"), std::string::npos) << e.what();
  }
}

TEST(SeparationTest, ParseSeparationMethod) {
  EXPECT_EQ(ParseSeparationMethod("defects"), SeparationMethod::kConcaveDefects);
  EXPECT_EQ(ParseSeparationMethod("watershed"), SeparationMethod::kWatershed);
  EXPECT_EQ(ParseSeparationMethod("none"), SeparationMethod::kNone);
  EXPECT_THROW(ParseSeparationMethod("Defects"), std::invalid_argument);
  EXPECT_THROW(ParseSeparationMethod(""), std::invalid_argument);
  try {
    ParseSeparationMethod("blobs");
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("defects, watershed, none"), std::string::npos);
  }
}

// FillOutline(s) fill exactly what cv::drawContours(FILLED, LINE_8) does: traced outlines of
// random blobs (holes too, several at once, shifted), and simplified ones (its own fallback).
TEST(ContourFillTest, SameAsDrawContours) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 250; ++trial) {
    const int w = 2 + static_cast<int>(rng() % 120), h = 2 + static_cast<int>(rng() % 120);
    cv::Mat mask = cv::Mat::zeros(h, w, CV_8UC1);
    for (int s = 0; s < 4; ++s) {
      const cv::Point c(static_cast<int>(rng() % w), static_cast<int>(rng() % h));
      cv::ellipse(mask, c, cv::Size(1 + rng() % 40, 1 + rng() % 25), rng() % 180, 0, 360,
                  cv::Scalar(255), cv::FILLED);
    }
    cv::Mat noise(h, w, CV_8UC1);
    cv::randu(noise, 0, 255);
    mask.setTo(0, noise < 40);
    std::vector<std::vector<cv::Point>> outlines;
    cv::findContours(mask, outlines, trial % 2 ? cv::RETR_EXTERNAL : cv::RETR_LIST,
                     cv::CHAIN_APPROX_NONE);
    if (trial % 5 == 0 && !outlines.empty()) {
      cv::approxPolyDP(std::vector<cv::Point>(outlines[0]), outlines[0], 1.0, true);
    }
    const cv::Point offset(static_cast<int>(rng() % 4), static_cast<int>(rng() % 4));
    const cv::Size size(w + 4, h + 4);
    for (const std::vector<cv::Point>& outline : outlines) {
      cv::Mat expected = cv::Mat::zeros(size, CV_8UC1), filled = cv::Mat::zeros(size, CV_8UC1);
      cv::drawContours(expected, std::vector<std::vector<cv::Point>>{outline}, 0, cv::Scalar(255),
                       cv::FILLED, cv::LINE_8, cv::noArray(), 0, offset);
      FillOutline(outline, offset, &filled);
      ASSERT_EQ(cv::norm(expected, filled, cv::NORM_INF), 0.0) << "trial " << trial;
    }
    cv::Mat expected = cv::Mat::zeros(size, CV_8UC1), filled = cv::Mat::zeros(size, CV_8UC1);
    cv::drawContours(expected, outlines, -1, cv::Scalar(255), cv::FILLED, cv::LINE_8, cv::noArray(),
                     INT_MAX, offset);
    FillOutlines(outlines, offset, &filled);
    ASSERT_EQ(cv::norm(expected, filled, cv::NORM_INF), 0.0) << "trial " << trial;
  }
}

}  // namespace
}  // namespace slamo::vision
