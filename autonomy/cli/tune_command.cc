// `slamo tune`: N seeded matches for every combination of --param values, on J processes, with
// a progress bar; prints the ranked table and writes tune.csv and tune.json. `--shard K/N`
// runs every N-th match only (for a batch system) and writes its outcomes; `tune merge`
// ranks the shards' outcomes together. Exit status: 0, 1 when files cannot be written, 2 on
// bad input.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "autonomy/cli/commands.h"
#include "autonomy/cli/options.h"
#include "autonomy/experiments/calibration.h"
#include "autonomy/experiments/tuning.h"
#include "field_configs/loader.h"

namespace slamo::autonomy {
namespace {

struct TuneArgs {
  std::string season = field::kDefaultSeason;
  std::string robot = field::kDefaultRobot;
  int matches = 20;
  uint64_t seed_base = 1;
  std::vector<std::string> params;
  std::vector<std::string> scenarios;  // --scenario: shorthand for --param scenario=...
  std::string calibration;             // learned P(success) for every match
  int jobs = 1;
  std::string shard;  // "K/N"
  std::string out = "tune";
  std::vector<std::string> merge_files;
  std::vector<std::string> calibrate_files;
  std::string combo;            // calibrate: only this combination's matches
  std::string calibration_out;  // calibrate: the model file
};

// tune.json files (or shards) -> their match outcomes; false (and a message) when one cannot
// be read.
bool ReadOutcomes(const std::vector<std::string>& files, std::vector<MatchOutcome>* outcomes) {
  for (const std::string& file : files) {
    std::ifstream in(file);
    if (!in) {
      std::cerr << "error: " << file << ": cannot read\n";
      return false;
    }
    try {
      const nlohmann::json j = nlohmann::json::parse(in);
      const nlohmann::json& list = j.is_array() ? j : j.at("matches");
      for (const nlohmann::json& o : list) outcomes->push_back(OutcomeFromJson(o));
    } catch (const std::exception& e) {
      std::cerr << "error: " << file << ": not a tune shard or tune.json (" << e.what() << ")\n";
      return false;
    }
  }
  return true;
}

bool WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) std::cerr << "error: cannot write " << path << "\n";
  return static_cast<bool>(out);
}

int Report(const std::vector<MatchOutcome>& outcomes, const std::string& dir) {
  const std::vector<ComboSummary> rows = Summarise(outcomes);
  PrintSummaryTable(rows, std::cout);
  if (!WriteText(dir + "/tune.csv", SummaryCsv(rows))) return 1;
  if (!WriteText(dir + "/tune.json", SummaryJson(rows, outcomes).dump(2) + "\n")) return 1;
  if (!WriteText(dir + "/attempts.csv", AttemptsCsv(outcomes))) return 1;
  std::cout << "wrote " << dir << "/tune.csv, " << dir << "/tune.json and " << dir
            << "/attempts.csv (every pick and score attempt)\n";
  return 0;
}

int Tune(const TuneArgs& args) {
  ParamGrid grid;
  int shard_k = 1, shard_n = 1;
  try {
    for (const std::string& p : args.params) grid.push_back(ParseParam(p));
    if (!args.scenarios.empty()) {
      std::string joined;
      for (const std::string& s : args.scenarios) joined += (joined.empty() ? "" : ",") + s;
      for (const auto& [name, values] : grid) {
        if (name == "scenario")
          throw std::invalid_argument("--scenario and --param scenario=...: give one of them");
      }
      grid.push_back(ParseParam("scenario=" + joined));
    }
    if (!args.shard.empty()) {
      if (std::sscanf(args.shard.c_str(), "%d/%d", &shard_k, &shard_n) != 2 || shard_n < 1 ||
          shard_k < 1 || shard_k > shard_n) {
        throw std::invalid_argument("--shard: expected K/N with 1 <= K <= N, got \"" + args.shard +
                                    "\"");
      }
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  MatchSetup base;
  if (!args.calibration.empty()) {
    try {
      base.strategy_options.learned_success =
          LearnedSuccess(LoadCalibration(args.calibration, season.season, robot.name));
    } catch (const std::invalid_argument& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
  }
  const std::vector<ParamSet> combos = Combinations(grid);
  std::vector<TuneTask> tasks;
  size_t index = 0;
  for (size_t c = 0; c < combos.size(); ++c) {
    for (int m = 0; m < args.matches; ++m, ++index) {
      if (static_cast<int>(index % shard_n) == shard_k - 1)
        tasks.push_back({c, args.seed_base + m});
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) {
    std::cerr << "error: " << args.out << ": " << ec.message() << "\n";
    return 1;
  }
  std::cout << season.name << ": " << combos.size() << " combination(s) x " << args.matches
            << " seeds (" << args.seed_base << ".." << args.seed_base + args.matches - 1 << ")";
  if (shard_n > 1) std::cout << ", shard " << shard_k << "/" << shard_n;
  std::cout << ": " << tasks.size() << " matches on " << args.jobs << " process(es)\n";

  const auto start = std::chrono::steady_clock::now();
  const std::vector<MatchOutcome> outcomes = RunTasks(
      season, robot, combos, tasks, args.jobs,
      [&](size_t done, size_t total) {
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double eta = done ? elapsed / done * (total - done) : 0.0;
        const int width = 30, filled = static_cast<int>(width * done / std::max<size_t>(total, 1));
        std::fprintf(stderr, "\r[%s%s] %zu/%zu  %.1f matches/min  ETA %dm%02ds ",
                     std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
                     done, total, done / std::max(elapsed, 1e-9) * 60.0, static_cast<int>(eta) / 60,
                     static_cast<int>(eta) % 60);
        if (done == total) std::fprintf(stderr, "\n");
      },
      base);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "throughput: " << tasks.size() << " matches in " << elapsed << " s, "
            << (elapsed > 0 ? tasks.size() / elapsed * 60.0 : 0.0) << " matches per minute on "
            << args.jobs << " process(es)\n";
  if (shard_n > 1) {
    nlohmann::json j = nlohmann::json::array();
    for (const MatchOutcome& o : outcomes) j.push_back(ToJson(o));
    const std::string path =
        args.out + "/shard-" + std::to_string(shard_k) + "-of-" + std::to_string(shard_n) + ".json";
    if (!WriteText(path, j.dump() + "\n")) return 1;
    std::cout << "wrote " << path << " (rank the shards with: slamo tune merge " << args.out
              << "/shard-*.json)\n";
    return 0;
  }
  return Report(outcomes, args.out);
}

int Merge(const TuneArgs& args) {
  std::vector<MatchOutcome> outcomes;
  if (!ReadOutcomes(args.merge_files, &outcomes)) return 2;
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  std::cout << outcomes.size() << " matches from " << args.merge_files.size() << " file(s)\n";
  return Report(outcomes, args.out);
}

// Success models from the attempts of the matches in the files: printed with their
// reliability table, written as JSON.
int CalibrateCommand(const TuneArgs& args) {
  std::vector<MatchOutcome> outcomes;
  if (!ReadOutcomes(args.calibrate_files, &outcomes)) return 2;
  if (!args.combo.empty()) {
    outcomes.erase(std::remove_if(outcomes.begin(), outcomes.end(),
                                  [&](const MatchOutcome& o) { return o.combo != args.combo; }),
                   outcomes.end());
  }
  const std::vector<AttemptSample> samples = SamplesOf(outcomes);
  if (samples.empty()) {
    std::cerr << "error: no judged pick or release attempts in " << outcomes.size()
              << " matches (tune.json files from this version of slamo tune record them"
              << (args.combo.empty() ? "" : "; --combo \"" + args.combo + "\" may match none")
              << ")\n";
    return 2;
  }
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::RobotConfig robot = field::LoadRobotConfig(args.robot);
  const Calibration calibration = Calibrate(samples, season.season, robot.name);
  std::cout << outcomes.size() << " matches, " << samples.size() << " attempts\n";
  PrintCalibration(calibration, samples, std::cout);
  const std::string path = args.calibration_out.empty()
                               ? "calibration-" + robot.name + "-" + season.season + ".json"
                               : args.calibration_out;
  if (!WriteText(path, ToJson(calibration).dump(2) + "\n")) return 1;
  std::cout << "wrote " << path << "\n";
  return 0;
}

}  // namespace

void RegisterTuneCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<TuneArgs>();
  std::string params_help = "name=v1,v2,... (repeatable); names:";
  for (const auto& [name, what] : TunableParams()) params_help += "\n  " + name + ": " + what;
  CLI::App* tune =
      app.add_subcommand("tune", "many seeded simulated matches per parameter combination, ranked");
  AddSeasonRobotOptions(tune, &args->season, &args->robot);
  tune->add_option("--matches", args->matches, "seeded matches per combination")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  tune->add_option("--seed-base", args->seed_base, "first seed")->capture_default_str();
  tune->add_option("--param", args->params, params_help);
  tune->add_option("--scenario", args->scenarios,
                   "nominal and/or disturbed (comma-separated or repeated): the object layouts "
                   "to run, as --param scenario=...")
      ->delimiter(',');
  tune->add_option("--calibration", args->calibration,
                   "pick and release success models from `slamo tune calibrate` for this "
                   "season and robot, for every match (default: the tolerance model)");
  tune->add_option("--jobs", args->jobs, "processes to run matches on")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  tune->add_option("--shard", args->shard,
                   "K/N: run every N-th match starting at the K-th (batch systems)");
  tune->add_option("--out", args->out, "directory for tune.csv and tune.json (or the shard file)")
      ->capture_default_str();
  CLI::App* merge =
      tune->add_subcommand("merge", "rank the outcomes of several --shard runs together");
  merge
      ->add_option("files", args->merge_files,
                   "shard files (DIR/shard-K-of-N.json) or tune.json files")
      ->required();
  merge->add_option("--out", args->out, "directory for tune.csv and tune.json")
      ->capture_default_str();
  CLI::App* calibrate = tune->add_subcommand(
      "calibrate",
      "fit pick and release success models to the attempts of tune runs, with a reliability "
      "table; e.g. slamo tune calibrate tune/tune.json --combo \"strategy=planner\"");
  calibrate->add_option("files", args->calibrate_files, "tune.json files or shards")->required();
  calibrate->add_option("--combo", args->combo,
                        "only the matches of this parameter combination (as tune.csv names it)");
  calibrate->add_option("--season", args->season, "the season the matches ran on (for the file)")
      ->capture_default_str();
  calibrate->add_option("--robot", args->robot, "the robot the matches ran with (for the file)")
      ->capture_default_str();
  calibrate->add_option("--out", args->calibration_out,
                        "the model file (default: calibration-ROBOT-SEASON.json)");
  tune->callback([args, action, merge, calibrate]() {
    if (calibrate->parsed()) {
      *action = [args]() { return CalibrateCommand(*args); };
    } else if (merge->parsed()) {
      *action = [args]() { return Merge(*args); };
    } else {
      *action = [args]() { return Tune(*args); };
    }
  });
}

}  // namespace slamo::autonomy
