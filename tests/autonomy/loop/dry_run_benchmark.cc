// Wall time of a full simulated autonomous period (45 s on Toss Up) on one core, per
// strategy; the counter x_real_time is match seconds per wall second (goal: >= 20).
#include <benchmark/benchmark.h>

#include "autonomy/io/sim_io.h"
#include "autonomy/loop/executive.h"
#include "field_configs/loader.h"

namespace slamo::autonomy {
namespace {

void BM_DryRun(benchmark::State& state, const std::string& strategy) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  MatchSetup setup;
  setup.strategy = strategy;
  setup.snapshot_period_s = 0.0;  // no replay pictures: the match itself
  uint64_t seed = 1;
  double match_s = 0.0;
  for (auto _ : state) {
    const MatchResult r = RunMatch(season, robot, setup, seed++);
    match_s += r.deadline_s;
    benchmark::DoNotOptimize(r.points);
  }
  state.counters["x_real_time"] = benchmark::Counter(match_s, benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_DryRun, planner, std::string("planner"))
    ->Unit(benchmark::kSecond)
    ->Iterations(5)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_DryRun, greedy, std::string("greedy"))
    ->Unit(benchmark::kSecond)
    ->Iterations(5)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_DryRun, scripted, std::string("scripted"))
    ->Unit(benchmark::kSecond)
    ->Iterations(5)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_DryRun, thesis, std::string("thesis"))
    ->Unit(benchmark::kSecond)
    ->Iterations(5)
    ->UseRealTime();

}  // namespace
}  // namespace slamo::autonomy

BENCHMARK_MAIN();
