// Planning benchmark: for every shipped season (walls and structures, no game objects) and
// every planner, 100 random valid queries with a fixed seed; the median solve time and the
// path length against the reference shortest path (planning/reference_path.h) on the same
// inflated grid. One benchmark run per season and planner; the numbers are its counters:
//   median_ms, p90_ms     time of Plan(), milliseconds (the budget bounds it)
//   median_ratio, mean_ratio, p90_ratio, min_ratio, max_ratio   path length / reference length
//   solved                fraction of the queries solved exactly within the budget
//   detours               queries whose straight line is blocked (the others are easy)
//   detour_median_ratio, detour_p90_ratio   the ratios over those queries only
// rrtconnect as shipped runs PlannerOptions::rrtconnect_attempts times and shortens each
// path (Planner::Shorten()); "rrtconnect_x1" is one attempt, shortened; "rrtconnect_raw" one
// attempt, not shortened (OMPL's simplification only): they measure what each step buys.
// Budgets: 0.05 s for rrtconnect, 0.1 s for the asymptotically optimal planners (which use
// all of it). Run: <build dir>/bin/planning_benchmark (about 6 minutes).
#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "field_configs/loader.h"
#include "mapping/object_map.h"
#include "planning/planner.h"
#include "planning/reference_path.h"

namespace slamo::planning {
namespace {

constexpr int kQueries = 100;
constexpr std::uint64_t kSeed = 20240601;
constexpr double kMinDistanceM = 0.3;  // queries shorter than this are left out

struct Query {
  Eigen::Vector2d start, goal;
  double reference_m = 0.0;
  bool straight = false;  // the straight line is clear
};

struct Field {
  std::unique_ptr<field::SeasonConfig> season;
  std::unique_ptr<Planner> planner;
  std::unique_ptr<Planner> raw_planner;  // one attempt, no Shorten()
  std::unique_ptr<Planner> x1_planner;   // one attempt, Shorten()
  std::vector<Query> queries;
};

// The season's field and its queries, built once.
Field& GetField(const std::string& name) {
  static std::map<std::string, Field> fields;
  auto it = fields.find(name);
  if (it != fields.end()) return it->second;
  Field field;
  field.season = std::make_unique<field::SeasonConfig>(field::LoadSeasonConfig(name));
  const field::RobotConfig robot = field::LoadRobotConfig(field::kDefaultRobot);
  mapping::ObjectMapOptions map_options;
  map_options.resolution_m = 0.02;
  const mapping::ObjectMap map(*field.season, map_options);
  field.planner = std::make_unique<Planner>(robot);
  field.planner->SetMap(map);
  PlannerOptions x1;
  x1.rrtconnect_attempts = 1;
  field.x1_planner = std::make_unique<Planner>(robot, x1);
  field.x1_planner->SetMap(map);
  PlannerOptions raw = x1;
  raw.shorten = false;
  field.raw_planner = std::make_unique<Planner>(robot, raw);
  field.raw_planner->SetMap(map);

  std::mt19937_64 rng(kSeed);
  const double half_m = field.season->HalfSize();
  std::uniform_real_distribution<double> coordinate(-half_m, half_m);
  while (static_cast<int>(field.queries.size()) < kQueries) {
    Query q;
    q.start = {coordinate(rng), coordinate(rng)};
    q.goal = {coordinate(rng), coordinate(rng)};
    if ((q.goal - q.start).norm() < kMinDistanceM) continue;
    if (!field.planner->IsClear(q.start) || !field.planner->IsClear(q.goal)) continue;
    const auto reference = ReferencePath(*field.planner, q.start, q.goal);
    if (!reference) continue;  // different free regions
    q.reference_m = PathLength(*reference);
    q.straight = field.planner->SegmentIsClear(q.start, q.goal);
    field.queries.push_back(q);
  }
  return fields.emplace(name, std::move(field)).first->second;
}

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * (values.size() - 1) + 0.5));
  return values[k];
}

void BM_Plan(benchmark::State& state, const std::string& season, const std::string& variant) {
  Field& field = GetField(season);
  const bool raw = variant == "rrtconnect_raw", x1 = variant == "rrtconnect_x1";
  const std::string planner_name = raw || x1 ? "rrtconnect" : variant;
  const Planner& planner = raw ? *field.raw_planner : x1 ? *field.x1_planner : *field.planner;
  std::vector<double> times_ms, ratios, detour_ratios;
  int solved = 0;
  for (auto _ : state) {
    times_ms.clear();
    ratios.clear();
    detour_ratios.clear();
    solved = 0;
    for (const Query& q : field.queries) {
      PlanRequest request;
      request.start_x_m = q.start.x();
      request.start_y_m = q.start.y();
      request.goal_x_m = q.goal.x();
      request.goal_y_m = q.goal.y();
      request.planner = planner_name;
      request.time_budget_s = planner_name == "rrtconnect" ? 0.05 : 0.1;
      const auto begin = std::chrono::steady_clock::now();
      const PlanResult result = planner.Plan(request);
      times_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin)
              .count());
      benchmark::DoNotOptimize(result.length_m);
      if (result.status != PlanStatus::kSolved) continue;
      ++solved;
      ratios.push_back(result.length_m / q.reference_m);
      if (!q.straight) detour_ratios.push_back(ratios.back());
    }
  }
  state.counters["median_ms"] = Quantile(times_ms, 0.5);
  state.counters["p90_ms"] = Quantile(times_ms, 0.9);
  state.counters["median_ratio"] = Quantile(ratios, 0.5);
  state.counters["mean_ratio"] =
      ratios.empty() ? 0.0 : std::accumulate(ratios.begin(), ratios.end(), 0.0) / ratios.size();
  state.counters["p90_ratio"] = Quantile(ratios, 0.9);
  state.counters["max_ratio"] = Quantile(ratios, 1.0);
  state.counters["min_ratio"] = Quantile(ratios, 0.0);
  state.counters["solved"] = static_cast<double>(solved) / field.queries.size();
  state.counters["detours"] = static_cast<double>(std::count_if(
      field.queries.begin(), field.queries.end(), [](const Query& q) { return !q.straight; }));
  state.counters["detour_median_ratio"] = Quantile(detour_ratios, 0.5);
  state.counters["detour_p90_ratio"] = Quantile(detour_ratios, 0.9);
}

// Time of one reference path (Theta* and shortening), for the record.
void BM_ReferencePath(benchmark::State& state, const std::string& season) {
  Field& field = GetField(season);
  size_t i = 0;
  for (auto _ : state) {
    const Query& q = field.queries[i++ % field.queries.size()];
    benchmark::DoNotOptimize(ReferencePath(*field.planner, q.start, q.goal));
  }
}

}  // namespace
}  // namespace slamo::planning

int main(int argc, char** argv) {
  using namespace slamo;
  planning::SeedPlanners(1);
  const std::vector<std::string> variants = {"rrtconnect", "rrtconnect_x1",   "rrtconnect_raw",
                                             "rrtstar",    "informedrrtstar", "prmstar",
                                             "bitstar"};
  for (const std::string& season : field::ListSeasons()) {
    for (const std::string& variant : variants) {
      benchmark::RegisterBenchmark(("BM_Plan/" + season + "/" + variant).c_str(), planning::BM_Plan,
                                   season, variant)
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond);
    }
    benchmark::RegisterBenchmark(("BM_ReferencePath/" + season).c_str(), planning::BM_ReferencePath,
                                 season)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
