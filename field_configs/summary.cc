#include "field_configs/summary.h"

#include <algorithm>

namespace slamo::field {

bool ScoresFor(const SeasonConfig& season, const std::string& colour, Alliance alliance) {
  if (!season.rules.own_colour_only) return true;
  if (colour == "red") return alliance == Alliance::kRed;
  if (colour == "blue") return alliance == Alliance::kBlue;
  return true;
}

int BestPoints(const SeasonConfig& season, const std::string& type, const std::string& colour,
               Alliance alliance) {
  if (!ScoresFor(season, colour, alliance)) return 0;
  int best = 0;
  for (const Goal& goal : season.goals) {
    if (goal.alliance != Alliance::kNone && goal.alliance != alliance) continue;
    const auto it = goal.points.find(type);
    if (it != goal.points.end()) best = std::max(best, it->second);
  }
  return best;
}

SeasonSummary Summarise(const SeasonConfig& season) {
  SeasonSummary summary;
  for (const ObjectPlacement& p : season.objects) {
    summary.objects[{p.type, p.colour}] += p.count;
    summary.total_objects += p.count;
    summary.max_autonomous_points_red +=
        p.count * BestPoints(season, p.type, p.colour, Alliance::kRed);
    summary.max_autonomous_points_blue +=
        p.count * BestPoints(season, p.type, p.colour, Alliance::kBlue);
  }
  summary.max_autonomous_points_red += season.rules.autonomous_bonus;
  summary.max_autonomous_points_blue += season.rules.autonomous_bonus;
  return summary;
}

}  // namespace slamo::field
