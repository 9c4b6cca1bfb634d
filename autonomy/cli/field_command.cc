// `slamo field`: list the shipped seasons, check a season file, draw a field.
#include <iomanip>
#include <iostream>
#include <memory>

#include <opencv2/imgcodecs.hpp>

#include "autonomy/cli/commands.h"
#include "autonomy/reports/field_picture.h"
#include "field_configs/loader.h"
#include "field_configs/summary.h"

namespace slamo::autonomy {
namespace {

struct FieldArgs {
  std::string season = field::kDefaultSeason;
  std::string out = "field.png";
  double px_per_m = 200.0;
};

int List() {
  for (const std::string& name : field::ListSeasons()) {
    const field::SeasonConfig season = field::LoadSeasonConfig(name);
    std::cout << std::left << std::setw(18) << name << season.name << " (" << season.years
              << "), autonomous " << season.rules.autonomous_s << " s"
              << (name == field::kDefaultSeason ? "  [default]" : "") << "\n";
  }
  return 0;
}

int Check(const FieldArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  const field::SeasonSummary summary = field::Summarise(season);
  std::cout << season.source_file << ": OK\n"
            << season.name << " (" << season.years << "): " << season.structures.size()
            << " structures, " << season.landmarks.size() << " landmarks, " << season.goals.size()
            << " goals/zones, " << season.starts.size() << " starting tiles, "
            << season.opponents.size() << " opponent robots\n"
            << "autonomous " << season.rules.autonomous_s << " s of a " << season.rules.match_s
            << " s match, bonus " << season.rules.autonomous_bonus << "\n"
            << "objects (" << summary.total_objects << "):\n";
  for (const auto& [key, count] : summary.objects) {
    const field::ObjectType* type = season.FindObjectType(key.first);
    std::cout << "  " << std::setw(3) << count << " " << key.second << " " << key.first << " ("
              << field::ToString(type->shape) << ", " << type->size_m << " m, "
              << field::ToString(type->material) << ")\n";
  }
  std::cout
      << "points available in autonomous (every scorable object in its best goal + bonus): red "
      << summary.max_autonomous_points_red << ", blue " << summary.max_autonomous_points_blue
      << "\n";
  return 0;
}

int Show(const FieldArgs& args) {
  const field::SeasonConfig season = field::LoadSeasonConfig(args.season);
  FieldPictureOptions options;
  options.px_per_m = args.px_per_m;
  const cv::Mat picture = DrawFieldPicture(season, options);
  if (!cv::imwrite(args.out, picture)) {
    std::cerr << "error: could not write " << args.out << "\n";
    return 1;
  }
  std::cout << "wrote " << args.out << " (" << picture.cols << "x" << picture.rows << ", "
            << season.name << ")\n";
  return 0;
}

}  // namespace

void RegisterFieldCommand(CLI::App& app, CommandAction* action) {
  auto args = std::make_shared<FieldArgs>();
  CLI::App* field = app.add_subcommand(
      "field",
      "Season field configs: list, check, show.   e.g. slamo field show toss_up --out field.png");
  field->require_subcommand(1);

  CLI::App* list =
      field->add_subcommand("list", "List the shipped seasons.   e.g. slamo field list");
  list->callback([action] { *action = [] { return List(); }; });

  CLI::App* check = field->add_subcommand(
      "check",
      "Validate a season (name or file) and summarise it.   e.g. slamo field check my_field.yaml");
  check->add_option("season", args->season, "season name or path to a .yaml file")->required();
  check->callback([action, args] { *action = [args] { return Check(*args); }; });

  CLI::App* show = field->add_subcommand(
      "show",
      "Draw a season's field from above as a PNG.   e.g. slamo field show toss_up --out f.png");
  show->add_option("season", args->season, "season name or path to a .yaml file")->required();
  show->add_option("--out,-o", args->out, "PNG file to write")->capture_default_str();
  show->add_option("--px-per-m", args->px_per_m, "picture scale in pixels per metre")
      ->check(CLI::Range(50.0, 1000.0))
      ->capture_default_str();
  show->callback([action, args] { *action = [args] { return Show(*args); }; });
}

}  // namespace slamo::autonomy
