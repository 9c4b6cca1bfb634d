// `slamo map build`: the OctoMap object map of a season with its starting objects (as the
// simulator places them from the seed). Writes map.bt (occupancy), map.ot (a ColorOcTree
// coloured by what each voxel is) and grid.png (the 2D planning footprint), and prints voxel
// counts and the time taken.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "autonomy/cli/commands.h"
#include "field_configs/loader.h"
#include "mapping/object_map.h"
#include "platform/sim/sim_world.h"

namespace slamo::autonomy {
namespace {

struct MapArgs {
  std::string season = field::kDefaultSeason;
  double resolution_m = 0.05;
  uint64_t seed = 1;
  std::string out;
  double grid_cell_m = 0.0;    // 0: the map's resolution
  double grid_min_z_m = 0.06;  // above drive-over bumps
  double grid_max_z_m = 0.50;  // up to a robot's height
};

// grid.png is scaled up (whole pixels per cell) to about this size.
constexpr int kPictureMinPx = 600;

double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Free light grey, occupied black, unknown mid grey; +x to the right, +y up.
cv::Mat GridPicture(const mapping::OccupancyGrid2D& grid, int min_px) {
  cv::Mat picture(grid.height, grid.width, CV_8UC1);
  for (int row = 0; row < grid.height; ++row) {
    for (int col = 0; col < grid.width; ++col) {
      const std::uint8_t cell = grid.At(col, row);
      picture.at<std::uint8_t>(grid.height - 1 - row, col) =
          cell == mapping::OccupancyGrid2D::kOccupied ? 0
          : cell == mapping::OccupancyGrid2D::kFree   ? 220
                                                      : 128;
    }
  }
  const int scale = std::max(1, min_px / std::max(1, std::max(grid.width, grid.height)));
  cv::Mat scaled;
  cv::resize(picture, scaled, cv::Size(), scale, scale, cv::INTER_NEAREST);
  return scaled;
}

int Build(const MapArgs& args) {
  if (!(args.grid_max_z_m > args.grid_min_z_m)) {
    std::cerr << "error: --grid-max-z must be above --grid-min-z\n";
    return 2;
  }
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const platform::SimWorld world = platform::CreateWorld(season, args.seed);
  std::vector<mapping::MappedObject> objects;
  std::map<std::string, int> per_type;
  for (const platform::SimObject& o : world.objects) {
    if (o.held) continue;
    objects.push_back(
        {o.id, o.type->name, o.colour, o.center_m, o.type->size_m / 2, o.type->height_m, 1.0});
    ++per_type[o.type->name];
  }

  mapping::ObjectMapOptions options;
  options.resolution_m = args.resolution_m;
  const auto start = std::chrono::steady_clock::now();
  mapping::ObjectMap map(season, options);
  const double static_ms = MsSince(start);
  const auto objects_start = std::chrono::steady_clock::now();
  map.SetObjects(objects);
  const double objects_ms = MsSince(objects_start);
  const double cell_m = args.grid_cell_m > 0 ? args.grid_cell_m : args.resolution_m;
  const auto grid_start = std::chrono::steady_clock::now();
  const mapping::OccupancyGrid2D grid = map.ToGrid(cell_m, args.grid_min_z_m, args.grid_max_z_m);
  const double grid_ms = MsSince(grid_start);

  const std::filesystem::path dir(args.out);
  const std::string bt = (dir / "map.bt").string(), ot = (dir / "map.ot").string();
  const std::string png = (dir / "grid.png").string();
  try {
    std::filesystem::create_directories(dir);
    const auto write_start = std::chrono::steady_clock::now();
    map.WriteBinary(bt);
    map.WriteColored(ot);
    const double write_ms = MsSince(write_start);
    if (!cv::imwrite(png, GridPicture(grid, kPictureMinPx))) {
      throw std::runtime_error(png + ": cannot write the picture");
    }

    const mapping::ObjectMapStats stats = map.Stats();
    std::printf("%s (%s), seed %llu: %zu objects (", season.name.c_str(), season.season.c_str(),
                static_cast<unsigned long long>(args.seed), objects.size());
    for (auto it = per_type.begin(); it != per_type.end(); ++it) {
      std::printf("%s%d %s", it == per_type.begin() ? "" : ", ", it->second, it->first.c_str());
    }
    std::printf(")\n");
    std::printf("resolution: %.3f m\n", args.resolution_m);
    std::printf(
        "voxels: %zu occupied, %zu free; of the layers: %zu wall and structure, %zu object (they "
        "overlap where an object lies on a structure)\n",
        stats.occupied_voxels, stats.free_voxels, stats.structure_voxels, stats.object_voxels);
    std::printf("octree: %zu leaves (%zu occupied, %zu free), %.1f KiB\n", stats.leaf_nodes,
                stats.occupied_leaves, stats.free_leaves, stats.memory_bytes / 1024.0);
    size_t counts[3] = {0, 0, 0};  // occupied, free, unknown
    for (const std::uint8_t cell : grid.cells) {
      ++counts[cell == mapping::OccupancyGrid2D::kOccupied ? 0
               : cell == mapping::OccupancyGrid2D::kFree   ? 1
                                                           : 2];
    }
    std::printf(
        "grid: %dx%d cells of %.3f m, z %.2f..%.2f m: %zu occupied, %zu free, %zu unknown\n",
        grid.width, grid.height, cell_m, args.grid_min_z_m, args.grid_max_z_m, counts[0], counts[1],
        counts[2]);
    std::printf("time: static map %.1f ms, objects %.1f ms, grid %.1f ms, writing %.1f ms\n",
                static_ms, objects_ms, grid_ms, write_ms);
    std::printf("wrote %s (%ju bytes), %s (%ju bytes), %s\n", bt.c_str(),
                static_cast<uintmax_t>(std::filesystem::file_size(bt)), ot.c_str(),
                static_cast<uintmax_t>(std::filesystem::file_size(ot)), png.c_str());
  } catch (const std::runtime_error& e) {  // includes std::filesystem::filesystem_error
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

void RegisterMapCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<MapArgs>();
  CLI::App* map = app.add_subcommand(
      "map", "The OctoMap object map.   e.g. slamo map build --season toss_up --out DIR");
  map->require_subcommand(1);

  CLI::App* build = map->add_subcommand(
      "build",
      "Build the map of a season with its starting objects; write map.bt, map.ot (coloured) and "
      "grid.png.   e.g. slamo map build --season toss_up --resolution 0.02 --out DIR");
  build->add_option("--season", args->season, "season name or .yaml file")->capture_default_str();
  build->add_option("--resolution", args->resolution_m, "voxel edge in metres")
      ->check(CLI::Range(0.005, 0.5))
      ->capture_default_str();
  build->add_option("--seed", args->seed, "random seed (objects placed in regions)")
      ->capture_default_str();
  build->add_option("--out,-o", args->out, "output directory")->required();
  build
      ->add_option("--grid-cell", args->grid_cell_m,
                   "grid.png cell edge in metres (0: the map's resolution)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  build->add_option("--grid-min-z", args->grid_min_z_m, "grid: lowest height in metres")
      ->capture_default_str();
  build->add_option("--grid-max-z", args->grid_max_z_m, "grid: highest height in metres")
      ->capture_default_str();
  build->callback([action, args] { *action = [args] { return Build(*args); }; });
}

}  // namespace slamo::autonomy
