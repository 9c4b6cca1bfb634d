// Facts a team checks first about a season file: objects by type and colour, and the points
// each alliance could earn in the autonomous period.
#pragma once

#include <map>
#include <string>
#include <utility>

#include "field_configs/season_config.h"

namespace slamo::field {

struct SeasonSummary {
  std::map<std::pair<std::string, std::string>, int> objects;  // (type, colour) -> count
  int total_objects = 0;
  // Per alliance: every object that can score for it placed in its best goal, plus the
  // autonomous bonus. An upper bound, not a plan.
  int max_autonomous_points_red = 0;
  int max_autonomous_points_blue = 0;
};

SeasonSummary Summarise(const SeasonConfig& season);

// Whether an object of `colour` can score for `alliance` at all: with own-colour scoring a red
// object scores only for red and a blue one only for blue; other colours score for either.
bool ScoresFor(const SeasonConfig& season, const std::string& colour, Alliance alliance);

// The most points one object of `type` and `colour` can earn for `alliance`; 0 if none.
int BestPoints(const SeasonConfig& season, const std::string& type, const std::string& colour,
               Alliance alliance);

}  // namespace slamo::field
