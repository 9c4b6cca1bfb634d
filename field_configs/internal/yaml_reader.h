// A validating view of a yaml-cpp node: typed reads whose failures throw ConfigError naming
// the file, line, column, key path and what was expected. Private to field_configs.
#pragma once

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "field_configs/season_config.h"

namespace slamo::field::internal {

class YamlReader {
 public:
  YamlReader(std::shared_ptr<const std::string> file, YAML::Node node, std::string path);

  // The root of a document; parse errors of yaml-cpp itself become ConfigError too.
  static YamlReader FromText(const std::string& text, const std::string& file);

  const std::string& path() const { return path_; }

  // Throws ConfigError at this node: "<file>:<line>:<col>: <path>: expected <what>, got <x>".
  [[noreturn]] void Fail(const std::string& expected) const;
  // Same, without the "got" part (for rules that span several keys).
  [[noreturn]] void FailRule(const std::string& message) const;

  // Maps.
  void ExpectMap() const;
  // Rejects any key not listed, suggesting the nearest allowed one.
  void AllowKeys(std::initializer_list<const char*> keys) const;
  bool Has(const std::string& key) const;
  YamlReader Required(const std::string& key) const;
  std::optional<YamlReader> Optional(const std::string& key) const;
  // The keys of a map, in file order, each with its value.
  std::vector<std::pair<std::string, YamlReader>> Entries() const;

  // Sequences.
  std::vector<YamlReader> Items() const;

  // Scalars.
  double Number() const;  // finite
  double Positive() const;
  double NonNegative() const;
  double InRange(double lo, double hi) const;
  int Int() const;
  int IntInRange(int lo, int hi) const;
  bool Bool() const;
  std::string String() const;  // non-empty
  // One of the listed words; returns its index.
  int OneOf(std::initializer_list<const char*> words) const;
  Vec2 Point() const;  // [x, y]
  std::vector<double> Numbers() const;

 private:
  std::string Got() const;

  std::shared_ptr<const std::string> file_;
  YAML::Node node_;
  std::string path_;
};

// Levenshtein distance, for "did you mean" suggestions.
int EditDistance(const std::string& a, const std::string& b);

}  // namespace slamo::field::internal
