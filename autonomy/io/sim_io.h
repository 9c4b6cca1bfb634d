// The robot of a dry run: the simulated field behind RobotIo (autonomy/robot_io.h), the one
// place the match loop's robot meets the simulator. It knows the truth: the true pose, the
// points, where every object is.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "autonomy/loop/executive.h"
#include "autonomy/loop/robot_io.h"
#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "strategy/strategy.h"

namespace slamo::autonomy {

// The simulated field of a dry run: SimField (drive base with slip, objects, opponents,
// intake, scoring), its camera renderer and a yaw gyro, all seeded by `seed`; time on a
// SimClock, so a dry run goes as fast as the computer allows and replays exactly. The field
// given to Start() is the season as its file has it (what the robot is told); the simulator
// places its objects from it for `seed` (PlaceObjects with placement_jitter_m), and only the
// simulator knows where they went.
std::unique_ptr<RobotIo> MakeSimIo(field::Alliance alliance, uint64_t seed,
                                   double placement_jitter_m = 0.0,
                                   Scenario scenario = Scenario::kNominal);

// The season with its fixed-position floor objects moved (clear of walls and structures), so
// no two seeds share a layout: nominal, uniformly up to jitter_m along each axis; disturbed,
// kDisturbMin_m to kDisturbMax_m in a uniform direction (jitter_m is not used). Preloads
// (objects on a starting tile) and raised objects stay; a stack moves as one.
field::SeasonConfig PlaceObjects(const field::SeasonConfig& season, double jitter_m, uint64_t seed,
                                 Scenario scenario = Scenario::kNominal);

// A dry run: one autonomous period on the simulated field (MakeSimIo), its objects placed for
// `seed` (PlaceObjects with setup.placement_jitter_m); the robot and its strategy know only
// `season` as its file has it. `progress` (optional) hears each action
// as it starts. When out_dir is set, the OctoMap object map is written there as objects.bt.
MatchResult RunMatch(const field::SeasonConfig& season, const field::RobotConfig& robot,
                     const MatchSetup& setup, uint64_t seed, const std::string& out_dir = "",
                     const std::function<void(const TimelineEntry&)>& progress = {});
// The same with a strategy of the caller's (setup.strategy is not used).
MatchResult RunMatchWith(std::unique_ptr<strategy::Strategy> strategy,
                         const field::SeasonConfig& season, const field::RobotConfig& robot,
                         const MatchSetup& setup, uint64_t seed, const std::string& out_dir = "",
                         const std::function<void(const TimelineEntry&)>& progress = {});

}  // namespace slamo::autonomy
