// One test per class of validation error: each edits the shipped file to make one mistake
// and asserts the message names the file, line, key path and what was expected.
#include <gtest/gtest.h>

#include "field_configs/config_error.h"
#include "field_configs/loader.h"
#include "tests/field_configs/config_test_util.h"

namespace slamo::field {
namespace {

using testing::Edit;
using testing::LineOf;
using testing::ReadShipped;

class SeasonValidationTest : public ::testing::Test {
 protected:
  void SetUp() override { text_ = ReadShipped(ResolveSeasonPath("toss_up")); }

  // Parses `text` expecting a ConfigError; returns it.
  ConfigError Reject(const std::string& text) {
    try {
      ParseSeasonConfig(text, "bad_field.yaml");
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.file(), "bad_field.yaml");
      EXPECT_NE(std::string(e.what()).find("bad_field.yaml:"), std::string::npos) << e.what();
      return e;
    }
    ADD_FAILURE() << "expected a ConfigError";
    return ConfigError("", 0, 0, "", "");
  }

  std::string text_;
};

TEST_F(SeasonValidationTest, ShippedTextParses) {
  EXPECT_NO_THROW(ParseSeasonConfig(text_, "toss_up.yaml"));
}

TEST_F(SeasonValidationTest, MisspeltKeyIsRejectedWithSuggestion) {
  const std::string bad = Edit(text_, "  tile_m: 0.597", "  tiel_m: 0.597");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "field.tiel_m");
  EXPECT_EQ(e.line(), LineOf(bad, "tiel_m"));
  EXPECT_EQ(e.column(), 3);
  EXPECT_NE(e.expected().find("unknown key"), std::string::npos) << e.what();
  EXPECT_NE(e.expected().find("did you mean 'tile_m'?"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, MissingRequiredKey) {
  const std::string bad = Edit(text_, "  wall_height_m: 0.30 ", "  # no wall height ");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "field");
  EXPECT_NE(e.expected().find("missing required key 'wall_height_m'"), std::string::npos)
      << e.what();
  EXPECT_GT(e.line(), 0);
}

TEST_F(SeasonValidationTest, WrongType) {
  const std::string bad = Edit(text_, "autonomous_s: 45", "autonomous_s: forty-five");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "rules.autonomous_s");
  EXPECT_EQ(e.line(), LineOf(bad, "forty-five"));
  EXPECT_NE(e.expected().find("expected a number, got 'forty-five'"), std::string::npos)
      << e.what();
}

TEST_F(SeasonValidationTest, NegativeSize) {
  const std::string bad = Edit(text_, "size_m: 0.127", "size_m: -0.127");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "object_types[0].size_m");
  EXPECT_EQ(e.line(), LineOf(bad, "-0.127"));
  EXPECT_NE(e.expected().find("expected a positive number, got '-0.127'"), std::string::npos)
      << e.what();
}

TEST_F(SeasonValidationTest, ObjectOutsideTheField) {
  const std::string bad = Edit(text_, "position_m: [0.61, 1.00]", "position_m: [2.50, 1.00]");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "objects[4].position_m");
  EXPECT_EQ(e.line(), LineOf(bad, "[2.50, 1.00]"));
  EXPECT_NE(e.expected().find("inside the field"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, OverlappingObjects) {
  const std::string bad =
      Edit(text_, "position_m: [0.61, 1.00], z_m: 0.35", "position_m: [-0.30, 0.95]");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "objects[4].position_m");
  EXPECT_NE(e.expected().find("not overlapping another object"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, OverlappingStartingTiles) {
  const std::string bad = Edit(text_, "center_m: [0.2985, 1.40]", "center_m: [-0.8955, 1.00]");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "starts[1].center_m");
  EXPECT_NE(e.expected().find("not overlapping another"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, UnknownColourName) {
  const std::string bad = Edit(text_, "shape: disc, colour: green}", "shape: disc, colour: teal}");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "landmarks[0].colour");
  EXPECT_NE(e.expected().find("a colour name from 'colours'"), std::string::npos) << e.what();
  EXPECT_NE(e.expected().find("got 'teal'"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, BadHexColour) {
  const std::string bad = Edit(text_, "red: \"#c81e28\"", "red: \"#c81e2\"");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "colours.red");
  EXPECT_NE(e.expected().find("'#rrggbb'"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, UnquotedHexColourIsExplained) {
  const std::string bad = Edit(text_, "red: \"#c81e28\"", "red: #c81e28");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "colours.red");
  EXPECT_NE(e.expected().find("'#' starts a YAML comment"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, ObjectColourNotOfItsType) {
  const std::string bad =
      Edit(text_, "{type: large_ball, colour: red,", "{type: large_ball, colour: green,");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "objects[0].colour");
  EXPECT_NE(e.expected().find("one of the colours of object type 'large_ball'"), std::string::npos)
      << e.what();
}

TEST_F(SeasonValidationTest, UnknownObjectTypeInPoints) {
  const std::string bad =
      Edit(text_, "points: {buckyball: 1, large_ball: 1}", "points: {buckyball: 1, beach_ball: 1}");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "goals[0].points.beach_ball");
  EXPECT_NE(e.expected().find("unknown object type 'beach_ball'"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, EmptyRegion) {
  const std::string bad = Edit(text_, "min_m: [-1.0, -1.15], max_m: [0.45, 1.15]",
                               "min_m: [0.45, -1.15], max_m: [-1.0, 1.15]");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "objects[8].region");
  EXPECT_NE(e.expected().find("min_m below max_m"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, BadEnumWord) {
  const std::string bad = Edit(text_, "material: solid", "material: rubber");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "object_types[0].material");
  EXPECT_NE(e.expected().find("one of {solid, semi_transparent}"), std::string::npos) << e.what();
}

TEST_F(SeasonValidationTest, YamlSyntaxError) {
  const std::string bad = Edit(text_, "  size_m: 3.566", "  size_m: [3.566");
  const ConfigError e = Reject(bad);
  EXPECT_EQ(e.key_path(), "(document)");
  EXPECT_GT(e.line(), 0);
  EXPECT_NE(e.expected().find("valid YAML"), std::string::npos) << e.what();
}

class RobotValidationTest : public ::testing::Test {
 protected:
  void SetUp() override { text_ = ReadShipped(ResolveRobotPath("thesis_robot")); }

  ConfigError Reject(const std::string& text) {
    try {
      ParseRobotConfig(text, "bad_robot.yaml");
    } catch (const ConfigError& e) {
      return e;
    }
    ADD_FAILURE() << "expected a ConfigError";
    return ConfigError("", 0, 0, "", "");
  }

  std::string text_;
};

TEST_F(RobotValidationTest, ShippedTextParses) {
  EXPECT_NO_THROW(ParseRobotConfig(text_, "r.yaml"));
}

TEST_F(RobotValidationTest, PwmStopMustLieBetweenTheEnds) {
  const ConfigError e = Reject(Edit(text_, "stop: 90", "stop: 200"));
  EXPECT_EQ(e.key_path(), "drive.pwm.full_reverse");
  EXPECT_NE(e.expected().find("strictly between"), std::string::npos) << e.what();
}

TEST_F(RobotValidationTest, NoiseTableNeedsOneSigmaPerDistance) {
  const ConfigError e = Reject(Edit(text_, "0.0028, 0.0036]", "0.0028]"));
  EXPECT_EQ(e.key_path(), "camera.noise.sigma_m");
  EXPECT_NE(e.expected().find("one sigma per distance (8 values)"), std::string::npos) << e.what();
}

TEST_F(RobotValidationTest, CruiseFasterThanMaxSpeed) {
  const ConfigError e = Reject(Edit(text_, "cruise_speed_mps: 0.067", "cruise_speed_mps: 0.9"));
  EXPECT_EQ(e.key_path(), "drive.cruise_speed_mps");
  EXPECT_NE(e.expected().find("no faster than max_speed_mps"), std::string::npos) << e.what();
}

TEST_F(RobotValidationTest, MisspeltCameraKey) {
  const ConfigError e = Reject(Edit(text_, "  fy: 365.456", "  fyy: 365.456"));
  EXPECT_EQ(e.key_path(), "camera.fyy");
  EXPECT_NE(e.expected().find("did you mean 'fy'?"), std::string::npos) << e.what();
}

TEST_F(RobotValidationTest, StopBiasIsRequiredAndBounded) {
  const ConfigError negative =
      Reject(Edit(text_, "    range_sigma_m: 0.01", "    range_sigma_m: -0.01"));
  EXPECT_EQ(negative.key_path(), "camera.stop_bias.range_sigma_m");
  const ConfigError missing = Reject(Edit(text_, "  stop_bias:", "  stop_biass:"));
  EXPECT_EQ(missing.key_path(), "camera.stop_biass");
  EXPECT_NE(missing.expected().find("did you mean 'stop_bias'?"), std::string::npos)
      << missing.what();
}

// The intake's times are the robot's: read from the file (1 s each when left out), and
// bounded.
TEST_F(RobotValidationTest, IntakeTimesAreReadAndBounded) {
  const RobotConfig shipped = ParseRobotConfig(text_, "r.yaml");
  EXPECT_DOUBLE_EQ(shipped.intake.pick_s, 1.0);
  const RobotConfig quick = ParseRobotConfig(
      Edit(Edit(text_, "  pick_s: 1.0", "  pick_s: 0.4"), "  release_s: 1.0", "  release_s: 0.3"),
      "r.yaml");
  EXPECT_DOUBLE_EQ(quick.intake.pick_s, 0.4);
  EXPECT_DOUBLE_EQ(quick.intake.release_s, 0.3);
  const ConfigError negative = Reject(Edit(text_, "  pick_s: 1.0", "  pick_s: -1"));
  EXPECT_EQ(negative.key_path(), "intake.pick_s");
}

// The camera's latency (frames taken while driving): none when left out, read, and bounded.
TEST_F(RobotValidationTest, CameraLatencyIsOptionalAndBounded) {
  EXPECT_DOUBLE_EQ(ParseRobotConfig(text_, "r.yaml").camera.latency_s, 0.0);
  const std::string with =
      Edit(text_, "  frame_rate_hz: 30.0", "  frame_rate_hz: 30.0\n  latency_s: 0.04");
  EXPECT_DOUBLE_EQ(ParseRobotConfig(with, "r.yaml").camera.latency_s, 0.04);
  const ConfigError e = Reject(Edit(with, "latency_s: 0.04", "latency_s: 2"));
  EXPECT_EQ(e.key_path(), "camera.latency_s");
}

}  // namespace
}  // namespace slamo::field
