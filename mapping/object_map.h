// The OctoMap object/obstacle map: a 3D occupancy octree of the field built from the season
// (perimeter walls and structures occupied, a layer above the floor free) with a layer of game
// objects the tracker replaces as they move, and point clouds fused in by ray casting. The
// map owns its octree; planning reads it through IsOccupied() and the 2D ToGrid().
//
// Unknown space: a voxel nothing has said anything about (neither the season, nor an object,
// nor a ray) is unknown, and Occupancy() says so with std::nullopt. Inside the perimeter the
// season lists every fixed element, so for planning unknown means "not observed, probably
// free": IsOccupied() treats it as free unless ObjectMapOptions::unknown_is_occupied is set.
// ToGrid() keeps the three states apart (255 = unknown) and leaves the choice to the planner.
// Only the layer up to free_layer_height_m is known free, so a planning grid's z range should
// reach into it, and start above drive-over structures (Toss Up's 5 cm bump is occupied).
// Every mutating call leaves the octree's inner nodes updated and pruned, so reads are const.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include <octomap/OcTree.h>
#include <Eigen/Core>

#include "field_configs/season_config.h"

namespace slamo::mapping {

struct ObjectMapOptions {
  double resolution_m = 0.05;                   // voxel edge, metres
  double structure_hit_probability = 0.97;      // probability set on wall and structure voxels
  double object_hit_probability = 0.9;          // probability set on object voxels
  double floor_free_probability = 0.3;          // probability set on the free layer, < 0.5
  double free_layer_height_m = 0.10;            // metres above the floor marked free (>= 1 voxel)
  double sensor_hit_probability = 0.7;          // point cloud: probability update for a hit
  double sensor_miss_probability = 0.4;         // point cloud: probability update along a ray
  double clamping_min_probability = 0.12;       // no voxel becomes more certainly free than this
  double clamping_max_probability = 0.97;       // no voxel becomes more certainly occupied
  double occupied_threshold_probability = 0.5;  // a voxel at or above this is occupied
  bool unknown_is_occupied = false;             // IsOccupied() on unknown space: true if set
};

// A game object as the tracker hands it over: an upright solid at centre_m (the centre of its
// bounding box, field frame). Spheres (by the season's object type) are mapped as spheres of
// radius_m, every other shape as a vertical cylinder of radius_m and height_m.
struct MappedObject {
  int id = 0;          // the tracker's id, stable while the object lives
  std::string type;    // a SeasonConfig object type name
  std::string colour;  // a SeasonConfig colour name
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  double height_m = 0.0;
  double confidence = 1.0;  // 0..1, the tracker's belief that the object is there
};

// A 2D footprint of the map for planning: row-major cells, row along +y, column along +x.
struct OccupancyGrid2D {
  static constexpr std::uint8_t kFree = 0;
  static constexpr std::uint8_t kOccupied = 100;
  static constexpr std::uint8_t kUnknown = 255;

  int width = 0;                                       // columns (x)
  int height = 0;                                      // rows (y)
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();  // corner of cell (0, 0): min x, min y
  double cell_m = 0.0;                                 // cell edge, metres
  std::vector<std::uint8_t> cells;                     // width * height

  std::uint8_t At(int col, int row) const { return cells[static_cast<size_t>(row) * width + col]; }
  // The cell holding a point, or nullopt outside the grid.
  std::optional<size_t> IndexOf(const Eigen::Vector2d& p_m) const;
};

// Leaf and voxel counts; "voxels" are at the map's resolution (a pruned leaf counts for all
// the voxels it covers).
struct ObjectMapStats {
  size_t leaf_nodes = 0;
  size_t occupied_leaves = 0;
  size_t free_leaves = 0;
  size_t occupied_voxels = 0;
  size_t free_voxels = 0;
  size_t structure_voxels = 0;  // walls and structures, as built from the season
  size_t object_voxels = 0;     // the current object layer
  size_t memory_bytes = 0;      // the octree's own estimate
};

class ObjectMap {
 public:
  // Builds the static layer of `season`: free floor layer, then walls and structures. The
  // season must outlive the map (colours and object types are looked up in it).
  explicit ObjectMap(const field::SeasonConfig& season, const ObjectMapOptions& options = {});

  // Replaces the object layer with `objects`. Objects that moved, changed or went have their
  // voxels go back to what the season says (structure, free floor layer or unknown;
  // point-cloud evidence there is dropped); new and moved ones are inserted with probability
  // 0.5 + (object_hit_probability - 0.5) * confidence; objects with confidence 0 are left out.
  // Unchanged objects (same id and fields) cost nothing. Ids should be unique; of two objects
  // with one id the later wins.
  void SetObjects(const std::vector<MappedObject>& objects);

  // Fuses a point cloud (field frame) by ray casting from `sensor_origin_m`: hits become more
  // occupied, voxels along the rays more free. Points beyond max_range_m (< 0: no limit) only
  // clear their ray up to that range.
  void InsertPointCloud(const std::vector<Eigen::Vector3d>& points,
                        const Eigen::Vector3d& sensor_origin_m, double max_range_m);

  // Occupied voxel, or unknown space when options.unknown_is_occupied is set.
  bool IsOccupied(const Eigen::Vector3d& p_m) const;
  // Occupancy probability of the voxel holding p_m; nullopt for unknown space.
  std::optional<double> Occupancy(const Eigen::Vector3d& p_m) const;

  // Footprint of the voxels between min_z_m and max_z_m over the field and its walls: a cell
  // is occupied if any occupied voxel overlaps it, free if only free ones do, else unknown.
  // Structures robots drive over (blocks_robot false, standing on the floor) are free.
  OccupancyGrid2D ToGrid(double cell_m, double min_z_m, double max_z_m) const;

  // .bt: maximum-likelihood occupancy only (octomap::OcTree reads it back).
  void WriteBinary(const std::string& path) const;
  // .ot of an octomap::ColorOcTree: objects in their colour, walls and structures in theirs,
  // free space in the tile colour, other occupied voxels (seen by the camera) black.
  void WriteColored(const std::string& path) const;

  ObjectMapStats Stats() const;
  const octomap::OcTree& tree() const { return tree_; }
  const ObjectMapOptions& options() const { return options_; }

 private:
  template <typename T>
  using KeyMap = std::unordered_map<octomap::OcTreeKey, T, octomap::OcTreeKey::KeyHash>;
  struct ObjectVoxel {
    field::Rgb colour;  // of the object that claimed it last
    int owners = 0;     // objects overlapping it
  };
  struct ObjectRecord {
    MappedObject object;
    std::vector<octomap::OcTreeKey> keys;
  };

  void InsertFreeLayer();
  void InsertObject(const MappedObject& object);
  void RemoveObject(const ObjectRecord& record);
  void InsertStructures();
  // The season's value of a voxel: structure, free floor layer or unknown (deleted).
  void RestoreStatic(const octomap::OcTreeKey& key);
  bool InFreeLayer(const octomap::OcTreeKey& key) const;
  field::Rgb PaletteColour(const std::string& name) const;
  // Updates inner nodes and prunes after lazy insertion; reads need it.
  void Finish();

  const field::SeasonConfig& season_;
  ObjectMapOptions options_;
  octomap::OcTree tree_;
  KeyMap<field::Rgb> structure_colour_;            // static occupied voxels
  KeyMap<ObjectVoxel> object_voxels_;              // the object layer's voxels
  std::unordered_map<int, ObjectRecord> objects_;  // the object layer, by object id
};

}  // namespace slamo::mapping
