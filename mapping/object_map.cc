#include "mapping/object_map.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>
#include <utility>

#include <octomap/ColorOcTree.h>
#include <octomap/Pointcloud.h>

namespace slamo::mapping {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
// Solids that only touch a voxel's face do not occupy it.
constexpr double kTouchEpsilon_m = 1e-6;
// Occupied voxels no season element or object accounts for: seen by the camera.
constexpr field::Rgb kObservedColour{0, 0, 0};
constexpr field::Rgb kFallbackColour{128, 128, 128};

float LogOdds(double probability) { return octomap::logodds(probability); }

// An axis-aligned voxel: centre and half edge.
struct Voxel {
  Eigen::Vector3d centre;
  double half;
};

bool ZOverlaps(const Voxel& v, double z_min, double z_max) {
  return v.centre.z() - v.half < z_max - kTouchEpsilon_m &&
         v.centre.z() + v.half > z_min + kTouchEpsilon_m;
}

// Separating axes of a yawed box and the voxel's square footprint.
bool BoxOverlaps(const Voxel& v, const Eigen::Vector2d& centre, const Eigen::Vector2d& half,
                 double yaw_rad) {
  const Eigen::Vector2d u(std::cos(yaw_rad), std::sin(yaw_rad));
  const Eigen::Vector2d w(-u.y(), u.x());
  const Eigen::Vector2d d = centre - v.centre.head<2>();
  const auto separated = [](double distance, double reach) {
    return std::abs(distance) >= reach - kTouchEpsilon_m;
  };
  if (separated(d.x(), v.half + half.x() * std::abs(u.x()) + half.y() * std::abs(w.x())))
    return false;
  if (separated(d.y(), v.half + half.x() * std::abs(u.y()) + half.y() * std::abs(w.y())))
    return false;
  if (separated(d.dot(u), half.x() + v.half * (std::abs(u.x()) + std::abs(u.y())))) return false;
  if (separated(d.dot(w), half.y() + v.half * (std::abs(w.x()) + std::abs(w.y())))) return false;
  return true;
}

// Squared distance from a point to the voxel (0 inside), over the first `dims` axes.
double SquaredDistance(const Voxel& v, const Eigen::Vector3d& p, int dims) {
  double sum = 0.0;
  for (int i = 0; i < dims; ++i) {
    const double outside = std::max(std::abs(p[i] - v.centre[i]) - v.half, 0.0);
    sum += outside * outside;
  }
  return sum;
}

bool CylinderOverlaps(const Voxel& v, const Eigen::Vector2d& centre, double radius) {
  const double r = radius - kTouchEpsilon_m;
  return r > 0 && SquaredDistance(v, Eigen::Vector3d(centre.x(), centre.y(), 0.0), 2) < r * r;
}

// Whether the voxel reaches into structure s (its footprint and its height range).
bool StructureOverlaps(const Voxel& v, const field::Structure& s) {
  if (!ZOverlaps(v, s.z_min_m, s.height_m)) return false;
  const Eigen::Vector2d centre(s.center_m.x, s.center_m.y);
  if (s.shape == field::SolidShape::kBox) {
    return BoxOverlaps(v, centre, Eigen::Vector2d(s.size_m.x, s.size_m.y) / 2.0,
                       s.yaw_deg * kDegToRad);
  }
  return CylinderOverlaps(v, centre, s.radius_m);
}

// A structure robots drive over, standing on the floor (a barrier pipe, a bump; not one they
// pass under, which the grid's height band decides).
bool DriveOver(const field::Structure& s) { return !s.blocks_robot && !s.PassUnder(); }

bool SphereOverlaps(const Voxel& v, const Eigen::Vector3d& centre, double radius) {
  const double r = radius - kTouchEpsilon_m;
  return r > 0 && SquaredDistance(v, centre, 3) < r * r;
}

// Calls visit(key) for every voxel in the box [lo, hi] for which overlaps(voxel) holds.
template <typename Overlaps, typename Visit>
void ForEachVoxel(const octomap::OcTree& tree, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                  const Overlaps& overlaps, const Visit& visit) {
  octomap::OcTreeKey min_key, max_key;
  if (!tree.coordToKeyChecked(lo.x(), lo.y(), lo.z(), min_key) ||
      !tree.coordToKeyChecked(hi.x(), hi.y(), hi.z(), max_key)) {
    throw std::invalid_argument("a solid lies outside the octree's range");
  }
  Voxel voxel{Eigen::Vector3d::Zero(), tree.getResolution() / 2.0};
  octomap::OcTreeKey key;
  for (int x = min_key[0]; x <= max_key[0]; ++x) {
    key[0] = static_cast<octomap::key_type>(x);
    voxel.centre.x() = tree.keyToCoord(key[0]);
    for (int y = min_key[1]; y <= max_key[1]; ++y) {
      key[1] = static_cast<octomap::key_type>(y);
      voxel.centre.y() = tree.keyToCoord(key[1]);
      for (int z = min_key[2]; z <= max_key[2]; ++z) {
        key[2] = static_cast<octomap::key_type>(z);
        voxel.centre.z() = tree.keyToCoord(key[2]);
        if (overlaps(voxel)) visit(key);
      }
    }
  }
}

// A ColorOcTree that prunes only children of one colour, so that every voxel keeps the colour
// of what it is (the stock one averages the colours of equally occupied children).
class ExactColourOcTree : public octomap::ColorOcTree {
 public:
  using ColorOcTree::ColorOcTree;

  bool isNodeCollapsible(const octomap::ColorOcTreeNode* node) const override {
    if (!ColorOcTree::isNodeCollapsible(node)) return false;
    const octomap::ColorOcTreeNode::Color first = getNodeChild(node, 0)->getColor();
    for (unsigned int i = 1; i < 8; ++i) {
      if (!(getNodeChild(node, i)->getColor() == first)) return false;
    }
    return true;
  }
};

// Erases one voxel, and every ancestor it leaves without children, so that its space is
// unknown again. octomap 1.9.7's deleteNode() deletes an emptied inner node without freeing
// its children array, which the library's own assertion then stops (OctoMap/octomap#287);
// here an emptied node is expanded and pruned, which frees the array, before it is deleted.
// The ancestors' occupancy is brought up to date, as a non-lazy update would.
void EraseVoxel(octomap::OcTree& tree, const octomap::OcTreeKey& key) {
  octomap::OcTreeNode* node = tree.getRoot();
  if (node == nullptr) return;
  const int depth = static_cast<int>(tree.getTreeDepth());
  std::vector<std::pair<octomap::OcTreeNode*, unsigned int>> path;  // parent, child index
  path.reserve(depth);
  for (int level = 0; level < depth; ++level) {
    const unsigned int pos = octomap::computeChildIdx(key, depth - 1 - level);
    if (!tree.nodeChildExists(node, pos)) {
      if (tree.nodeHasChildren(node)) return;  // already unknown
      tree.expandNode(node);                   // a pruned leaf covering the voxel
    }
    path.emplace_back(node, pos);
    node = tree.getNodeChild(node, pos);
  }
  for (auto step = path.rbegin(); step != path.rend(); ++step) {
    octomap::OcTreeNode* child = tree.getNodeChild(step->first, step->second);
    if (step != path.rbegin()) {
      tree.expandNode(child);  // frees the emptied children array ...
      tree.pruneNode(child);   // ... by collapsing the children just made
    }
    tree.deleteNodeChild(step->first, step->second);
    if (tree.nodeHasChildren(step->first)) {
      for (; step != path.rend(); ++step) step->first->updateOccupancyChildren();
      return;
    }
  }
  tree.clear();  // the root lost its last child
}

std::ofstream OpenForWriting(const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  return out;
}

void CloseOrThrow(std::ofstream& out, const std::string& path) {
  out.close();
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace

std::optional<size_t> OccupancyGrid2D::IndexOf(const Eigen::Vector2d& p_m) const {
  const double col = std::floor((p_m.x() - origin_m.x()) / cell_m);
  const double row = std::floor((p_m.y() - origin_m.y()) / cell_m);
  if (col < 0 || row < 0 || col >= width || row >= height) return std::nullopt;
  return static_cast<size_t>(row) * width + static_cast<size_t>(col);
}

ObjectMap::ObjectMap(const field::SeasonConfig& season, const ObjectMapOptions& options)
    : season_(season), options_(options), tree_(options.resolution_m) {
  tree_.setProbHit(options_.sensor_hit_probability);
  tree_.setProbMiss(options_.sensor_miss_probability);
  tree_.setClampingThresMin(options_.clamping_min_probability);
  tree_.setClampingThresMax(options_.clamping_max_probability);
  tree_.setOccupancyThres(options_.occupied_threshold_probability);
  // Free floor first: walls and structures overwrite the voxels they reach into.
  InsertFreeLayer();
  InsertStructures();
  Finish();
}

bool ObjectMap::InFreeLayer(const octomap::OcTreeKey& key) const {
  const double half_field = season_.HalfSize();
  const double height = std::max(options_.free_layer_height_m, options_.resolution_m);
  const double x = tree_.keyToCoord(key[0]);
  const double y = tree_.keyToCoord(key[1]);
  const double z = tree_.keyToCoord(key[2]);
  return std::abs(x) < half_field && std::abs(y) < half_field && z > 0.0 && z < height;
}

void ObjectMap::InsertFreeLayer() {
  const double half_field = season_.HalfSize();
  const double height = std::max(options_.free_layer_height_m, options_.resolution_m);
  const float free = LogOdds(options_.floor_free_probability);
  ForEachVoxel(
      tree_, Eigen::Vector3d(-half_field, -half_field, 0.0),
      Eigen::Vector3d(half_field, half_field, height),
      [&](const Voxel& v) {
        return std::abs(v.centre.x()) < half_field && std::abs(v.centre.y()) < half_field &&
               v.centre.z() > 0.0 && v.centre.z() < height;
      },
      [&](const octomap::OcTreeKey& key) { tree_.setNodeValue(key, free, /*lazy_eval=*/true); });
}

void ObjectMap::InsertStructures() {
  const float occupied = LogOdds(options_.structure_hit_probability);
  const auto insert_box = [&](Eigen::Vector2d centre, Eigen::Vector2d size, double yaw_deg,
                              double z_min, double z_max, const field::Rgb& colour) {
    const Eigen::Vector2d half = size / 2.0;
    const double yaw_rad = yaw_deg * kDegToRad;
    const double c = std::abs(std::cos(yaw_rad)), s = std::abs(std::sin(yaw_rad));
    const Eigen::Vector2d reach(half.x() * c + half.y() * s, half.x() * s + half.y() * c);
    ForEachVoxel(
        tree_, Eigen::Vector3d(centre.x() - reach.x(), centre.y() - reach.y(), z_min),
        Eigen::Vector3d(centre.x() + reach.x(), centre.y() + reach.y(), z_max),
        [&](const Voxel& v) {
          return ZOverlaps(v, z_min, z_max) && BoxOverlaps(v, centre, half, yaw_rad);
        },
        [&](const octomap::OcTreeKey& key) {
          tree_.setNodeValue(key, occupied, /*lazy_eval=*/true);
          structure_colour_[key] = colour;
        });
  };

  // Perimeter walls, outside the field square; the x walls run over the corners.
  const field::FieldGeometry& f = season_.field;
  const double half_field = season_.HalfSize();
  const double t = f.wall_thickness_m;
  const double outer = f.size_m + 2.0 * t;
  const field::Rgb wall = PaletteColour(f.wall_colour);
  for (const double side : {-1.0, 1.0}) {
    const double offset = side * (half_field + t / 2.0);
    insert_box({offset, 0.0}, {t, outer}, 0.0, 0.0, f.wall_height_m, wall);
    insert_box({0.0, offset}, {outer, t}, 0.0, 0.0, f.wall_height_m, wall);
  }

  // Structures.
  for (const field::Structure& s : season_.structures) {
    const Eigen::Vector2d centre(s.center_m.x, s.center_m.y);
    const field::Rgb colour = PaletteColour(s.colour);
    if (s.shape == field::SolidShape::kBox) {
      insert_box(centre, {s.size_m.x, s.size_m.y}, s.yaw_deg, s.z_min_m, s.height_m, colour);
      continue;
    }
    const Eigen::Vector3d reach(s.radius_m, s.radius_m, 0.0);
    ForEachVoxel(
        tree_, Eigen::Vector3d(centre.x(), centre.y(), s.z_min_m) - reach,
        Eigen::Vector3d(centre.x(), centre.y(), s.height_m) + reach,
        [&](const Voxel& v) {
          return ZOverlaps(v, s.z_min_m, s.height_m) && CylinderOverlaps(v, centre, s.radius_m);
        },
        [&](const octomap::OcTreeKey& key) {
          tree_.setNodeValue(key, occupied, /*lazy_eval=*/true);
          structure_colour_[key] = colour;
        });
  }
}

void ObjectMap::RestoreStatic(const octomap::OcTreeKey& key) {
  if (structure_colour_.count(key)) {
    tree_.setNodeValue(key, LogOdds(options_.structure_hit_probability), /*lazy_eval=*/false);
  } else if (InFreeLayer(key)) {
    tree_.setNodeValue(key, LogOdds(options_.floor_free_probability), /*lazy_eval=*/false);
  } else {
    EraseVoxel(tree_, key);
  }
}

void ObjectMap::SetObjects(const std::vector<MappedObject>& objects) {
  const auto same = [](const MappedObject& a, const MappedObject& b) {
    return a.type == b.type && a.colour == b.colour && a.centre_m == b.centre_m &&
           a.radius_m == b.radius_m && a.height_m == b.height_m && a.confidence == b.confidence;
  };
  std::map<int, const MappedObject*> wanted;  // ordered: the same result on every run
  for (const MappedObject& object : objects) {
    if (object.confidence > 0.0) wanted[object.id] = &object;
  }

  // Remove the objects that went or changed.
  for (auto it = objects_.begin(); it != objects_.end();) {
    const auto kept = wanted.find(it->first);
    if (kept != wanted.end() && same(*kept->second, it->second.object)) {
      wanted.erase(kept);
      ++it;
    } else {
      RemoveObject(it->second);
      it = objects_.erase(it);
    }
  }

  // Insert the new and changed ones.
  // Non-lazy updates: a few moved objects must not cost a pass over the whole tree.
  for (const auto& [id, object] : wanted) InsertObject(*object);
}

void ObjectMap::RemoveObject(const ObjectRecord& record) {
  for (const octomap::OcTreeKey& key : record.keys) {
    const auto voxel = object_voxels_.find(key);
    if (voxel == object_voxels_.end() || --voxel->second.owners > 0) continue;
    object_voxels_.erase(voxel);
    RestoreStatic(key);
  }
}

void ObjectMap::InsertObject(const MappedObject& object) {
  const field::ObjectType* type = season_.FindObjectType(object.type);
  const bool sphere = type != nullptr && type->shape == field::ObjectShape::kSphere;
  const double r = object.radius_m;
  const double half_height = sphere ? r : (object.height_m > 0 ? object.height_m : 2 * r) / 2;
  const Eigen::Vector3d reach(r, r, half_height);
  const Eigen::Vector3d& c = object.centre_m;
  const double probability =
      0.5 + (options_.object_hit_probability - 0.5) * std::min(object.confidence, 1.0);
  const float value = LogOdds(probability);
  const field::Rgb colour = PaletteColour(object.colour);
  ObjectRecord& record = objects_[object.id];
  record.object = object;
  ForEachVoxel(
      tree_, c - reach, c + reach,
      [&](const Voxel& v) {
        if (sphere) return SphereOverlaps(v, c, r);
        return ZOverlaps(v, c.z() - half_height, c.z() + half_height) &&
               CylinderOverlaps(v, c.head<2>(), r);
      },
      [&](const octomap::OcTreeKey& key) {
        // An object inside a structure (a ball in a goal) leaves the structure as it is.
        if (!structure_colour_.count(key)) tree_.setNodeValue(key, value, /*lazy_eval=*/false);
        ObjectVoxel& voxel = object_voxels_[key];
        voxel.colour = colour;
        ++voxel.owners;
        record.keys.push_back(key);
      });
}

void ObjectMap::InsertPointCloud(const std::vector<Eigen::Vector3d>& points,
                                 const Eigen::Vector3d& sensor_origin_m, double max_range_m) {
  octomap::Pointcloud cloud;
  cloud.reserve(points.size());
  for (const Eigen::Vector3d& p : points) cloud.push_back(p.x(), p.y(), p.z());
  const octomap::point3d origin(sensor_origin_m.x(), sensor_origin_m.y(), sensor_origin_m.z());
  tree_.insertPointCloud(cloud, origin, max_range_m, /*lazy_eval=*/true, /*discretize=*/false);
  Finish();
}

bool ObjectMap::IsOccupied(const Eigen::Vector3d& p_m) const {
  const octomap::OcTreeNode* node = tree_.search(p_m.x(), p_m.y(), p_m.z());
  if (node == nullptr) return options_.unknown_is_occupied;
  return tree_.isNodeOccupied(node);
}

std::optional<double> ObjectMap::Occupancy(const Eigen::Vector3d& p_m) const {
  const octomap::OcTreeNode* node = tree_.search(p_m.x(), p_m.y(), p_m.z());
  if (node == nullptr) return std::nullopt;
  return node->getOccupancy();
}

OccupancyGrid2D ObjectMap::ToGrid(double cell_m, double min_z_m, double max_z_m) const {
  if (!(cell_m > 0.0)) throw std::invalid_argument("ToGrid: cell_m must be positive");
  if (!(max_z_m > min_z_m)) throw std::invalid_argument("ToGrid: max_z_m must exceed min_z_m");
  const double half = season_.HalfSize() + season_.field.wall_thickness_m;
  OccupancyGrid2D grid;
  grid.cell_m = cell_m;
  grid.origin_m = Eigen::Vector2d(-half, -half);
  grid.width = grid.height = static_cast<int>(std::ceil(2.0 * half / cell_m - 1e-9));
  grid.cells.assign(static_cast<size_t>(grid.width) * grid.height, OccupancyGrid2D::kUnknown);

  // Cells [first, last] a leaf's extent [lo, hi) overlaps along one axis.
  const auto cell_range = [&](double lo, double hi, double origin, int count) {
    const int first = static_cast<int>(std::floor((lo - origin) / cell_m + 1e-9));
    const int last = static_cast<int>(std::ceil((hi - origin) / cell_m - 1e-9)) - 1;
    return std::make_pair(std::max(first, 0), std::min(last, count - 1));
  };

  const octomap::point3d bbx_min(-half, -half, min_z_m), bbx_max(half, half, max_z_m);
  for (auto it = tree_.begin_leafs_bbx(bbx_min, bbx_max), end = tree_.end_leafs_bbx(); it != end;
       ++it) {
    const double h = it.getSize() / 2.0;
    const Voxel leaf{Eigen::Vector3d(it.getX(), it.getY(), it.getZ()), h};
    if (!ZOverlaps(leaf, min_z_m, max_z_m)) continue;
    bool occupied = tree_.isNodeOccupied(*it);
    // A structure robots drive over is no obstacle however tall (the Over Under barrier's
    // 0.073 m pipe stands above the band's floor), unless a blocking one shares the voxel.
    if (occupied && std::any_of(season_.structures.begin(), season_.structures.end(),
                                [&](const field::Structure& s) {
                                  return DriveOver(s) && StructureOverlaps(leaf, s);
                                })) {
      occupied = std::any_of(
          season_.structures.begin(), season_.structures.end(),
          [&](const field::Structure& s) { return !DriveOver(s) && StructureOverlaps(leaf, s); });
    }
    const auto [col0, col1] =
        cell_range(leaf.centre.x() - h, leaf.centre.x() + h, grid.origin_m.x(), grid.width);
    const auto [row0, row1] =
        cell_range(leaf.centre.y() - h, leaf.centre.y() + h, grid.origin_m.y(), grid.height);
    for (int row = row0; row <= row1; ++row) {
      for (int col = col0; col <= col1; ++col) {
        std::uint8_t& cell = grid.cells[static_cast<size_t>(row) * grid.width + col];
        if (occupied) {
          cell = OccupancyGrid2D::kOccupied;
        } else if (cell == OccupancyGrid2D::kUnknown) {
          cell = OccupancyGrid2D::kFree;
        }
      }
    }
  }
  return grid;
}

void ObjectMap::WriteBinary(const std::string& path) const {
  std::ofstream out = OpenForWriting(path);
  if (!tree_.writeBinaryConst(out)) throw std::runtime_error(path + ": write failed");
  CloseOrThrow(out, path);
}

void ObjectMap::WriteColored(const std::string& path) const {
  ExactColourOcTree coloured(tree_.getResolution());
  coloured.setClampingThresMin(tree_.getClampingThresMin());
  coloured.setClampingThresMax(tree_.getClampingThresMax());
  coloured.setOccupancyThres(tree_.getOccupancyThres());
  const field::Rgb floor = PaletteColour(season_.field.tile_colour);
  const unsigned int max_depth = tree_.getTreeDepth();

  // Every voxel of every leaf (pruned leaves cover many), coloured by what it is.
  for (auto it = tree_.begin_leafs(), end = tree_.end_leafs(); it != end; ++it) {
    const float value = it->getLogOdds();
    const bool occupied = tree_.isNodeOccupied(*it);
    const octomap::OcTreeKey first = it.getIndexKey();
    const int span = 1 << (max_depth - it.getDepth());
    octomap::OcTreeKey key;
    for (int dx = 0; dx < span; ++dx) {
      for (int dy = 0; dy < span; ++dy) {
        for (int dz = 0; dz < span; ++dz) {
          key[0] = static_cast<octomap::key_type>(first[0] + dx);
          key[1] = static_cast<octomap::key_type>(first[1] + dy);
          key[2] = static_cast<octomap::key_type>(first[2] + dz);
          field::Rgb colour = occupied ? kObservedColour : floor;
          if (auto object = object_voxels_.find(key); object != object_voxels_.end()) {
            colour = object->second.colour;
          } else if (auto structure = structure_colour_.find(key);
                     occupied && structure != structure_colour_.end()) {
            colour = structure->second;
          }
          octomap::ColorOcTreeNode* node = coloured.setNodeValue(key, value, /*lazy_eval=*/true);
          node->setColor(colour.r, colour.g, colour.b);
        }
      }
    }
  }
  coloured.updateInnerOccupancy();
  coloured.prune();

  std::ofstream out = OpenForWriting(path);
  if (!coloured.write(out)) throw std::runtime_error(path + ": write failed");
  CloseOrThrow(out, path);
}

ObjectMapStats ObjectMap::Stats() const {
  ObjectMapStats stats;
  const unsigned int max_depth = tree_.getTreeDepth();
  for (auto it = tree_.begin_leafs(), end = tree_.end_leafs(); it != end; ++it) {
    const size_t voxels = size_t{1} << (3 * (max_depth - it.getDepth()));
    ++stats.leaf_nodes;
    if (tree_.isNodeOccupied(*it)) {
      ++stats.occupied_leaves;
      stats.occupied_voxels += voxels;
    } else {
      ++stats.free_leaves;
      stats.free_voxels += voxels;
    }
  }
  stats.structure_voxels = structure_colour_.size();
  stats.object_voxels = object_voxels_.size();
  stats.memory_bytes = tree_.memoryUsage();
  return stats;
}

field::Rgb ObjectMap::PaletteColour(const std::string& name) const {
  const auto it = season_.colours.find(name);
  return it == season_.colours.end() ? kFallbackColour : it->second;
}

void ObjectMap::Finish() {
  tree_.updateInnerOccupancy();
  tree_.prune();
}

}  // namespace slamo::mapping
