// The robot of a dry run: the simulated field behind RobotIo (autonomy/robot_io.h), the one
// place the match loop's robot meets the simulator. It knows the truth: the true pose, the
// points, where every object is.
#pragma once

#include <cstdint>
#include <memory>

#include "autonomy/robot_io.h"
#include "field_configs/season_config.h"

namespace slamo::autonomy {

// The simulated field of a dry run: SimField (drive base with slip, objects, opponents,
// intake, scoring), its camera renderer and a yaw gyro, all seeded by `seed`; time on a
// SimClock, so a dry run goes as fast as the computer allows and replays exactly.
std::unique_ptr<RobotIo> MakeSimIo(field::Alliance alliance, uint64_t seed);

}  // namespace slamo::autonomy
