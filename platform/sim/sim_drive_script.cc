#include "platform/sim/sim_drive_script.h"

#include <utility>

namespace slamo::platform {

std::vector<DriveStepResult> RunDriveScript(const std::vector<DriveStep>& steps,
                                            const DriveControllerOptions& options,
                                            SimDriveBase* sim, SimClock* clock,
                                            std::function<void(double)> advance) {
  DriveBodyLink body;
  body.base = sim;
  body.metres_per_tick = sim->metres_per_tick();
  body.track_width_m = sim->drive().track_width_m;
  body.odometry_start = sim->odometry_pose();
  body.clock = clock;
  body.advance = [sim, clock, step = std::move(advance)](double dt_s) {
    if (step) {
      step(dt_s);
    } else {
      sim->Step(dt_s);
    }
    clock->Advance(dt_s);
  };
  body.truth = [sim]() { return sim->true_pose(); };
  return RunDriveScript(steps, options, body);
}

std::vector<DriveStepResult> SimulateDriveScript(const std::string& script,
                                                 const field::RobotConfig& robot,
                                                 const SimDriveOptions& sim_options, uint64_t seed,
                                                 const Pose2D& start,
                                                 std::function<bool(const Pose2D&)> is_free) {
  const std::vector<DriveStep> steps = ParseDriveScript(script);
  SimDriveBase sim(robot.drive, sim_options, seed, start);
  if (is_free) sim.SetFreeSpaceCheck(std::move(is_free));
  SimClock clock;
  return RunDriveScript(steps, DriveControllerOptionsFor(robot.drive), &sim, &clock);
}

}  // namespace slamo::platform
