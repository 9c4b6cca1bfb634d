// Time per mask of each separation method (one core), on two and three touching balls of
// 100 px radius overlapping by 15 % of a diameter in a 640x480 mask.
#include <benchmark/benchmark.h>

#include <string>

#include <opencv2/imgproc.hpp>

#include "vision/separation.h"

namespace slamo::vision {
namespace {

cv::Mat BallsInARow(int count) {
  constexpr int kRadiusPx = 100;
  cv::Mat mask = cv::Mat::zeros(480, 640, CV_8UC1);
  const double step_px = 2.0 * kRadiusPx * 0.85;
  for (int i = 0; i < count; ++i) {
    cv::circle(mask, cv::Point(cvRound(110 + i * step_px), 240), kRadiusPx, cv::Scalar(255),
               cv::FILLED);
  }
  return mask;
}

void BM_Separate(benchmark::State& state, SeparationMethod method, int balls) {
  const cv::Mat mask = BallsInARow(balls);
  size_t pieces = 0;
  for (auto _ : state) {
    SeparationResult result = SeparateTouching(mask, method);
    pieces = result.pieces.size();
    benchmark::DoNotOptimize(result);
  }
  state.SetLabel(std::to_string(pieces) + " pieces");
}
BENCHMARK_CAPTURE(BM_Separate, none_2_balls, SeparationMethod::kNone, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Separate, defects_2_balls, SeparationMethod::kConcaveDefects, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Separate, watershed_2_balls, SeparationMethod::kWatershed, 2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Separate, none_3_balls, SeparationMethod::kNone, 3)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Separate, defects_3_balls, SeparationMethod::kConcaveDefects, 3)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Separate, watershed_3_balls, SeparationMethod::kWatershed, 3)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamo::vision

BENCHMARK_MAIN();
