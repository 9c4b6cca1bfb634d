// Many simulated matches: every combination of parameter values times N seeds, run in
// separate processes (OMPL's random numbers are per process, so each match gets a fresh one
// and stays repeatable), summarised per combination with a confidence interval.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autonomy/loop/executive.h"
#include "autonomy/loop/match_world.h"
#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"

namespace slamo::autonomy {

// A parameter sweep: name -> the values to try ("strategy" -> {"planner", "greedy"}).
using ParamGrid = std::vector<std::pair<std::string, std::vector<std::string>>>;
using ParamSet = std::vector<std::pair<std::string, std::string>>;

// The names --param accepts, with what they set.
const std::map<std::string, std::string>& TunableParams();
// Applies name=value to a setup; throws std::invalid_argument on an unknown name or value.
void ApplyParam(const std::string& name, const std::string& value, MatchSetup* setup);
// "name=v1,v2,..." -> (name, values); throws std::invalid_argument.
std::pair<std::string, std::vector<std::string>> ParseParam(const std::string& text);
// Every combination, in a fixed order.
std::vector<ParamSet> Combinations(const ParamGrid& grid);
std::string Describe(const ParamSet& params);

// One match's outcome, as a tuning run keeps it.
struct MatchOutcome {
  std::string combo;
  uint64_t seed = 0;
  int points = 0;
  int points_start = 0;
  double overrun_s = 0.0;
  int refused = 0;
  double pose_ate_m = 0.0;
  int nees_updates = 0, nees_honest = 0;  // filter updates; NEES in its band or below
  int attempts = 0, attempts_inside = 0;  // picks/scores; true error inside the 3-sigma
  // Every pick and score attempt, judged on the simulator (AttemptCheck::outcome): the
  // records `tune calibrate` fits its success models to.
  std::vector<AttemptCheck> records;
  double duration_s = 0.0;
  double wall_s = 0.0;
  bool failed = false;  // the match process crashed or threw
  std::string error;
};
nlohmann::json ToJson(const MatchOutcome& o);
MatchOutcome OutcomeFromJson(const nlohmann::json& j);

struct TuneTask {
  size_t combo_index = 0;
  uint64_t seed = 0;
};

// Runs the tasks on `jobs` processes; `progress(done, total)` after each. Every match starts
// from `base` (snapshots off) with its combination's parameters applied.
std::vector<MatchOutcome> RunTasks(const field::SeasonConfig& season,
                                   const field::RobotConfig& robot,
                                   const std::vector<ParamSet>& combos,
                                   const std::vector<TuneTask>& tasks, int jobs,
                                   const std::function<void(size_t, size_t)>& progress,
                                   const MatchSetup& base = MatchSetup());

struct ComboSummary {
  std::string combo;
  int matches = 0;
  int failed = 0;
  double mean_points = 0.0;
  double ci95_points = 0.0;  // half-width of the 95 % confidence interval of the mean
  double mean_gained = 0.0;
  double ci95_gained = 0.0;
  int overruns = 0;  // matches with motors driven after the deadline
  double mean_overrun_s = 0.0;
  double mean_ate_m = 0.0;
  double nees_honest_fraction = 0.0;  // over all updates: NEES in its band or below
  // Over all picks (skipped ones too: the pose is checked when the pick starts) and scores:
  // the true error inside 3-sigma.
  double attempts_inside_fraction = 0.0;
  // Picks that took their target, another object, nothing; releases that scored in the goal
  // aimed at (fractions of the attempts; NaN: none). Picks given up before the approach
  // (the look on arrival did not find the target) are not attempts: counted apart.
  int picks = 0, releases = 0, pick_skips = 0;
  double pick_target_fraction = 0.0, pick_other_fraction = 0.0, pick_nothing_fraction = 0.0;
  double release_scored_fraction = 0.0;
  // Knocks off a raised structure, and the fraction that brought the object down into the
  // zone aimed at.
  int knocks = 0;
  double knock_scored_fraction = 0.0;
  double mean_wall_s = 0.0;
};
// Per combination, ranked by mean points (best first).
std::vector<ComboSummary> Summarise(const std::vector<MatchOutcome>& outcomes);
std::string SummaryCsv(const std::vector<ComboSummary>& rows);
nlohmann::json SummaryJson(const std::vector<ComboSummary>& rows,
                           const std::vector<MatchOutcome>& outcomes);
void PrintSummaryTable(const std::vector<ComboSummary>& rows, std::ostream& out);
// Every attempt of every match, one row each (combo, seed, action, kind, colour, goal,
// range_m, bearing_deg, sigma_m, error_m, target_error_m, outcome): attempts.csv.
std::string AttemptsCsv(const std::vector<MatchOutcome>& outcomes);

}  // namespace slamo::autonomy
