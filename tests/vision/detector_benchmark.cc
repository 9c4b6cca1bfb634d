// Detection per frame, for each method, on a rendered Toss Up view with solid and
// semi-transparent balls, at the depth camera's 512x424 and at 1920x1080 (the Kinect V2
// colour resolution); on a Push Back arena view, with and without the cut at depth edges;
// and the threshold's masks alone, by either path. One core.
#include <benchmark/benchmark.h>

#include <map>

#include <opencv2/imgproc.hpp>

#include "field_configs/loader.h"
#include "platform/sim/sim_renderer.h"
#include "vision/detector.h"

namespace slamo::vision {
namespace {

struct Scene {
  cv::Mat colour, depth;
  DetectorSetup setup;
};

const Scene& SceneAt(int width) {
  static std::map<int, Scene> scenes;
  auto it = scenes.find(width);
  if (it != scenes.end()) return it->second;
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  if (width != robot.camera.width_px) {
    // The Kinect V2 colour camera: 1920x1080, square pixels, fx = fy ~ 1081 px.
    robot.camera.width_px = 1920, robot.camera.height_px = 1080;
    robot.camera.fx = robot.camera.fy = 1081.37;
    robot.camera.cx = 959.5, robot.camera.cy = 539.5;
  }
  const platform::SimWorld world = platform::CreateWorld(season, 1);
  platform::SimRenderer renderer(season, robot.camera, platform::RenderOptions{}, 1);
  const platform::RgbdFrame frame =
      renderer.Render(world, platform::Pose2D{-1.2, -0.5, 0.5}, 0.0, nullptr);
  Scene scene{frame.colour, frame.depth_mm, ObjectDetectorSetup(season, &robot.camera)};
  return scenes.emplace(width, std::move(scene)).first->second;
}

// A Push Back view in the arena (blocks: every kind solid, so the cut at depth edges runs), at
// the depth camera's 512x424, looking across the field at the far alliance wall and the crowd.
const Scene& ArenaScene() {
  static const Scene scene = [] {
    const field::SeasonConfig season = field::LoadSeasonConfig("push_back");
    const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
    const platform::SimWorld world = platform::CreateWorld(season, 1);
    platform::RenderOptions render;
    render.arena = true;
    platform::SimRenderer renderer(season, robot.camera, render, 1);
    const platform::RgbdFrame frame =
        renderer.Render(world, platform::Pose2D{-1.0, 0.9, 0.2}, 0.0, nullptr);
    return Scene{frame.colour, frame.depth_mm, ObjectDetectorSetup(season, &robot.camera)};
  }();
  return scene;
}

void BM_DetectArena(benchmark::State& state, DetectMethod method, bool depth_cut) {
  const Scene& scene = ArenaScene();
  DetectOptions options;
  options.method = method;
  if (!depth_cut) options.depth_cut_min_m = 0.0;
  size_t found = 0;
  for (auto _ : state) {
    found = Detect(scene.colour, scene.depth, scene.setup, options).size();
    benchmark::DoNotOptimize(found);
  }
  state.SetLabel("push_back arena, " + std::to_string(found) + " found");
}

void BM_Detect(benchmark::State& state, DetectMethod method, SeparationMethod separation,
               bool split_spheres = true) {
  const Scene& scene = SceneAt(static_cast<int>(state.range(0)));
  DetectOptions options;
  options.method = method;
  options.separation = separation;
  options.split_spheres = split_spheres;
  size_t found = 0;
  for (auto _ : state) {
    const std::vector<Detection> detections =
        Detect(scene.colour, scene.depth, scene.setup, options);
    found = detections.size();
    benchmark::DoNotOptimize(found);
  }
  state.SetLabel(std::to_string(scene.colour.cols) + "x" + std::to_string(scene.colour.rows) +
                 ", " + std::to_string(found) + " found");
}

// The threshold's masks alone: BGR -> HSV -> windows, and the same masks straight from BGR.
void BM_Threshold(benchmark::State& state, bool from_bgr) {
  const Scene& scene = SceneAt(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    std::vector<cv::Mat> masks;
    if (from_bgr) {
      masks = ThresholdBgr(scene.colour, scene.setup.colours);
    } else {
      cv::Mat hsv;
      cv::cvtColor(scene.colour, hsv, cv::COLOR_BGR2HSV);
      masks = ThresholdHsv(hsv, scene.setup.colours);
    }
    benchmark::DoNotOptimize(masks.data());
  }
}

BENCHMARK_CAPTURE(BM_Threshold, hsv, false)->Arg(512)->Arg(1920)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Threshold, bgr, true)->Arg(512)->Arg(1920)->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_Detect, threshold_defects, DetectMethod::kThreshold,
                  SeparationMethod::kConcaveDefects)
    ->Arg(512)
    ->Arg(1920)
    ->Unit(benchmark::kMillisecond);
// What the split of touching balls by their centres costs (vision/sphere_split.h).
BENCHMARK_CAPTURE(BM_Detect, threshold_defects_without_sphere_split, DetectMethod::kThreshold,
                  SeparationMethod::kConcaveDefects, false)
    ->Arg(512)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detect, threshold_watershed, DetectMethod::kThreshold,
                  SeparationMethod::kWatershed)
    ->Arg(512)
    ->Arg(1920)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detect, kmeans_defects, DetectMethod::kKMeans,
                  SeparationMethod::kConcaveDefects)
    ->Arg(512)
    ->Arg(1920)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detect, kmeans_watershed, DetectMethod::kKMeans, SeparationMethod::kWatershed)
    ->Arg(512)
    ->Arg(1920)
    ->Unit(benchmark::kMillisecond);
// What the cut at depth edges costs (DetectOptions::depth_cut_min_m).
BENCHMARK_CAPTURE(BM_DetectArena, threshold_defects, DetectMethod::kThreshold, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DetectArena, threshold_defects_without_depth_cut, DetectMethod::kThreshold,
                  false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DetectArena, kmeans_defects, DetectMethod::kKMeans, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DetectArena, kmeans_defects_without_depth_cut, DetectMethod::kKMeans, false)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamo::vision

// One core: OpenCV's own worker threads off.
int main(int argc, char** argv) {
  cv::setNumThreads(0);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
