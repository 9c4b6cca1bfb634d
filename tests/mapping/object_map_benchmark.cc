// The OctoMap object map: fusing a 20k-point depth frame at 5 and 2 cm, building the Toss Up
// map, replacing its 28 objects (side table, and against rebuilding from a copy of the static
// map) and the 2D planning grid. One core.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "field_configs/loader.h"
#include "mapping/object_map.h"
#include "platform/sim/sim_world.h"

namespace slamo::mapping {
namespace {

const field::SeasonConfig& Season() {
  static const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  return season;
}

ObjectMapOptions AtResolution(double resolution_m) {
  ObjectMapOptions options;
  options.resolution_m = resolution_m;
  return options;
}

// A depth camera 30 cm up at the near end looking down the field: 70 x 50 deg, rays end on
// the floor, the far wall or at 3.5 m.
const Eigen::Vector3d kSensor(-1.5, 0.0, 0.3);

std::vector<Eigen::Vector3d> DepthFrame(int points) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> yaw(-0.61, 0.61), pitch(-0.44, 0.44);
  std::vector<Eigen::Vector3d> cloud;
  cloud.reserve(points);
  const double wall_x = Season().HalfSize();
  while (static_cast<int>(cloud.size()) < points) {
    const double a = yaw(rng), b = pitch(rng);
    const Eigen::Vector3d d(std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b));
    double range = 3.5;
    if (d.z() < 0) range = std::min(range, -kSensor.z() / d.z());
    range = std::min(range, (wall_x - kSensor.x()) / d.x());
    cloud.push_back(kSensor + range * d);
  }
  return cloud;
}

std::vector<MappedObject> StartingObjects(uint64_t seed) {
  const platform::SimWorld world = platform::CreateWorld(Season(), seed);
  std::vector<MappedObject> objects;
  for (const platform::SimObject& o : world.objects) {
    objects.push_back(
        {o.id, o.type->name, o.colour, o.center_m, o.type->size_m / 2, o.type->height_m, 1.0});
  }
  return objects;
}

void BM_InsertPointCloud(benchmark::State& state) {
  const double resolution_m = state.range(0) / 100.0;
  const std::vector<Eigen::Vector3d> cloud = DepthFrame(20000);
  for (auto _ : state) {
    state.PauseTiming();
    ObjectMap map(Season(), AtResolution(resolution_m));
    state.ResumeTiming();
    map.InsertPointCloud(cloud, kSensor, 4.0);
    benchmark::DoNotOptimize(map.tree().size());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(cloud.size()));
}
BENCHMARK(BM_InsertPointCloud)->Arg(5)->Arg(2)->ArgName("cm")->Unit(benchmark::kMillisecond);

void BM_BuildTossUpMap(benchmark::State& state) {
  const double resolution_m = state.range(0) / 100.0;
  for (auto _ : state) {
    ObjectMap map(Season(), AtResolution(resolution_m));
    benchmark::DoNotOptimize(map.tree().size());
  }
}
BENCHMARK(BM_BuildTossUpMap)->Arg(5)->Arg(2)->ArgName("cm")->Unit(benchmark::kMillisecond);

// The side table, worst case: every object moves 10 cm.
void BM_SetObjects(benchmark::State& state) {
  const double resolution_m = state.range(0) / 100.0;
  std::vector<MappedObject> objects = StartingObjects(1);
  ObjectMap map(Season(), AtResolution(resolution_m));
  map.SetObjects(objects);
  bool flip = false;
  for (auto _ : state) {
    flip = !flip;
    for (MappedObject& o : objects) o.centre_m.x() += flip ? 0.1 : -0.1;
    map.SetObjects(objects);
    benchmark::DoNotOptimize(map.tree().size());
  }
  state.counters["objects"] = static_cast<double>(objects.size());
}
BENCHMARK(BM_SetObjects)->Arg(5)->Arg(2)->ArgName("cm")->Unit(benchmark::kMillisecond);

// A typical frame: one of the 28 objects moved (pushed), the others are where they were.
void BM_SetObjectsOneMoves(benchmark::State& state) {
  const double resolution_m = state.range(0) / 100.0;
  std::vector<MappedObject> objects = StartingObjects(1);
  ObjectMap map(Season(), AtResolution(resolution_m));
  map.SetObjects(objects);
  bool flip = false;
  for (auto _ : state) {
    objects[0].centre_m.x() += (flip = !flip) ? 0.1 : -0.1;
    map.SetObjects(objects);
    benchmark::DoNotOptimize(map.tree().size());
  }
}
BENCHMARK(BM_SetObjectsOneMoves)->Arg(5)->Arg(2)->ArgName("cm")->Unit(benchmark::kMillisecond);

// The alternative: copy the static map and insert the objects into the copy.
void BM_SetObjectsByRebuild(benchmark::State& state) {
  const double resolution_m = state.range(0) / 100.0;
  std::vector<MappedObject> objects = StartingObjects(1);
  const ObjectMap static_map(Season(), AtResolution(resolution_m));
  bool flip = false;
  for (auto _ : state) {
    flip = !flip;
    for (MappedObject& o : objects) o.centre_m.x() += flip ? 0.1 : -0.1;
    ObjectMap map(static_map);
    map.SetObjects(objects);
    benchmark::DoNotOptimize(map.tree().size());
  }
}
BENCHMARK(BM_SetObjectsByRebuild)->Arg(5)->Arg(2)->ArgName("cm")->Unit(benchmark::kMillisecond);

void BM_ToGrid(benchmark::State& state) {
  const double resolution_m = state.range(0) / 100.0;
  ObjectMap map(Season(), AtResolution(resolution_m));
  map.SetObjects(StartingObjects(1));
  for (auto _ : state) {
    const OccupancyGrid2D grid = map.ToGrid(0.02, 0.06, 0.5);
    benchmark::DoNotOptimize(grid.cells.data());
  }
}
BENCHMARK(BM_ToGrid)->Arg(5)->Arg(2)->ArgName("map_cm")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamo::mapping

BENCHMARK_MAIN();
