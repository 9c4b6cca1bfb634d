#include "planning/export.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace slamo::planning {
namespace {

// "x, y, speed" -> three numbers, or false.
bool ParsePoint(const std::string& line, LemLibPoint* point) {
  char rest = 0;
  return std::sscanf(line.c_str(), "%lf, %lf, %lf%c", &point->x_in, &point->y_in, &point->speed,
                     &rest) == 3;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(ExportTest, FieldMetresAreInchesFromTheCentre) {
  EXPECT_TRUE(FieldToInches({0.0, 0.0}).isZero());
  EXPECT_NEAR(FieldToInches({0.0254, -0.254}).x(), 1.0, 1e-12);
  EXPECT_NEAR(FieldToInches({0.0254, -0.254}).y(), -10.0, 1e-12);
  // A 12 ft field: the corner at 72 in.
  EXPECT_NEAR(FieldToInches({3.6576 / 2, 3.6576 / 2}).x(), 72.0, 1e-9);
}

TEST(ExportTest, PointsEveryTwoInchesPerSegmentThenEndAndGhost) {
  // 1 m along +x (39.37 in: 20 points at 0, 2, ..., 38 in), then 0.5 m along +y (19.685 in:
  // 10 points), then the end and the ghost point 20 in beyond it.
  const std::vector<Eigen::Vector2d> path = {{-0.5, 0.0}, {0.5, 0.0}, {0.5, 0.5}};
  const std::vector<LemLibPoint> points = LemLibPoints(path);
  ASSERT_EQ(points.size(), 20u + 10u + 1u + 1u);
  EXPECT_NEAR(points[0].x_in, -0.5 / 0.0254, 1e-9);
  EXPECT_NEAR(points[1].x_in - points[0].x_in, 2.0, 1e-9);
  EXPECT_NEAR(points[20].x_in, 0.5 / 0.0254, 1e-9);  // the corner is a point
  EXPECT_NEAR(points[20].y_in, 0.0, 1e-9);
  const LemLibPoint end = points[30], ghost = points[31];
  EXPECT_NEAR(end.x_in, 19.685, 1e-3);
  EXPECT_NEAR(end.y_in, 19.685, 1e-3);
  EXPECT_NEAR(ghost.x_in, 19.685, 1e-3);
  EXPECT_NEAR(ghost.y_in, 19.685 + 20.0, 1e-3);
  EXPECT_EQ(end.speed, 0.0);
  EXPECT_EQ(ghost.speed, 0.0);
  // Full speed at the start; the ramp down never rises towards the end and stays above the
  // floor until the end.
  EXPECT_EQ(points[0].speed, 100.0);
  for (size_t k = 1; k < 30; ++k) {
    EXPECT_LE(points[k].speed, points[k - 1].speed) << k;
    EXPECT_GE(points[k].speed, 20.0) << k;
  }
  EXPECT_LT(points[29].speed, 100.0);
}

TEST(ExportTest, FileParsesLineByLine) {
  const std::vector<Eigen::Vector2d> path = {{-1.524, 0.3048}, {-0.6, -0.9}, {0.3, -1.2}};
  LemLibExportOptions options;
  options.name = "test \"route\"";
  const std::string file = ::testing::TempDir() + "/slamo_export_test.txt";
  WriteLemLibPath(file, path, options);
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  const std::vector<std::string> lines = Lines(text.str());
  const std::vector<LemLibPoint> expected = LemLibPoints(path, options);

  // Points up to endData, as LemLib reads them.
  size_t i = 0;
  for (; i < lines.size() && lines[i] != "endData"; ++i) {
    LemLibPoint p;
    ASSERT_TRUE(ParsePoint(lines[i], &p)) << "line " << i + 1 << ": " << lines[i];
    ASSERT_LT(i, expected.size());
    EXPECT_NEAR(p.x_in, expected[i].x_in, 5e-4);
    EXPECT_NEAR(p.y_in, expected[i].y_in, 5e-4);
    EXPECT_NEAR(p.speed, expected[i].speed, 5e-4);
  }
  ASSERT_LT(i, lines.size()) << "no endData";
  EXPECT_EQ(i, expected.size());
  // The first point is the start, in inches: -60 in, 12 in.
  LemLibPoint first;
  ASSERT_TRUE(ParsePoint(lines[0], &first));
  EXPECT_NEAR(first.x_in, -60.0, 1e-3);
  EXPECT_NEAR(first.y_in, 12.0, 1e-3);
  // Deceleration rate, maximum speed, multiplier.
  ASSERT_GE(lines.size(), i + 4 + 2 + 1);
  EXPECT_EQ(lines[i + 1], "127");
  EXPECT_EQ(lines[i + 2], "100");
  EXPECT_EQ(lines[i + 3], "200");
  // One line of eight numbers per segment: start, middle, middle, end.
  for (size_t s = 0; s < 2; ++s) {
    double v[8];
    ASSERT_EQ(std::sscanf(lines[i + 4 + s].c_str(), "%lf, %lf, %lf, %lf, %lf, %lf, %lf, %lf", &v[0],
                          &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7]),
              8);
    const Eigen::Vector2d a = FieldToInches(path[s]), b = FieldToInches(path[s + 1]);
    EXPECT_NEAR(v[0], a.x(), 5e-4);
    EXPECT_NEAR(v[1], a.y(), 5e-4);
    EXPECT_NEAR(v[2], (a.x() + b.x()) / 2, 5e-4);
    EXPECT_NEAR(v[7], b.y(), 5e-4);
  }
  // Last: the editor's data on one line, a JSON object with the format and the name escaped.
  const std::string& data = lines[i + 6];
  ASSERT_EQ(data.rfind("#PATH.JERRYIO-DATA {", 0), 0u);
  EXPECT_EQ(data.back(), '}');
  EXPECT_NE(data.find("\"format\":\"LemLib v0.4.x (inch, byte-voltage)\""), std::string::npos);
  EXPECT_NE(data.find("\"name\":\"test \\\"route\\\"\""), std::string::npos);
  EXPECT_EQ(i + 7, lines.size());
}

TEST(ExportTest, TooShortAPathIsRejected) {
  EXPECT_TRUE(LemLibPoints({{0, 0}}).empty());
  EXPECT_THROW(LemLibPathFile({{0, 0}}), std::invalid_argument);
  EXPECT_THROW(WriteLemLibPath("/nonexistent/dir/p.txt", {{0, 0}, {1, 0}}), std::runtime_error);
}

}  // namespace
}  // namespace slamo::planning
