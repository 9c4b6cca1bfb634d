#include "autonomy/experiments/vision_eval.h"

#include <gtest/gtest.h>

#include <functional>

#include "field_configs/loader.h"

namespace slamo::autonomy {
namespace {

std::vector<VisionMethodScore> Scores(const std::string& season_name, int frames, uint64_t seed,
                                      bool arena, VisionEvalOptions options = {}) {
  const field::SeasonConfig season = field::LoadSeasonConfig(season_name);
  options.frames = frames;
  options.seed = seed;
  options.arena = arena;
  return EvaluateVision(season, field::LoadRobotConfig("thesis_robot"), options);
}

// A detector change against the detector without it (`with` and `without`), per method on
// `frames` arena views of `season`, seed 1: `each` checks every method's pair of scores; the
// false detections (on pieces of objects, on robots, on anything else) and the objects found
// are summed over the methods.
struct ArenaComparison {
  int on_pieces = 0, on_pieces_without = 0;
  int on_robots = 0, on_robots_without = 0;
  int on_other = 0, on_other_without = 0;
  int found = 0, found_without = 0;
};
ArenaComparison CompareInArena(
    const std::string& season, int frames, const VisionEvalOptions& with,
    const VisionEvalOptions& without,
    const std::function<void(const VisionMethodScore&, const VisionMethodScore&)>& each) {
  const std::vector<VisionMethodScore> a = Scores(season, frames, 1, true, with);
  const std::vector<VisionMethodScore> b = Scores(season, frames, 1, true, without);
  EXPECT_EQ(a.size(), b.size());
  ArenaComparison sums;
  for (size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
    SCOPED_TRACE(a[k].name);
    each(a[k], b[k]);
    sums.on_pieces += a[k].false_pieces;
    sums.on_pieces_without += b[k].false_pieces;
    sums.on_robots += a[k].false_on_robots;
    sums.on_robots_without += b[k].false_on_robots;
    sums.on_other += a[k].false_other;
    sums.on_other_without += b[k].false_other;
    sums.found += a[k].found;
    sums.found_without += b[k].found;
  }
  return sums;
}

// In the arena, the field gate drops the crowd, posters and lights beyond the perimeter:
// precision with it beats precision without it by a wide margin for every method, and it
// drops no real object. Measured with `slamo eval vision --season toss_up --arena --frames 10
// --seed 1`: +0.35 for the smallest gain (0.837 against 0.488 for threshold+defects), no
// object dropped; the test asks for +0.25. Among the dropped, 1-4 per method lie inside or on
// a structure of their own colour (the red and blue stashes, the alliance-coloured posts).
TEST(VisionEvalTest, ArenaPrecisionIsBetterWithTheFieldGate) {
  const std::vector<VisionMethodScore> scores = Scores("toss_up", 10, 1, true);
  ASSERT_EQ(scores.size(), 6u);
  for (const VisionMethodScore& s : scores) {
    SCOPED_TRACE(s.name);
    EXPECT_GT(s.rejected_by_geometry, 10);
    EXPECT_GT(s.rejected_structure, 0);
    EXPECT_EQ(s.rejected_objects, 0);
    EXPECT_GT(s.Precision(), s.RawPrecision() + 0.25);
    EXPECT_GT(s.expected, 20);
  }
}

// The same seed gives the same scores; the clean field (no arena) has almost nothing for the
// gate to drop. The gate alone: without the bulge test, which drops some of the crowd's flat
// round blobs before the gate sees them (in these 4 views, all of them for the `none` methods).
TEST(VisionEvalTest, DeterministicPerSeedAndTheCleanFieldHasLittleToReject) {
  VisionEvalOptions gate_only;
  gate_only.detect.min_bulge_ratio = 0.0;
  const std::vector<VisionMethodScore> a = Scores("over_under", 4, 3, true, gate_only);
  const std::vector<VisionMethodScore> b = Scores("over_under", 4, 3, true, gate_only);
  EXPECT_EQ(FormatVisionTable(a), FormatVisionTable(b));
  EXPECT_EQ(FormatVisionTable(Scores("over_under", 4, 3, true)),
            FormatVisionTable(Scores("over_under", 4, 3, true)));
  const std::vector<VisionMethodScore> clean = Scores("over_under", 4, 3, false, gate_only);
  for (size_t k = 0; k < a.size(); ++k) {
    // Off the field (the stands, posters): only in the arena. (Structures of an object's
    // colour are on the clean field too, so those are left out of the comparison.)
    EXPECT_LT(clean[k].rejected_by_geometry - clean[k].rejected_structure,
              a[k].rejected_by_geometry - a[k].rejected_structure)
        << a[k].name;
    EXPECT_EQ(clean[k].rejected_objects, 0) << a[k].name;
  }
}

// Shapes per type (#16 item 3): Starstruck's stars have concave outlines of their own, which
// the concave-defect cut took for touching objects, and the pieces failed the shape and size
// tests. With depth, a blob no larger than one star or cube can look is not cut. Measured with
// `slamo eval vision --season starstruck --frames 10 --seed 1`, threshold+defects: recall
// 0.958 with the rule, 0.583 without it (extent_margin_px -1e9); the test asks for +0.2.
TEST(VisionEvalTest, StarsAreFoundWholeOnlyWithTheSizeRule) {
  const auto recall = [](const std::vector<VisionMethodScore>& scores) {
    return scores.at(0).Recall();  // threshold+defects
  };
  VisionEvalOptions without;
  without.detect.extent_margin_px = -1e9;
  without.detect.split_by_size = false;  // the split by size keeps them whole too
  const std::vector<VisionMethodScore> with_rule = Scores("starstruck", 10, 1, false);
  const std::vector<VisionMethodScore> without_rule = Scores("starstruck", 10, 1, false, without);
  ASSERT_EQ(with_rule.at(0).name, "threshold+defects");
  EXPECT_GT(recall(with_rule), recall(without_rule) + 0.2);
  EXPECT_GE(with_rule.at(0).Precision(), without_rule.at(0).Precision());
}

// Round solid kinds must curve away from the camera (DetectOptions::min_bulge_ratio): in the
// Over Under arena the opponents' red and blue bumpers, cut into triball-sized pieces, are
// flat and dropped. Measured with `slamo eval vision --season over_under --arena --frames 20
// --seed 1 --no-sphere-split [--no-bulge-test]`: precision +0.093 (threshold+defects, 0.807 ->
// 0.900) to +0.239 (kmeans+watershed, 0.736 -> 0.975) per method, recall the same or 0.022
// lower (one triball of 45); the test asks for +0.08 and -0.04. Without the sphere split that
// came after it (DetectOptions::split_spheres), whose own curvature test drops some of the same
// pieces: with it, the bulge test adds +0.076 to +0.183. (On the first 10 of these views, since
// the split by size no longer shrinks the blob it is given, threshold+watershed and
// threshold+none keep the same one false detection with the test or without.)
TEST(VisionEvalTest, FlatFacesAreNotTakenForRoundObjects) {
  VisionEvalOptions with;
  with.detect.split_spheres = false;
  VisionEvalOptions without = with;
  without.detect.min_bulge_ratio = 0.0;
  const std::vector<VisionMethodScore> with_test = Scores("over_under", 20, 1, true, with);
  const std::vector<VisionMethodScore> without_test = Scores("over_under", 20, 1, true, without);
  ASSERT_EQ(with_test.size(), without_test.size());
  for (size_t k = 0; k < with_test.size(); ++k) {
    SCOPED_TRACE(with_test[k].name);
    EXPECT_GT(with_test[k].Precision(), without_test[k].Precision() + 0.08);
    EXPECT_GE(with_test[k].Recall(), without_test[k].Recall() - 0.04);
  }
}

// Touching balls are counted by their centres (DetectOptions::split_spheres): in the Nothing
// but Net arena, with its pyramids of three balls and heaps of driver loads, every method
// finds more balls, keeps no more false detections and counts more touching groups right.
// Measured with `slamo eval vision --season nothing_but_net --arena --frames 10 --seed 1
// [--no-sphere-split]`: recall +0.17 (threshold+defects, 0.805 -> 0.977) to +0.62
// (kmeans+none, 0.299 -> 0.920), precision 0.87-0.95 -> 0.991-0.992, groups counted right
// 0.04-0.71 -> 0.88-0.96 of 24; the test asks for +0.1 recall, no precision lost and more
// groups counted right. Both with the curvature test judging the curvature nearest zero, as
// then: judging the lowest (DetectOptions::convex_curvature) drops pieces spanning two balls,
// whose valley curves towards the camera, and without the split the threshold methods' 3 false
// detections on these views go (precision 1.000, recall 0.793 -> 0.770, threshold+defects).
TEST(VisionEvalTest, TouchingBallsAreCountedByTheirCentres) {
  VisionEvalOptions with;
  with.detect.convex_curvature = false;
  VisionEvalOptions without = with;
  without.detect.split_spheres = false;
  const std::vector<VisionMethodScore> with_split = Scores("nothing_but_net", 10, 1, true, with);
  const std::vector<VisionMethodScore> without_split =
      Scores("nothing_but_net", 10, 1, true, without);
  ASSERT_EQ(with_split.size(), without_split.size());
  for (size_t k = 0; k < with_split.size(); ++k) {
    SCOPED_TRACE(with_split[k].name);
    EXPECT_GT(with_split[k].Recall(), without_split[k].Recall() + 0.1);
    EXPECT_GE(with_split[k].Precision(), without_split[k].Precision());
    EXPECT_GT(with_split[k].groups_counted, without_split[k].groups_counted);
  }
}

// A piece of the cut that no circle fits is split by the balls' centres in it
// (DetectOptions::split_sphere_pieces): in the Toss Up arena, two buckyballs one behind
// another beside a large ball of their colour, which the whole blob's split cannot explain,
// are found. Measured with `slamo eval vision --season toss_up --arena --frames 20 --seed 1
// [--no-sphere-pieces]`: recall +0.014 (threshold+defects, 0.683 -> 0.697) and +0.028
// (kmeans+defects, 0.817 -> 0.845), groups counted right 8 -> 9 and 9 -> 11 of 15, precision
// +0.002 each; the other methods (whose cut leaves no such piece) the same. The test
// asks for no method worse and 4 more objects found over the six. (Measured before the
// semi-transparent balls found by their depth, below, which find some of the same balls: both
// sides without them. With them, the step adds 2 objects over the six, all kmeans+defects.)
TEST(VisionEvalTest, BallsLeftTogetherByTheCutAreCountedByTheirCentres) {
  VisionEvalOptions with;
  with.detect.semi_sphere_pieces = false;
  VisionEvalOptions without = with;
  without.detect.split_sphere_pieces = false;
  const ArenaComparison r = CompareInArena(
      "toss_up", 20, with, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GE(a.Precision(), b.Precision());
        EXPECT_GE(a.found, b.found);
        EXPECT_GE(a.groups_counted, b.groups_counted);
      });
  EXPECT_GE(r.found, r.found_without + 4);
}

// With depth, kinds that fit a piece by size but stand at different heights are told apart
// by the height its points span (DetectOptions::type_height_ratio): Starstruck's stars lying
// flat (9 cm) and its cubes (25 cm), of one colour and nearly one size. Measured with `slamo
// eval vision --season starstruck --arena --frames 20 --seed 1`, `kmeans+defects`: typed
// right, cubes 1 -> 10 of 11, stars 0 -> 25 of 27 (by size alone most stars were typed cubes).
// The test asks for 0.8 of each with the rule, and that by size alone it was under 0.3.
TEST(VisionEvalTest, StarsAndCubesAreTypedByTheirHeight) {
  VisionEvalOptions without;
  without.detect.type_height_ratio = 0.0;
  const VisionMethodScore with_rule = Scores("starstruck", 20, 1, true).at(3);
  const VisionMethodScore without_rule = Scores("starstruck", 20, 1, true, without).at(3);
  ASSERT_EQ(with_rule.name, "kmeans+defects");
  for (const char* type : {"cube", "star"}) {
    SCOPED_TRACE(type);
    const TypeScore& a = with_rule.types.at(type);
    const TypeScore& b = without_rule.types.at(type);
    ASSERT_GT(a.typed, 5);
    ASSERT_GT(b.typed, 5);
    EXPECT_GE(a.typed_right, 0.8 * a.typed);
    EXPECT_LT(b.typed_right, 0.3 * b.typed);
  }
}

// Nothing floats (DetectOptions::drop_floating): in the High Stakes arena the opponents'
// bumpers, held 2 cm off the floor, were cut into ring-sized pieces; under them the camera sees
// the floor behind the gap, so they are cleared, while rings, which stand on the floor or on
// each other, are all kept. Measured with `slamo eval vision --season high_stakes --arena
// --frames 10 --seed 1 [--no-float-test]`: false detections on robots 59 -> 22 over the six
// methods, precision +0.04 to +0.19 per method, recall the same; the test asks for half the
// false detections on robots, no precision lost and no recall lost.
TEST(VisionEvalTest, BumpersOffTheFloorAreNotTakenForRings) {
  VisionEvalOptions without;
  without.detect.drop_floating = false;
  const ArenaComparison r = CompareInArena(
      "high_stakes", 10, {}, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GE(a.Precision(), b.Precision());
        EXPECT_EQ(a.found, b.found);
      });
  EXPECT_GT(r.on_robots_without, 20);
  EXPECT_LE(2 * r.on_robots, r.on_robots_without);
}

// Round kinds must curve in every direction (DetectOptions::flat_curvature_ratio): pieces of
// an opponent's bumper running diagonally in the image, which the bulge test's row and column
// bands take for triballs, are dropped. Measured with `slamo eval vision --season over_under
// --arena --frames 50 --seed 1 --no-attach-test [--no-curvature-test]`: false detections on
// robots 156 -> 118 over the six methods (159 -> 103 when the split by size still shrank the
// blob it was given), precision up for each, the same triballs found; the test asks for a fifth
// fewer. Both without the attach test that came after it (below), which drops many of the same
// pieces.
TEST(VisionEvalTest, BumperPiecesFlatAlongTheirLengthAreNotTakenForTriballs) {
  VisionEvalOptions with;
  with.detect.attach_margin_ratio = 0.0;
  with.detect.convex_curvature = false;  // unsigned, as then (below: signed)
  VisionEvalOptions without = with;
  without.detect.flat_curvature_ratio = 0.0;
  const ArenaComparison r = CompareInArena(
      "over_under", 50, with, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GT(a.Precision(), b.Precision());
      });
  EXPECT_GT(r.on_robots_without, 100);
  EXPECT_LT(r.on_robots, 0.8 * r.on_robots_without);
  EXPECT_GE(r.found, r.found_without - 2);
}

// The curvature test is signed (DetectOptions::convex_curvature): a piece of a bumper cut at
// its concave defects, whose surface curves towards the camera along some direction (a saddle
// where the bumper meets its chassis, a hollow), is dropped however strongly it curves; a
// triball curves away every way. Measured with `slamo eval vision --season over_under --arena
// --frames 30 --seed 1 [--either-curvature]`: false detections on robots 25 -> 10 over the six
// methods, precision up for each (kmeans+defects 0.929 -> 0.958), the same triballs found.
TEST(VisionEvalTest, BumperPiecesCurvingTowardsTheCameraAreNotTakenForTriballs) {
  VisionEvalOptions without;
  without.detect.convex_curvature = false;
  const ArenaComparison r = CompareInArena(
      "over_under", 30, {}, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GT(a.Precision(), b.Precision());
      });
  EXPECT_GT(r.on_robots_without, 18);
  EXPECT_LE(2 * r.on_robots, r.on_robots_without);
  EXPECT_EQ(r.found, r.found_without);
}

// A piece split off by size under a tenth of the smallest kind's apparent area at its depth
// is a strip of a rim, not an object (DetectOptions::min_sized_area_ratio): High Stakes' rings
// seen from under a metre, whose rims' mixed readings cluster apart on the floor, are no
// longer counted two or three times. Measured with `slamo eval vision --season high_stakes
// --arena --frames 20 --seed 1 --same-depth-cut [--keep-small-pieces]`: false detections on pieces
// and on nothing 15 -> 3 over the six methods, precision up for each (kmeans+defects 0.879 ->
// 0.921), the same objects found.
TEST(VisionEvalTest, StripsOfARimAreNotObjects) {
  VisionEvalOptions with;
  with.detect.depth_cut_min_flat_m = 0.0;  // as then: the 0.1 m cut parts many strips off too
  VisionEvalOptions without = with;
  without.detect.min_sized_area_ratio = 0.0;
  const ArenaComparison r = CompareInArena(
      "high_stakes", 20, with, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GT(a.Precision(), b.Precision());
        EXPECT_EQ(a.found, b.found);
      });
  EXPECT_GE(r.on_pieces_without + r.on_other_without, 10);
  EXPECT_LE(2 * (r.on_pieces + r.on_other), r.on_pieces_without + r.on_other_without);
}

// The top of a round piece must not run on into a taller body (DetectOptions::
// attach_margin_ratio): pieces of the opponents' bumpers, under their chassis, are dropped and
// no triball is lost. Measured with `slamo eval vision --season over_under --arena --frames 30
// --seed 1 [--no-attach-test]`: false detections on robots 58 -> 23 over the six methods,
// precision up for each (kmeans+defects 0.824 -> 0.886), recall the same for each. With the
// curvature test unsigned, as it was then (the signed test above drops many of the same).
TEST(VisionEvalTest, BumperPiecesUnderTheirChassisAreNotTakenForTriballs) {
  VisionEvalOptions with;
  with.detect.convex_curvature = false;
  VisionEvalOptions without = with;
  without.detect.attach_margin_ratio = 0.0;
  const ArenaComparison r = CompareInArena(
      "over_under", 30, with, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GT(a.Precision(), b.Precision());
        EXPECT_EQ(a.found, b.found);
      });
  EXPECT_GT(r.on_robots_without, 40);
  EXPECT_LT(2 * r.on_robots, r.on_robots_without);
}

// A sliver in a pile (a cube hidden behind others or cut by the image's edge shows a thin
// group on the floor) no longer refuses the whole pile's split by size
// (SizeSplitOptions::sliver_fraction): Skyrise's strips of touching cubes are found. Measured
// with `slamo eval vision --season skyrise --arena --frames 20 --seed 1 [--no-sliver-drop]`:
// recall +0.24 to +0.33 per method (kmeans+defects 0.697 -> 0.895), precision -0.014 to
// +0.012. Since colour masks are cut at depth edges (DetectOptions::depth_cut_min_m), which
// takes many cubes apart from what stands behind them, less is left for it: recall +0.048 to
// +0.099 (kmeans+defects 0.876 -> 0.930), precision -0.025 to +0.001. The test asks for +0.04
// of recall and at most 0.03 of precision lost, per method.
TEST(VisionEvalTest, ASliverDoesNotRefuseAPileOfCubes) {
  VisionEvalOptions with;
  with.detect.depth_cut_min_flat_m = 0.0;  // as then: the 0.1 m cut parts many piles too
  VisionEvalOptions without = with;
  without.detect.size_split.sliver_fraction = 0.0;
  CompareInArena("skyrise", 20, with, without,
                 [](const VisionMethodScore& a, const VisionMethodScore& b) {
                   EXPECT_GT(a.Recall(), b.Recall() + 0.04);
                   EXPECT_GT(a.Precision(), b.Precision() - 0.03);
                 });
}

// Each group split off by size must be at least 0.6 of an object's width deep on the floor
// (SizeSplitOptions::min_top_depth; an object seen from above shows its top and its front): an
// opponent's bumper, 6 cm thick, is not cut into Skyrise's 15 cm cubes. Against 0.35 (which,
// with slivers dropped, let most bumpers through), on these 20 views: false detections on
// robots 380 -> 190 over the six methods, precision +0.07 to +0.09 per method (kmeans+defects
// 0.725 -> 0.811), for recall 0.971-0.984 -> 0.815-0.939 (cubes partly hidden at the side are
// thin too). The test asks for a third fewer on robots, +0.05 of precision and recall kept
// at 0.8 or more, per method. Both with pieces of any size kept, as then (dropping strips of
// a rim, DetectOptions::min_sized_area_ratio, takes many of the same bumper pieces at 0.35).
TEST(VisionEvalTest, BumpersAreNotCutIntoCubes) {
  VisionEvalOptions with;
  with.detect.min_sized_area_ratio = 0.0;
  with.detect.depth_cut_min_flat_m = 0.0;  // and the cut at 0.25 m, as then
  VisionEvalOptions without = with;
  without.detect.size_split.min_top_depth = 0.35;
  const ArenaComparison r = CompareInArena(
      "skyrise", 20, with, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GT(a.Precision(), b.Precision() + 0.05);
        EXPECT_GE(a.Recall(), 0.8);
      });
  EXPECT_GT(r.on_robots_without, 200);
  EXPECT_LT(3 * r.on_robots, 2 * r.on_robots_without);
}

// A piece taller than its kind can stand (DetectOptions::drop_too_tall) is not one: High
// Stakes' upright blue and red bars are no longer rings. Measured on these 20 arena views:
// false detections on neither objects nor robots 19 -> 9 over the six methods, precision
// +0.009 to +0.024 per method, the same objects found; the test asks for that, with 0.6 of
// the other false detections.
TEST(VisionEvalTest, UprightBarsAreNotTakenForRings) {
  VisionEvalOptions without;
  without.detect.drop_too_tall = false;
  const ArenaComparison r = CompareInArena(
      "high_stakes", 20, {}, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GT(a.Precision(), b.Precision());
        EXPECT_EQ(a.found, b.found);
      });
  EXPECT_GT(r.on_other_without, 12);
  EXPECT_LT(r.on_other, 0.6 * r.on_other_without);
}

// The groups split off by size are grown back over the blob's rim only onto pixels no other
// group holds (SizeSplitOptions::exclusive_growth): overlapping, neighbouring pieces made a
// second detection on one object or one spanning two. Measured on these 20 Skyrise arena
// views: false detections on pieces of objects 187 -> 154 over the six methods (199 -> 142
// when the split by size still shrank the blob it was given, and the pieces grew over less),
// precision up for each method, the same objects found. Since colour masks are cut at depth
// edges (DetectOptions::depth_cut_min_m): 139 -> 109, precision up for each method, the same
// objects found by the threshold and one more by each K-Means method. The test asks for a
// seventh fewer, precision up and no object lost, per method.
TEST(VisionEvalTest, PiecesSplitBySizeDoNotOverlap) {
  VisionEvalOptions without;
  without.detect.size_split.exclusive_growth = false;
  const ArenaComparison r = CompareInArena(
      "skyrise", 20, {}, without, [](const VisionMethodScore& a, const VisionMethodScore& b) {
        EXPECT_GT(a.Precision(), b.Precision());
        EXPECT_GE(a.found, b.found);
      });
  EXPECT_GT(r.on_pieces_without, 120);
  EXPECT_LT(7 * r.on_pieces, 6 * r.on_pieces_without);
}

// Piles (#16 item 4): `--pile 10,30` puts a heap of touching blocks in every view; split by
// their known size they are counted, without it hardly at all. Measured with `slamo eval
// vision --season push_back --frames 6 --seed 1 --pile 10,30 [--no-size-split]`,
// threshold+defects: 5 piles, 60 of 82 visible blocks counted (mean error 0.28) against 4
// (0.94); the test asks for half the error.
TEST(VisionEvalTest, PilesAreCountedWithTheSplitBySize) {
  VisionEvalOptions with;
  with.pile_min = 10;
  with.pile_max = 30;
  VisionEvalOptions without = with;
  without.detect.split_by_size = false;
  const VisionMethodScore a = Scores("push_back", 6, 1, false, with).at(0);
  const VisionMethodScore b = Scores("push_back", 6, 1, false, without).at(0);
  ASSERT_EQ(a.name, "threshold+defects");
  EXPECT_GE(a.piles, 4);
  EXPECT_EQ(a.piles, b.piles);
  EXPECT_EQ(a.pile_visible, b.pile_visible);
  EXPECT_LT(a.pile_abs_error_ratio_sum, 0.5 * b.pile_abs_error_ratio_sum);
  EXPECT_GT(a.pile_detected, 2 * b.pile_detected);
}

// Objects that overlap in the image but lie apart on the floor are not one group (#16): the
// split by size takes each stack level's footprint apart at its gaps before clustering it, so
// no group spans two Skyrise cubes standing apart, and no cube is cut to make the others fit.
// Measured with this test's own figures (20 arena views, seed 1), one part -> parts:
// threshold+defects precision 0.751 -> 0.805, recall 0.812 -> 0.818, groups counted right
// 25 -> 31 of 50; kmeans+defects 0.684 -> 0.753, 0.803 -> 0.822, 19 -> 29 of 50 (0.672 ->
// 0.718 and 0.616 -> 0.684 before floating bumpers were cleared). Since colour masks are cut
// at depth edges (DetectOptions::depth_cut_min_m), which parts some of those objects itself:
// threshold+defects 0.853 -> 0.859, 0.943 -> 0.959, groups 32 -> 36 of 50; kmeans+defects
// 0.826 -> 0.861, 0.930 -> 0.930, 32 -> 36. The test asks for precision up, no recall lost,
// and three more groups counted right.
TEST(VisionEvalTest, ObjectsApartOnTheFloorAreNotCutByTheSizeSplit) {
  VisionEvalOptions as_then;
  as_then.detect.depth_cut_min_flat_m = 0.0;  // the 0.1 m cut parts many of them too
  VisionEvalOptions one_part = as_then;
  one_part.detect.size_split.link_fraction = 0.0;  // as before: a level is one part
  const std::vector<VisionMethodScore> parts = Scores("skyrise", 20, 1, true, as_then);
  const std::vector<VisionMethodScore> whole = Scores("skyrise", 20, 1, true, one_part);
  ASSERT_EQ(parts.size(), whole.size());
  for (size_t k : {0, 3}) {
    SCOPED_TRACE(parts[k].name);
    EXPECT_GT(parts[k].Precision(), whole[k].Precision());
    EXPECT_GE(parts[k].Recall(), whole[k].Recall());
    ASSERT_GT(parts[k].groups, 20);
    EXPECT_GE(parts[k].groups_counted, whole[k].groups_counted + 3);
  }
}

// Colour masks are cut where the depth jumps (DetectOptions::depth_cut_min_m): a block or a
// cube seen against a poster, a shirt or an alliance wall of its colour far behind it is a
// blob of its own instead of a part of that one. Measured on these 20 arena views, without ->
// with the cut: Push Back recall +0.107 to +0.155 per method (kmeans+defects 0.660 -> 0.777),
// precision +0.003 to +0.035; Skyrise recall +0.020 to +0.061 (0.892 -> 0.930), precision
// +0.009 to +0.047, false detections on pieces of cubes 154 -> 109 over the six methods. The
// test asks for precision up and +0.015 of recall, per method and season. With the cut at
// 0.25 m for every colour, as then (below: 0.1 m for colours with no round kind).
TEST(VisionEvalTest, ObjectsBeforeThingsOfTheirColourAreFound) {
  VisionEvalOptions with;
  with.detect.depth_cut_min_flat_m = 0.0;
  VisionEvalOptions without = with;
  without.detect.depth_cut_min_m = 0.0;
  for (const char* season : {"push_back", "skyrise"}) {
    SCOPED_TRACE(season);
    CompareInArena(season, 20, with, without,
                   [](const VisionMethodScore& a, const VisionMethodScore& b) {
                     EXPECT_GT(a.Precision(), b.Precision());
                     EXPECT_GT(a.Recall(), b.Recall() + 0.015);
                   });
  }
}

// Colours with no round kind are cut at a depth step of 0.1 m, not 0.25 m
// (DetectOptions::depth_cut_min_flat_m): a block touching, in the image, a structure of its
// colour a little behind it (a long goal's base) is cut from it, and the split by size, which
// refused the blob (its top at no whole number of block heights), counts it. Measured with
// `slamo eval vision --season push_back --arena --frames 20 --seed 1 [--same-depth-cut]`:
// recall +0.030 to +0.039 per method (kmeans+defects 0.883 -> 0.922), precision -0.014 to
// +0.006, groups counted right 21-22 -> 22-23 of 28. The test asks for +0.02 of recall, at most
// 0.02 of precision lost and no group fewer, per method.
TEST(VisionEvalTest, BlocksBesideAStructureOfTheirColourAreCut) {
  VisionEvalOptions without;
  without.detect.depth_cut_min_flat_m = 0.0;
  CompareInArena("push_back", 20, {}, without,
                 [](const VisionMethodScore& a, const VisionMethodScore& b) {
                   EXPECT_GT(a.Recall(), b.Recall() + 0.02);
                   EXPECT_GT(a.Precision(), b.Precision() - 0.02);
                   EXPECT_GE(a.groups_counted, b.groups_counted);
                 });
}

// Objects rest on what the season file places them on, not only on the floor
// (ObjectExtent::rest_heights_m): Push Back's blocks on its long goals, 0.40 m up, are split
// by their size, and their top faces, seen edge on from a camera at about their height, are
// not asked for. Measured on these 20 arena views, without -> with: recall +0.106 to +0.117
// per method (kmeans+defects 0.777 -> 0.883), groups counted right 11-12 -> 21-22 of 28,
// precision -0.006 to +0.024. The test asks for +0.08 of recall, seven more groups and at
// most 0.015 of precision lost, per method.
TEST(VisionEvalTest, BlocksOnTheLongGoalsAreCountedOneByOne) {
  VisionEvalOptions without;
  without.detect.size_split.rest_on_supports = false;
  CompareInArena("push_back", 20, {}, without,
                 [](const VisionMethodScore& a, const VisionMethodScore& b) {
                   EXPECT_GT(a.Recall(), b.Recall() + 0.08);
                   EXPECT_GE(a.groups_counted, b.groups_counted + 7);
                   EXPECT_GT(a.Precision(), b.Precision() - 0.015);
                 });
}

// A semi-transparent ball's blob whose outline is a circle it fills is that ball, one piece,
// before the cut at concave defects (DetectOptions::min_disc_fill, min_disc_outline): Toss
// Up's large balls, notched where buckyballs, highlights and the floor show through them, were
// cut apart there, and so were the groups they touch. Measured on these 20 arena views,
// without -> with: groups counted right +2 to +3 per method (kmeans+defects 8 -> 11), recall
// the same or higher (kmeans+defects 0.803 -> 0.845), kmeans+defects precision 0.946 ->
// 0.949; the other methods' precision -0.022 to +0.008. The test asks for +2 groups and no
// object fewer per method, and kmeans+defects' precision no lower and recall +0.03.
// (Measured before the semi-transparent balls found by their depth, below: both sides
// without them.)
TEST(VisionEvalTest, SemiTransparentBallsAreNotCutWhereThingsShowThrough) {
  VisionEvalOptions with;
  with.detect.semi_sphere_pieces = false;
  VisionEvalOptions without = with;
  without.detect.min_disc_fill = 0.0;
  CompareInArena("toss_up", 20, with, without,
                 [](const VisionMethodScore& a, const VisionMethodScore& b) {
                   EXPECT_GE(a.groups_counted, b.groups_counted + 2);
                   EXPECT_GE(a.found, b.found);
                   if (a.name == "kmeans+defects") {
                     EXPECT_GE(a.Precision(), b.Precision());
                     EXPECT_GT(a.Recall(), b.Recall() + 0.03);
                   }
                 });
}

// A semi-transparent ball whose blob no circle fits (ragged where the background shows
// through it, cut apart at its notches, or clipped by the image's edge) is found by its depth:
// on the front of one ball of the kind's size, filling half its disc in the image
// (DetectOptions::semi_sphere_pieces), with K-Means, and with the threshold when asked
// (semi_sphere_threshold). Measured on these 20 arena views (`slamo eval vision --season
// toss_up --arena --frames 20 --seed 1 [--no-semi-spheres | --semi-spheres-threshold]`),
// without -> with: semi-transparent recall +0.04 to +0.26 per method (kmeans+defects 0.745
// -> 0.784, threshold+defects 0.373 -> 0.569), groups counted right +1 to +4 of 15, false
// detections the same in every method. The test asks for two balls more per method, a group
// more, and no false detection more; and, not asked, the threshold's methods the same.
TEST(VisionEvalTest, SemiTransparentBallsAreFoundByTheirDepth) {
  VisionEvalOptions without;
  without.detect.semi_sphere_pieces = false;
  VisionEvalOptions with;
  with.detect.semi_sphere_threshold = true;
  CompareInArena("toss_up", 20, with, without,
                 [](const VisionMethodScore& a, const VisionMethodScore& b) {
                   EXPECT_GE(a.found_semi, b.found_semi + 2);
                   EXPECT_GE(a.groups_counted, b.groups_counted + 1);
                   EXPECT_LE(a.false_positives, b.false_positives);
                 });
  CompareInArena("toss_up", 20, {}, without,
                 [](const VisionMethodScore& a, const VisionMethodScore& b) {
                   if (a.name.rfind("threshold", 0) != 0) return;
                   EXPECT_EQ(a.found, b.found);
                   EXPECT_EQ(a.false_positives, b.false_positives);
                   EXPECT_EQ(a.groups_counted, b.groups_counted);
                 });
}

}  // namespace
}  // namespace slamo::autonomy
