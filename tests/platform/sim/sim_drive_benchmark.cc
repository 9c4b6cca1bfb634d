// Speed of the simulated drive base: one physics step at the firmware's PID period, and a
// whole scripted 0.3 m drive.
#include <benchmark/benchmark.h>

#include "field_configs/loader.h"
#include "platform/drive_script.h"
#include "platform/sim/sim_drive.h"
#include "platform/sim/sim_drive_script.h"

namespace slamo::platform {
namespace {

void BM_SimDriveStep(benchmark::State& state) {
  const field::DriveConfig drive = field::LoadRobotConfig("thesis_robot").drive;
  SimDriveBase sim(drive, SimDriveOptions{}, 1);
  sim.SetSpeedTargets(0.067, 0.06);
  const double dt_s = 1.0 / drive.pid.rate_hz;
  for (auto _ : state) {
    sim.Step(dt_s);
    benchmark::DoNotOptimize(sim.true_pose());
  }
}
BENCHMARK(BM_SimDriveStep);

void BM_DriveScriptForward(benchmark::State& state) {
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  uint64_t seed = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(SimulateDriveScript("forward 0.3", robot, {}, ++seed));
  }
}
BENCHMARK(BM_DriveScriptForward)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace slamo::platform

BENCHMARK_MAIN();
