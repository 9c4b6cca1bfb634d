// Render time per 512x424 colour + depth frame (one core), from the start tile and from mid
// field looking at many objects.
#include <benchmark/benchmark.h>

#include "field_configs/loader.h"
#include "platform/sim/sim_renderer.h"

namespace slamo::platform {
namespace {

void BM_RenderFrame(benchmark::State& state, Pose2D pose, bool with_objects) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  SimWorld world = CreateWorld(season, 1);
  if (!with_objects) world.objects.clear();
  SimRenderer renderer(season, robot.camera, RenderOptions{}, 1);
  FrameTruth truth;
  for (auto _ : state) {
    RgbdFrame frame = renderer.Render(world, pose, 0.0, &truth);
    benchmark::DoNotOptimize(frame.depth_mm.data);
  }
  state.SetLabel(std::to_string(robot.camera.width_px) + "x" +
                 std::to_string(robot.camera.height_px));
}
BENCHMARK_CAPTURE(BM_RenderFrame, start_tile, Pose2D{-0.8955, 1.40, 0.0}, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RenderFrame, mid_field, Pose2D{-0.9, 0.0, 0.0}, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RenderFrame, start_tile_no_objects, Pose2D{-0.8955, 1.40, 0.0}, false)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamo::platform

BENCHMARK_MAIN();
