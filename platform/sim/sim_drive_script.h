// Drive scripts on the simulated drive base: the drive controller (platform/drive_script.h)
// with SimDriveBase as its body, time on a SimClock in lockstep.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "field_configs/robot_config.h"
#include "platform/clock.h"
#include "platform/drive_base.h"
#include "platform/drive_script.h"
#include "platform/sim/sim_drive.h"

namespace slamo::platform {

// Drives `steps` on `sim`, advancing `clock` in lockstep with it. Headings are tracked
// against the intended heading, so a turn also corrects the previous turn's encoder error.
// `advance` steps the simulation (default: sim->Step); a SimField passes its own Step so
// objects and opponents move with the robot.
std::vector<DriveStepResult> RunDriveScript(const std::vector<DriveStep>& steps,
                                            const DriveControllerOptions& options,
                                            SimDriveBase* sim, SimClock* clock,
                                            std::function<void(double)> advance = nullptr);

// For the command line: parses `script` (throws DriveScriptError), builds the robot's
// simulated drive base with `sim_options` and `seed` at `start` (collisions through the
// optional `is_free`, see SimDriveBase::SetFreeSpaceCheck), and runs it.
std::vector<DriveStepResult> SimulateDriveScript(
    const std::string& script, const field::RobotConfig& robot, const SimDriveOptions& sim_options,
    uint64_t seed, const Pose2D& start = {}, std::function<bool(const Pose2D&)> is_free = nullptr);

}  // namespace slamo::platform
