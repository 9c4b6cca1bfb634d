#include "mapping/object_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include "field_configs/loader.h"

namespace slamo::mapping {
namespace {

bool IsFree(const ObjectMap& map, const Eigen::Vector3d& p) {
  const std::optional<double> occupancy = map.Occupancy(p);
  return occupancy.has_value() && *occupancy < 0.5;
}

bool IsUnknown(const ObjectMap& map, const Eigen::Vector3d& p) {
  return !map.Occupancy(p).has_value();
}

class ObjectMapTest : public ::testing::Test {
 protected:
  ObjectMapTest() : season_(field::LoadSeasonConfig("toss_up")), map_(season_) {}

  static std::filesystem::path TempDir() {
    const std::filesystem::path dir =
        std::filesystem::path(::testing::TempDir()) / "object_map_test";
    std::filesystem::create_directories(dir);
    return dir;
  }

  MappedObject Buckyball(int id, double x, double y) const {
    return {id, "buckyball", "red", Eigen::Vector3d(x, y, 0.0635), 0.0635, 0.127, 1.0};
  }

  field::SeasonConfig season_;
  ObjectMap map_;
};

TEST_F(ObjectMapTest, WallsAreOccupiedAndTheFloorBesideThemFree) {
  const double wall_x = season_.HalfSize() + season_.field.wall_thickness_m / 2;
  for (const double side : {-1.0, 1.0}) {
    EXPECT_TRUE(map_.IsOccupied({side * wall_x, 0.5, 0.15}));
    EXPECT_TRUE(map_.IsOccupied({0.5, side * wall_x, 0.15}));
    EXPECT_TRUE(IsFree(map_, {side * (season_.HalfSize() - 0.1), 0.5, 0.05}));
  }
  EXPECT_TRUE(map_.IsOccupied({wall_x, wall_x, 0.25})) << "corner";
}

TEST_F(ObjectMapTest, AboveTheWallIsUnknownAndCountsAsFreeUnlessTheFlagSaysOtherwise) {
  const Eigen::Vector3d above(season_.HalfSize() + 0.025, 0.0, 0.5);
  EXPECT_TRUE(IsUnknown(map_, above));
  EXPECT_FALSE(map_.IsOccupied(above));
  // Inside the field above the free layer: unknown too.
  EXPECT_TRUE(IsUnknown(map_, {0.0, -1.0, 0.4}));

  ObjectMapOptions options;
  options.unknown_is_occupied = true;
  const ObjectMap cautious(season_, options);
  EXPECT_TRUE(cautious.IsOccupied(above));
  EXPECT_FALSE(cautious.IsOccupied({0.0, -1.0, 0.05})) << "free floor stays free";
}

TEST_F(ObjectMapTest, EveryStructureIsOccupiedOverItsHeightRange) {
  for (const field::Structure& s : season_.structures) {
    const double z_mid = (s.z_min_m + s.height_m) / 2;
    EXPECT_TRUE(map_.IsOccupied({s.center_m.x, s.center_m.y, z_mid})) << s.name;
    EXPECT_TRUE(IsUnknown(map_, {s.center_m.x, s.center_m.y, s.height_m + 0.1})) << s.name;
  }
}

TEST_F(ObjectMapTest, StructuresHaveFreeFloorBesideThem) {
  // Red goal: cylinder r = 0.14 at (0.78, 0.61); one voxel and a bit away on the +x side.
  EXPECT_TRUE(map_.IsOccupied({0.78 + 0.13, 0.61, 0.05}));
  EXPECT_TRUE(IsFree(map_, {0.78 + 0.14 + 0.06, 0.61, 0.05}));
  // Barrier: a pipe 0.05 thick at x = 0.61 raised 0.30-0.35 m, open near the side walls
  // (|y| > 1.22): occupied at its height, free floor under it and beside it.
  EXPECT_TRUE(map_.IsOccupied({0.61, 0.0, 0.325}));
  EXPECT_TRUE(IsFree(map_, {0.61, 0.0, 0.05})) << "robots lower than 0.30 m pass under";
  EXPECT_TRUE(IsFree(map_, {0.61 + 0.025 + 0.06, 0.0, 0.05}));
  EXPECT_TRUE(IsFree(map_, {0.61, 1.5, 0.05})) << "the gap by the wall";
  // Elevated hanging bar: occupied at its height, free floor and unknown space below it.
  EXPECT_TRUE(map_.IsOccupied({-1.45, 1.07, 0.73}));
  EXPECT_TRUE(IsUnknown(map_, {-1.45, 1.07, 0.4}));
  EXPECT_TRUE(IsFree(map_, {-1.45, 1.07, 0.05}));
  // The bump (5 cm): occupied in the first layer, free floor layer above it.
  EXPECT_TRUE(map_.IsOccupied({-0.30, 0.0, 0.025}));
  EXPECT_TRUE(IsFree(map_, {-0.30, 0.0, 0.075}));
}

TEST_F(ObjectMapTest, ObjectsAppearMoveAndDisappear) {
  const Eigen::Vector3d a(0.0, -1.0, 0.0635), b(1.0, -1.5, 0.0635);
  ASSERT_TRUE(IsFree(map_, a));
  const size_t leaves_before = map_.tree().getNumLeafNodes();

  map_.SetObjects({Buckyball(7, a.x(), a.y())});
  EXPECT_TRUE(map_.IsOccupied(a));
  EXPECT_GT(map_.Stats().object_voxels, 0u);

  map_.SetObjects({Buckyball(7, b.x(), b.y())});
  EXPECT_TRUE(IsFree(map_, a)) << "the old voxels go back to the free floor";
  EXPECT_TRUE(map_.IsOccupied(b));

  // A large ball reaches above the free layer; gone, its top is unknown again.
  const MappedObject large{8, "large_ball", "blue", Eigen::Vector3d(1.2, 0.3, 0.2), 0.2, 0.4, 1};
  map_.SetObjects({Buckyball(7, b.x(), b.y()), large});
  EXPECT_TRUE(map_.IsOccupied({1.2, 0.3, 0.3}));
  map_.SetObjects({});
  EXPECT_TRUE(IsFree(map_, b));
  EXPECT_TRUE(IsUnknown(map_, {1.2, 0.3, 0.3}));
  EXPECT_EQ(map_.Stats().object_voxels, 0u);
  EXPECT_EQ(map_.tree().getNumLeafNodes(), leaves_before) << "back to the static map";
}

TEST_F(ObjectMapTest, OverlappingObjectsKeepTheirVoxelsWhenTheOtherGoes) {
  const MappedObject a = Buckyball(1, 0.0, -1.0), b = Buckyball(2, 0.05, -1.0);
  const MappedObject c = Buckyball(3, 1.0, 1.0);
  map_.SetObjects({a, b, c});
  map_.SetObjects({a, c});
  EXPECT_TRUE(map_.IsOccupied(a.centre_m));
  EXPECT_TRUE(map_.IsOccupied({0.0 - 0.05, -1.0, 0.0635}));
  EXPECT_TRUE(IsFree(map_, {0.05 + 0.1, -1.0, 0.0635})) << "b's far side";
  // c moves, a stays: the same map as building both afresh.
  MappedObject c_moved = c;
  c_moved.centre_m.x() = 1.3;
  map_.SetObjects({c_moved, a});
  ObjectMap fresh(season_);
  fresh.SetObjects({a, c_moved});
  EXPECT_EQ(map_.Stats().object_voxels, fresh.Stats().object_voxels);
  EXPECT_EQ(map_.tree().getNumLeafNodes(), fresh.tree().getNumLeafNodes());
  EXPECT_TRUE(IsFree(map_, c.centre_m));
}

TEST_F(ObjectMapTest, ObjectInsideAStructureLeavesItOccupiedWhenItGoes) {
  const MappedObject in_goal{1,      "buckyball", "red", Eigen::Vector3d(0.78, 0.61, 0.4),
                             0.0635, 0.127,       1.0};
  map_.SetObjects({in_goal});
  map_.SetObjects({});
  EXPECT_TRUE(map_.IsOccupied({0.78, 0.61, 0.4}));
}

TEST_F(ObjectMapTest, ZeroConfidenceObjectsAreNotObstacles) {
  MappedObject doubtful = Buckyball(3, 0.0, -1.0);
  doubtful.confidence = 0.0;
  map_.SetObjects({doubtful});
  EXPECT_FALSE(map_.IsOccupied(doubtful.centre_m));
}

TEST_F(ObjectMapTest, GridMarksTheRedGoalOccupiedAndTheStartTilesFree) {
  for (const double cell_m : {0.05, 0.02, 0.1}) {
    const OccupancyGrid2D grid = map_.ToGrid(cell_m, 0.06, 0.5);
    ASSERT_EQ(grid.cells.size(), static_cast<size_t>(grid.width) * grid.height);
    const auto at = [&grid](double x, double y) {
      const std::optional<size_t> index = grid.IndexOf({x, y});
      EXPECT_TRUE(index.has_value()) << x << ", " << y;
      return index ? grid.cells[*index] : std::uint8_t{42};
    };
    EXPECT_EQ(at(0.78, 0.61), OccupancyGrid2D::kOccupied) << cell_m;
    for (const field::StartTile& start : season_.starts) {
      EXPECT_EQ(at(start.center_m.x, start.center_m.y), OccupancyGrid2D::kFree) << cell_m;
    }
    EXPECT_EQ(at(season_.HalfSize() + 0.02, 0.0), OccupancyGrid2D::kOccupied) << "wall";
    EXPECT_EQ(at(-0.30, 0.0), OccupancyGrid2D::kFree) << "above the bump";
    EXPECT_EQ(at(-1.45, 1.07), OccupancyGrid2D::kFree) << "under the hanging bar";
    EXPECT_EQ(at(0.61, 0.0), OccupancyGrid2D::kOccupied) << "the barrier, up to 0.5 m";
    EXPECT_FALSE(grid.IndexOf({5.0, 0.0}).has_value());
  }
  // A grid for a robot lower than the barrier's underside: the barrier is not in it.
  const OccupancyGrid2D low = map_.ToGrid(0.05, 0.06, 0.25);
  EXPECT_NE(low.cells[*low.IndexOf({0.61, 0.0})], OccupancyGrid2D::kOccupied);
  // Above the free layer nothing is known but the tall structures.
  const OccupancyGrid2D high = map_.ToGrid(0.05, 0.5, 0.8);
  EXPECT_EQ(high.cells[*high.IndexOf({0.78, 0.61})], OccupancyGrid2D::kOccupied);
  EXPECT_EQ(high.cells[*high.IndexOf({0.0, -1.0})], OccupancyGrid2D::kUnknown);
}

// Over Under's barrier is a 0.073 m pipe robots climb over (blocks_robot: false): taller than
// the grid's 0.06 m floor, it used to close the field's two halves to the planner, and the V5
// robot found no way to any goal or zone of its (seed 1 idled from 3 s). Its elevation posts
// still block.
TEST(ObjectMapOverUnderTest, TheGridLeavesStructuresRobotsDriveOverFree) {
  const field::SeasonConfig season = field::LoadSeasonConfig("over_under");
  const ObjectMap map(season);
  const OccupancyGrid2D grid = map.ToGrid(0.05, 0.06, 0.45);
  const auto at = [&grid](double x, double y) { return grid.cells[*grid.IndexOf({x, y})]; };
  EXPECT_EQ(at(0.0, 0.6), OccupancyGrid2D::kFree) << "the long barrier";
  EXPECT_EQ(at(0.4, 1.197), OccupancyGrid2D::kFree) << "a short barrier";
  EXPECT_EQ(at(0.0, -1.197), OccupancyGrid2D::kOccupied) << "the red elevation post";
  EXPECT_EQ(at(0.0, -1.5), OccupancyGrid2D::kOccupied) << "its bar, lower than the robot";
  EXPECT_EQ(at(1.5, 0.0), OccupancyGrid2D::kOccupied) << "the red goal's frame";
  // The octree still holds the barrier (pictures, the 3D map).
  EXPECT_TRUE(map.IsOccupied(Eigen::Vector3d(0.0, 0.6, 0.05)));
}

TEST_F(ObjectMapTest, PointCloudClearsAlongRaysAndMarksHits) {
  // A board ~1 m ahead of a sensor 20 cm up, where the season has nothing.
  std::vector<Eigen::Vector3d> points;
  for (double y = -0.3; y <= 0.3; y += 0.01) {
    for (double z = 0.15; z <= 0.45; z += 0.01) points.emplace_back(-0.18, y - 1.0, z);
  }
  const Eigen::Vector3d origin(-1.2, -1.0, 0.3);
  ASSERT_TRUE(IsUnknown(map_, {-0.18, -1.0, 0.3}));
  map_.InsertPointCloud(points, origin, 5.0);
  EXPECT_TRUE(map_.IsOccupied({-0.18, -1.0, 0.3}));
  EXPECT_TRUE(IsFree(map_, {-0.7, -1.0, 0.3}));

  // Beyond the maximum range: the ray is cleared up to it, no hit.
  ObjectMap short_range(season_);
  short_range.InsertPointCloud(points, origin, 0.5);
  EXPECT_TRUE(IsFree(short_range, {-0.9, -1.0, 0.3}));
  EXPECT_TRUE(IsUnknown(short_range, {-0.18, -1.0, 0.3}));
}

TEST_F(ObjectMapTest, BinaryFileReadsBackWithTheSameLeaves) {
  map_.SetObjects({Buckyball(1, 0.0, -1.0)});
  const std::string path = (TempDir() / "map.bt").string();
  map_.WriteBinary(path);
  octomap::OcTree read(0.1);
  ASSERT_TRUE(read.readBinary(path));
  EXPECT_DOUBLE_EQ(read.getResolution(), map_.options().resolution_m);
  EXPECT_EQ(read.getNumLeafNodes(), map_.tree().getNumLeafNodes());
  const octomap::OcTreeNode* goal = read.search(0.78, 0.61, 0.4);
  ASSERT_NE(goal, nullptr);
  EXPECT_TRUE(read.isNodeOccupied(goal));
  EXPECT_EQ(read.search(0.0, -1.0, 0.5), nullptr);
}

TEST_F(ObjectMapTest, ColouredFileHasStructureAndObjectColours) {
  map_.SetObjects(
      {{1, "buckyball", "blue", Eigen::Vector3d(0.0, -1.0, 0.0635), 0.0635, 0.127, 1.0}});
  const std::string path = (TempDir() / "map.ot").string();
  map_.WriteColored(path);
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(path));
  auto* coloured = dynamic_cast<octomap::ColorOcTree*>(tree.get());
  ASSERT_NE(coloured, nullptr);
  const auto colour_at = [&](double x, double y, double z) {
    const octomap::ColorOcTreeNode* node = coloured->search(x, y, z);
    EXPECT_NE(node, nullptr) << x << ", " << y << ", " << z;
    return node ? node->getColor() : octomap::ColorOcTreeNode::Color(1, 2, 3);
  };
  const auto palette = [&](const std::string& name) {
    const field::Rgb c = season_.colours.at(name);
    return octomap::ColorOcTreeNode::Color(c.r, c.g, c.b);
  };
  EXPECT_EQ(colour_at(0.78, 0.61, 0.4), palette("red"));
  EXPECT_EQ(colour_at(0.78, -0.61, 0.4), palette("blue"));
  EXPECT_EQ(colour_at(0.61, 0.0, 0.325), palette("pvc_white"));
  EXPECT_EQ(colour_at(season_.HalfSize() + 0.025, 0.0, 0.1), palette("wall_grey"));
  EXPECT_EQ(colour_at(0.0, -1.0, 0.0635), palette("blue"));
  EXPECT_EQ(colour_at(1.0, 1.0, 0.025), palette("tile_grey")) << "free floor";
}

TEST_F(ObjectMapTest, WritingToAnUnwritablePathThrowsNamingIt) {
  const std::string path = "/nonexistent-dir/sub/map.bt";
  for (const bool coloured : {false, true}) {
    try {
      coloured ? map_.WriteColored(path) : map_.WriteBinary(path);
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST_F(ObjectMapTest, FinerResolutionKeepsTheSameShapes) {
  ObjectMapOptions options;
  options.resolution_m = 0.02;
  const ObjectMap fine(season_, options);
  EXPECT_TRUE(fine.IsOccupied({-1.45, 0.76, 0.4})) << "a 6 cm post";
  EXPECT_TRUE(IsFree(fine, {-1.45 + 0.06, 0.76, 0.05}));
  const OccupancyGrid2D grid = fine.ToGrid(0.02, 0.06, 0.5);
  EXPECT_EQ(grid.cells[*grid.IndexOf({0.78, 0.61})], OccupancyGrid2D::kOccupied);
}

}  // namespace
}  // namespace slamo::mapping
