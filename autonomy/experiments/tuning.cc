#include "autonomy/experiments/tuning.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "autonomy/io/sim_io.h"
#include "autonomy/loop/executive.h"
#include "autonomy/reports/match_report.h"
#include "planning/planner.h"
#include "strategy/strategy.h"

namespace slamo::autonomy {
namespace {

double ToDouble(const std::string& name, const std::string& value) {
  try {
    size_t used = 0;
    const double v = std::stod(value, &used);
    if (used == value.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("--param " + name + ": expected a number, got \"" + value + "\"");
}

int ToInt(const std::string& name, const std::string& value) {
  const double v = ToDouble(name, value);
  if (v != std::floor(v))
    throw std::invalid_argument("--param " + name + ": expected a whole number, got \"" + value +
                                "\"");
  return static_cast<int>(v);
}

// A switch: "1" or "0".
bool ToFlag(const std::string& name, const std::string& value) {
  if (value != "0" && value != "1")
    throw std::invalid_argument("--param " + name + ": expected 0 or 1, got \"" + value + "\"");
  return value == "1";
}

// Set-up every match process would otherwise repeat for itself, the same whatever the match:
// done once before the first fork, and inherited. OpenCV builds its BGR-to-Lab tables on the
// first conversion (the detectors' colour classes): about 0.17 s of CPU, more than a whole
// scripted match. A one-pixel conversion runs on this thread (no worker threads to lose in
// the fork).
void WarmUpBeforeFork() {
  const cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar::all(0));
  cv::Mat converted;
  cv::cvtColor(pixel, converted, cv::COLOR_BGR2Lab);
}

}  // namespace

const std::map<std::string, std::string>& TunableParams() {
  static const std::map<std::string, std::string> params = {
      {"strategy", "planner | greedy | scripted | thesis"},
      {"frames", "frame rule: fixed:N | covariance | gmm"},
      {"speed", "driving speed, m/s (0: the robot's match_speed_mps)"},
      {"jitter", "object placement jitter, m"},
      {"scenario",
       "nominal: objects jittered up to `jitter`; disturbed: objects moved 0.3-0.8 m (the robot is "
       "told the season file either way)"},
      {"horizon", "planner: pick-and-score cycles searched ahead"},
      {"min_gain", "planner: expected points below which a cycle is not worth it"},
      {"duration_spread",
       "planner: a sequence's duration about its estimate, relative sd (0: it fits or not)"},
      {"look_frames", "frames of an exploratory look"},
      {"pick_tolerance", "lateral error the intake forgives, m"},
      {"approach_margin", "staging distance before the final approach, m"},
      {"pick_in_view",
       "1: stage picks where the camera sees the target whole and skip it when the look misses it; "
       "0: approach_margin only"},
      {"check_spacing",
       "m of path between quick looks while driving (0: none; default 2.4 with steer and "
       "moving_frames, 1.2 without)"},
      {"correction_frames", "frames of a quick look"},
      {"steer", "1: frames while driving re-aim a path leg under way from the estimate; 0: never"},
      {"moving_frames", "s between frames taken while driving straight (0: frames only at stops)"},
      {"arrival_fixes", "look-and-correct rounds on arrival"},
      {"arrival_slack", "error after an arrival's look left to the next action's own aim, m"},
      {"floor_push", "1: objects on the floor may be pushed into a zone that pays more; 0: never"},
      {"push_loss",
       "planner: 1 counts against a sequence what its first drive pushes out of our zones, and "
       "plans no second cycle on what that drive pushes on; 0: neither"},
      {"reverse_max",
       "path legs behind the robot up to this long (m) are driven backwards (0: never)"},
      {"corner_merge",
       "two path corners closer than this (m) become one where the legs meet (0: never)"},
      {"pushable", "objects narrower than this fraction of the robot are pushed, not avoided"},
      {"arrival_frames", "planner: frames to check an arrival"},
      {"observe_first", "planner: 1 weighs observing before a cycle (frames 5, 10, 20); 0 never"},
      {"look_charge",
       "planner: a look before a cycle is charged its seconds at this times the best rate "
       "without one (0: only what it pushes out of time)"},
      {"gyro", "1: a yaw gyro's heading into SLAM-O; 0: encoders and camera only"},
      {"adaptive", "1: the EKF's adaptive noise (NIS, sensor/motion checks, re-acquire); 0: off"},
      {"gyro_turns",
       "1: the drive controller turns and holds heading on the gyro (robots with an imu, gyro=1); "
       "0: on the encoders"},
      {"planner", "OMPL planner: rrtconnect | rrtstar | informedrrtstar | prmstar | bitstar"},
  };
  return params;
}

void ApplyParam(const std::string& name, const std::string& value, MatchSetup* setup) {
  if (name == "strategy") {
    strategy::MakeStrategy(value, setup->strategy_options);  // throws on an unknown name
    setup->strategy = value;
  } else if (name == "frames") {
    mapping::ParseFrameRule(value, &setup->frames);
  } else if (name == "speed") {
    setup->drive_speed_mps = ToDouble(name, value);
  } else if (name == "jitter") {
    setup->placement_jitter_m = ToDouble(name, value);
  } else if (name == "scenario") {
    try {
      setup->scenario = ParseScenario(value);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--param scenario: ") + e.what());
    }
  } else if (name == "horizon") {
    setup->strategy_options.horizon = ToInt(name, value);
  } else if (name == "min_gain") {
    setup->strategy_options.min_gain = ToDouble(name, value);
  } else if (name == "duration_spread") {
    setup->strategy_options.duration_spread = ToDouble(name, value);
  } else if (name == "look_frames") {
    setup->strategy_options.look_frames = ToInt(name, value);
  } else if (name == "pick_tolerance") {
    setup->strategy_options.pick_tolerance_m = ToDouble(name, value);
  } else if (name == "pick_in_view") {
    setup->strategy_options.pick_in_view = ToInt(name, value) != 0;
  } else if (name == "approach_margin") {
    setup->strategy_options.approach_margin_m = ToDouble(name, value);
  } else if (name == "check_spacing") {
    setup->check_spacing_m = ToDouble(name, value);
  } else if (name == "moving_frames") {
    setup->moving_frame_period_s = ToDouble(name, value);
  } else if (name == "steer") {
    setup->steer_on_estimate = ToFlag(name, value);
  } else if (name == "correction_frames") {
    setup->correction_frames = ToInt(name, value);
  } else if (name == "arrival_fixes") {
    setup->arrival_fixes = ToInt(name, value);
  } else if (name == "arrival_slack") {
    setup->arrival_slack_m = ToDouble(name, value);
  } else if (name == "floor_push") {
    setup->strategy_options.floor_pushes = ToFlag(name, value);
  } else if (name == "push_loss") {
    setup->strategy_options.count_push_loss = ToFlag(name, value);
  } else if (name == "reverse_max") {
    setup->reverse_max_m = ToDouble(name, value);
  } else if (name == "corner_merge") {
    setup->corner_merge_m = ToDouble(name, value);
  } else if (name == "pushable") {
    setup->pushable_fraction = ToDouble(name, value);
  } else if (name == "arrival_frames") {
    setup->strategy_options.arrival_frames = ToInt(name, value);
  } else if (name == "observe_first") {
    setup->strategy_options.frame_choices =
        ToFlag(name, value) ? std::vector<int>{0, 5, 10, 20} : std::vector<int>{0};
  } else if (name == "look_charge") {
    setup->strategy_options.look_charge = ToDouble(name, value);
  } else if (name == "gyro") {
    setup->gyro = ToFlag(name, value);
  } else if (name == "gyro_turns") {
    setup->gyro_turns = ToFlag(name, value);
  } else if (name == "adaptive") {
    setup->adaptive_filter = ToFlag(name, value);
  } else if (name == "planner") {
    const auto& names = planning::PlannerNames();
    if (std::find(names.begin(), names.end(), value) == names.end()) {
      throw std::invalid_argument("--param planner: unknown planner \"" + value + "\"");
    }
    setup->planner = value;
  } else {
    std::string known;
    for (const auto& [n, _] : TunableParams()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("--param: unknown parameter \"" + name + "\" (known: " + known +
                                ")");
  }
}

std::pair<std::string, std::vector<std::string>> ParseParam(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw std::invalid_argument("--param: expected name=v1,v2,..., got \"" + text + "\"");
  }
  std::pair<std::string, std::vector<std::string>> out{text.substr(0, eq), {}};
  std::stringstream values(text.substr(eq + 1));
  std::string v;
  while (std::getline(values, v, ',')) {
    if (v.empty()) throw std::invalid_argument("--param " + out.first + ": an empty value");
    out.second.push_back(v);
  }
  MatchSetup check;
  for (const std::string& value : out.second) ApplyParam(out.first, value, &check);
  return out;
}

std::vector<ParamSet> Combinations(const ParamGrid& grid) {
  std::vector<ParamSet> out = {{}};
  for (const auto& [name, values] : grid) {
    std::vector<ParamSet> next;
    for (const ParamSet& base : out) {
      for (const std::string& v : values) {
        ParamSet p = base;
        p.emplace_back(name, v);
        next.push_back(p);
      }
    }
    out = next;
  }
  return out;
}

std::string Describe(const ParamSet& params) {
  if (params.empty()) return "(defaults)";
  std::string out;
  for (const auto& [name, value] : params) out += (out.empty() ? "" : " ") + name + "=" + value;
  return out;
}

nlohmann::json ToJson(const MatchOutcome& o) {
  nlohmann::json records = nlohmann::json::array();
  for (const AttemptCheck& a : o.records) records.push_back(AttemptJson(a));
  return {{"combo", o.combo},
          {"seed", o.seed},
          {"points", o.points},
          {"points_start", o.points_start},
          {"overrun_s", o.overrun_s},
          {"refused", o.refused},
          {"pose_ate_m", o.pose_ate_m},
          {"nees_updates", o.nees_updates},
          {"nees_honest", o.nees_honest},
          {"attempts", o.attempts},
          {"attempts_inside", o.attempts_inside},
          {"records", records},
          {"duration_s", o.duration_s},
          {"wall_s", o.wall_s},
          {"failed", o.failed},
          {"error", o.error}};
}

MatchOutcome OutcomeFromJson(const nlohmann::json& j) {
  MatchOutcome o;
  o.combo = j.at("combo").get<std::string>();
  o.seed = j.at("seed").get<uint64_t>();
  o.points = j.at("points").get<int>();
  o.points_start = j.at("points_start").get<int>();
  o.overrun_s = j.at("overrun_s").get<double>();
  o.refused = j.at("refused").get<int>();
  o.pose_ate_m = j.at("pose_ate_m").get<double>();
  o.nees_updates = j.value("nees_updates", 0);
  o.nees_honest = j.value("nees_honest", 0);
  o.attempts = j.value("attempts", 0);
  o.attempts_inside = j.value("attempts_inside", 0);
  if (j.contains("records")) {
    for (const nlohmann::json& a : j.at("records")) o.records.push_back(AttemptFromJson(a));
  }
  o.duration_s = j.at("duration_s").get<double>();
  o.wall_s = j.at("wall_s").get<double>();
  o.failed = j.at("failed").get<bool>();
  o.error = j.value("error", "");
  return o;
}

std::vector<MatchOutcome> RunTasks(const field::SeasonConfig& season,
                                   const field::RobotConfig& robot,
                                   const std::vector<ParamSet>& combos,
                                   const std::vector<TuneTask>& tasks, int jobs,
                                   const std::function<void(size_t, size_t)>& progress,
                                   const MatchSetup& base) {
  std::vector<MatchOutcome> out(tasks.size());
  struct Child {
    pid_t pid;
    int fd;
    size_t task;
  };
  std::vector<Child> running;
  size_t next = 0, done = 0;
  WarmUpBeforeFork();
  const auto launch = [&](size_t t) {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("tune: cannot create a pipe");
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("tune: cannot fork");
    if (pid == 0) {
      // The match, alone in this process; its outcome goes back as one JSON line.
      close(fds[0]);
      MatchOutcome o;
      o.combo = Describe(combos[tasks[t].combo_index]);
      o.seed = tasks[t].seed;
      try {
        MatchSetup setup = base;
        setup.snapshot_period_s = 0.0;
        for (const auto& [name, value] : combos[tasks[t].combo_index])
          ApplyParam(name, value, &setup);
        const MatchResult r = RunMatch(season, robot, setup, tasks[t].seed);
        o.points = r.points;
        o.points_start = r.points_start;
        o.overrun_s = r.overrun_s;
        o.refused = r.refused;
        o.pose_ate_m = r.pose_ate_m;
        o.nees_updates = r.consistency.updates;
        o.nees_honest = r.consistency.in_band + r.consistency.below;
        o.attempts = static_cast<int>(r.attempts.size());
        for (const AttemptCheck& a : r.attempts) o.attempts_inside += a.Inside();
        o.records = r.attempts;
        o.duration_s = r.duration_s;
        o.wall_s = r.wall_s;
      } catch (const std::exception& e) {
        o.failed = true;
        o.error = e.what();
      }
      const std::string line = ToJson(o).dump() + "\n";
      size_t written = 0;
      while (written < line.size()) {
        const ssize_t n = write(fds[1], line.data() + written, line.size() - written);
        if (n <= 0) break;
        written += static_cast<size_t>(n);
      }
      close(fds[1]);
      _exit(0);
    }
    close(fds[1]);
    running.push_back({pid, fds[0], t});
  };
  while (done < tasks.size()) {
    while (static_cast<int>(running.size()) < std::max(1, jobs) && next < tasks.size())
      launch(next++);
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) throw std::runtime_error("tune: waitpid failed");
    const auto it = std::find_if(running.begin(), running.end(),
                                 [pid](const Child& c) { return c.pid == pid; });
    if (it == running.end()) continue;
    std::string text;
    char buffer[4096];
    for (ssize_t n; (n = read(it->fd, buffer, sizeof(buffer))) > 0;)
      text.append(buffer, static_cast<size_t>(n));
    close(it->fd);
    MatchOutcome o;
    try {
      o = OutcomeFromJson(nlohmann::json::parse(text));
    } catch (const std::exception&) {
      o.combo = Describe(combos[tasks[it->task].combo_index]);
      o.seed = tasks[it->task].seed;
      o.failed = true;
      o.error = WIFSIGNALED(status)
                    ? "the match process died of signal " + std::to_string(WTERMSIG(status))
                    : "the match process exited with status " + std::to_string(WEXITSTATUS(status));
    }
    out[it->task] = o;
    running.erase(it);
    ++done;
    if (progress) progress(done, tasks.size());
  }
  return out;
}

std::vector<ComboSummary> Summarise(const std::vector<MatchOutcome>& outcomes) {
  std::vector<std::string> order;
  std::map<std::string, std::vector<const MatchOutcome*>> by_combo;
  for (const MatchOutcome& o : outcomes) {
    if (!by_combo.count(o.combo)) order.push_back(o.combo);
    by_combo[o.combo].push_back(&o);
  }
  std::vector<ComboSummary> rows;
  for (const std::string& combo : order) {
    ComboSummary s;
    s.combo = combo;
    std::vector<double> points, gained;
    int updates = 0, honest = 0, attempts = 0, inside = 0;
    int pick_target = 0, pick_other = 0, pick_nothing = 0, scored = 0, knocked = 0;
    for (const MatchOutcome* o : by_combo[combo]) {
      if (o->failed) {
        ++s.failed;
        continue;
      }
      ++s.matches;
      points.push_back(o->points);
      gained.push_back(o->points - o->points_start);
      if (o->overrun_s > 0.0) ++s.overruns;
      s.mean_overrun_s += o->overrun_s;
      s.mean_ate_m += o->pose_ate_m;
      updates += o->nees_updates, honest += o->nees_honest;
      attempts += o->attempts, inside += o->attempts_inside;
      for (const AttemptCheck& a : o->records) {
        if (a.action == "PICK" && a.outcome == "skipped") {
          ++s.pick_skips;
        } else if (a.action == "PICK") {
          ++s.picks;
          pick_target += a.outcome == "target";
          pick_other += a.outcome == "other";
          pick_nothing += a.outcome == "nothing";
        } else if (a.action == "SCORE") {
          ++s.releases;
          scored += a.outcome == "scored";
        } else if (a.action == "KNOCK" || a.action == "PUSH") {
          ++s.knocks;
          knocked += a.outcome == "scored";
        }
      }
      s.mean_wall_s += o->wall_s;
    }
    const auto mean_ci = [](const std::vector<double>& v, double* mean, double* ci) {
      *mean = *ci = 0.0;
      if (v.empty()) return;
      for (double x : v) *mean += x;
      *mean /= v.size();
      if (v.size() < 2) return;
      double ss = 0.0;
      for (double x : v) ss += (x - *mean) * (x - *mean);
      *ci = 1.96 * std::sqrt(ss / (v.size() - 1)) / std::sqrt(static_cast<double>(v.size()));
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    s.nees_honest_fraction = updates ? static_cast<double>(honest) / updates : nan;
    s.attempts_inside_fraction = attempts ? static_cast<double>(inside) / attempts : nan;
    const auto fraction = [&](int n, int of) { return of ? static_cast<double>(n) / of : nan; };
    s.pick_target_fraction = fraction(pick_target, s.picks);
    s.pick_other_fraction = fraction(pick_other, s.picks);
    s.pick_nothing_fraction = fraction(pick_nothing, s.picks);
    s.release_scored_fraction = fraction(scored, s.releases);
    s.knock_scored_fraction = fraction(knocked, s.knocks);
    mean_ci(points, &s.mean_points, &s.ci95_points);
    mean_ci(gained, &s.mean_gained, &s.ci95_gained);
    if (s.matches > 0) {
      s.mean_overrun_s /= s.matches;
      s.mean_ate_m /= s.matches;
      s.mean_wall_s /= s.matches;
    }
    rows.push_back(s);
  }
  std::stable_sort(rows.begin(), rows.end(), [](const ComboSummary& a, const ComboSummary& b) {
    return a.mean_points > b.mean_points;
  });
  return rows;
}

std::string SummaryCsv(const std::vector<ComboSummary>& rows) {
  std::ostringstream out;
  out << "rank,combo,matches,failed,mean_points,ci95_points,mean_gained,ci95_gained,overruns,mean_"
         "overrun_s,"
         "mean_ate_m,nees_honest_fraction,attempts_inside_fraction,picks,pick_target_fraction,"
         "pick_other_fraction,pick_nothing_fraction,pick_skips,releases,release_scored_fraction,"
         "knocks,"
         "knock_scored_fraction,mean_wall_s\n";
  int rank = 0;
  for (const ComboSummary& r : rows) {
    out << ++rank << ",\"" << r.combo << "\"," << r.matches << ',' << r.failed << ','
        << r.mean_points << ',' << r.ci95_points << ',' << r.mean_gained << ',' << r.ci95_gained
        << ',' << r.overruns << ',' << r.mean_overrun_s << ',' << r.mean_ate_m << ','
        << r.nees_honest_fraction << ',' << r.attempts_inside_fraction << ',' << r.picks << ','
        << r.pick_target_fraction << ',' << r.pick_other_fraction << ',' << r.pick_nothing_fraction
        << ',' << r.pick_skips << ',' << r.releases << ',' << r.release_scored_fraction << ','
        << r.knocks << ',' << r.knock_scored_fraction << ',' << r.mean_wall_s << '\n';
  }
  return out.str();
}

nlohmann::json SummaryJson(const std::vector<ComboSummary>& rows,
                           const std::vector<MatchOutcome>& outcomes) {
  nlohmann::json j;
  j["ranking"] = nlohmann::json::array();
  for (const ComboSummary& r : rows) {
    j["ranking"].push_back({{"combo", r.combo},
                            {"matches", r.matches},
                            {"failed", r.failed},
                            {"mean_points", r.mean_points},
                            {"ci95_points", r.ci95_points},
                            {"mean_gained", r.mean_gained},
                            {"ci95_gained", r.ci95_gained},
                            {"overruns", r.overruns},
                            {"mean_overrun_s", r.mean_overrun_s},
                            {"mean_ate_m", r.mean_ate_m},
                            {"nees_honest_fraction", r.nees_honest_fraction},
                            {"attempts_inside_fraction", r.attempts_inside_fraction},
                            {"picks", r.picks},
                            {"pick_target_fraction", r.pick_target_fraction},
                            {"pick_other_fraction", r.pick_other_fraction},
                            {"pick_nothing_fraction", r.pick_nothing_fraction},
                            {"pick_skips", r.pick_skips},
                            {"knocks", r.knocks},
                            {"knock_scored_fraction", r.knock_scored_fraction},
                            {"releases", r.releases},
                            {"release_scored_fraction", r.release_scored_fraction},
                            {"mean_wall_s", r.mean_wall_s}});
  }
  j["matches"] = nlohmann::json::array();
  for (const MatchOutcome& o : outcomes) j["matches"].push_back(ToJson(o));
  return j;
}

void PrintSummaryTable(const std::vector<ComboSummary>& rows, std::ostream& out) {
  out << std::left << std::setw(5) << "rank" << std::setw(40) << "parameters" << std::right
      << std::setw(8) << "matches" << std::setw(18) << "points (95% CI)" << std::setw(18)
      << "gained (95% CI)" << std::setw(10) << "overruns" << std::setw(10) << "ATE m"
      << std::setw(10) << "NEES ok" << std::setw(10) << "in 3sig" << std::setw(7) << "picks"
      << std::setw(8) << "target" << std::setw(8) << "other" << std::setw(8) << "nothing"
      << std::setw(7) << "skips" << std::setw(7) << "rels" << std::setw(8) << "scored"
      << std::setw(8) << "knocks" << std::setw(8) << "down" << std::setw(10) << "wall s"
      << "\n";
  int rank = 0;
  for (const ComboSummary& r : rows) {
    std::ostringstream points, gained;
    points << std::fixed << std::setprecision(2) << r.mean_points << " +- " << r.ci95_points;
    gained << std::fixed << std::setprecision(2) << r.mean_gained << " +- " << r.ci95_gained;
    out << std::left << std::setw(5) << ++rank << std::setw(40) << r.combo << std::right
        << std::setw(8) << r.matches << std::setw(18) << points.str() << std::setw(18)
        << gained.str() << std::setw(10) << r.overruns << std::setw(10) << std::fixed
        << std::setprecision(3) << r.mean_ate_m << std::setw(10) << std::setprecision(3)
        << r.nees_honest_fraction << std::setw(10) << r.attempts_inside_fraction << std::setw(7)
        << r.picks << std::setprecision(2) << std::setw(8) << r.pick_target_fraction << std::setw(8)
        << r.pick_other_fraction << std::setw(8) << r.pick_nothing_fraction << std::setw(7)
        << r.pick_skips << std::setw(7) << r.releases << std::setw(8) << r.release_scored_fraction
        << std::setw(8) << r.knocks << std::setw(8) << r.knock_scored_fraction << std::setw(10)
        << r.mean_wall_s << "\n";
    if (r.failed) out << "     (" << r.failed << " matches failed: see tune.json)\n";
  }
}

std::string AttemptsCsv(const std::vector<MatchOutcome>& outcomes) {
  std::ostringstream out;
  out << "combo,seed,t_s,action,kind,colour,goal_index,range_m,bearing_deg,sigma_m,error_m,"
         "target_error_m,outcome,taken_kind,taken_colour\n";
  out << std::setprecision(6);
  for (const MatchOutcome& o : outcomes) {
    for (const AttemptCheck& a : o.records) {
      out << '"' << o.combo << "\"," << o.seed << ',' << a.t_s << ',' << a.action << ',' << a.kind
          << ',' << a.colour << ',' << a.goal_index << ',' << a.range_m << ','
          << a.bearing_rad * 180.0 / M_PI << ',' << a.three_sigma_m / 3.0 << ',' << a.error_m << ','
          << a.target_error_m << ',' << a.outcome << ',' << a.taken_kind << ',' << a.taken_colour
          << '\n';
    }
  }
  return out.str();
}

}  // namespace slamo::autonomy
