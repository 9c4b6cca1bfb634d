#include "field_configs/internal/yaml_reader.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "field_configs/config_error.h"

namespace slamo::field::internal {
namespace {

std::string JoinPath(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

}  // namespace

int EditDistance(const std::string& a, const std::string& b) {
  std::vector<int> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      const int above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

YamlReader::YamlReader(std::shared_ptr<const std::string> file, YAML::Node node, std::string path)
    : file_(std::move(file)), node_(std::move(node)), path_(std::move(path)) {}

YamlReader YamlReader::FromText(const std::string& text, const std::string& file) {
  auto file_name = std::make_shared<const std::string>(file);
  try {
    YAML::Node root = YAML::Load(text);
    return YamlReader(file_name, root, "");
  } catch (const YAML::Exception& e) {
    throw ConfigError(file, e.mark.line + 1, e.mark.column + 1, "(document)",
                      "valid YAML (" + e.msg + ")");
  }
}

std::string YamlReader::Got() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsScalar()) return "'" + node_.Scalar() + "'";
  if (node_.IsSequence()) {
    std::ostringstream out;
    out << "[";
    for (size_t i = 0; i < node_.size(); ++i) {
      const YAML::Node item = node_[i];
      out << (i ? ", " : "") << (item.IsScalar() ? item.Scalar() : "...");
    }
    out << "]";
    return out.str();
  }
  return "a map";
}

void YamlReader::Fail(const std::string& expected) const {
  FailRule("expected " + expected + ", got " + Got());
}

void YamlReader::FailRule(const std::string& message) const {
  const YAML::Mark mark = node_.Mark();
  const bool known = mark.line >= 0;
  throw ConfigError(*file_, known ? mark.line + 1 : 0, known ? mark.column + 1 : 0,
                    path_.empty() ? "(document)" : path_, message);
}

void YamlReader::ExpectMap() const {
  if (!node_.IsMap()) Fail("a map of keys");
}

void YamlReader::AllowKeys(std::initializer_list<const char*> keys) const {
  ExpectMap();
  for (const auto& entry : node_) {
    const std::string key = entry.first.as<std::string>();
    const bool allowed =
        std::any_of(keys.begin(), keys.end(), [&](const char* k) { return key == k; });
    if (allowed) continue;
    std::string best;
    int best_distance = 3;
    for (const char* k : keys) {
      const int d = EditDistance(key, k);
      if (d < best_distance) best_distance = d, best = k;
    }
    std::string expected = "one of the keys {";
    for (const char* k : keys) expected += std::string(k) + (k == *(keys.end() - 1) ? "" : ", ");
    expected += "}";
    if (!best.empty()) expected = "a known key (did you mean '" + best + "'?); " + expected;
    YamlReader(file_, entry.first, JoinPath(path_, key))
        .FailRule("unknown key: expected " + expected);
  }
}

bool YamlReader::Has(const std::string& key) const {
  ExpectMap();
  return static_cast<bool>(node_[key]);
}

YamlReader YamlReader::Required(const std::string& key) const {
  ExpectMap();
  const YAML::Node child = node_[key];
  if (!child) FailRule("missing required key '" + key + "'");
  return YamlReader(file_, child, JoinPath(path_, key));
}

std::optional<YamlReader> YamlReader::Optional(const std::string& key) const {
  ExpectMap();
  const YAML::Node child = node_[key];
  if (!child) return std::nullopt;
  return YamlReader(file_, child, JoinPath(path_, key));
}

std::vector<std::pair<std::string, YamlReader>> YamlReader::Entries() const {
  ExpectMap();
  std::vector<std::pair<std::string, YamlReader>> out;
  for (const auto& entry : node_) {
    const std::string key = entry.first.as<std::string>();
    out.emplace_back(key, YamlReader(file_, entry.second, JoinPath(path_, key)));
  }
  return out;
}

std::vector<YamlReader> YamlReader::Items() const {
  if (!node_.IsSequence()) Fail("a list");
  std::vector<YamlReader> out;
  for (size_t i = 0; i < node_.size(); ++i) {
    out.emplace_back(file_, node_[i], path_ + "[" + std::to_string(i) + "]");
  }
  return out;
}

double YamlReader::Number() const {
  if (!node_.IsScalar()) Fail("a number");
  double value = 0.0;
  try {
    value = node_.as<double>();
  } catch (const YAML::Exception&) {
    Fail("a number");
  }
  if (!std::isfinite(value)) Fail("a finite number");
  return value;
}

double YamlReader::Positive() const {
  const double value = Number();
  if (value <= 0.0) Fail("a positive number");
  return value;
}

double YamlReader::NonNegative() const {
  const double value = Number();
  if (value < 0.0) Fail("a number >= 0");
  return value;
}

double YamlReader::InRange(double lo, double hi) const {
  const double value = Number();
  if (value < lo || value > hi) {
    std::ostringstream out;
    out << "a number in [" << lo << ", " << hi << "]";
    Fail(out.str());
  }
  return value;
}

int YamlReader::Int() const {
  if (!node_.IsScalar()) Fail("an integer");
  try {
    return node_.as<int>();
  } catch (const YAML::Exception&) {
    Fail("an integer");
  }
}

int YamlReader::IntInRange(int lo, int hi) const {
  const int value = Int();
  if (value < lo || value > hi) {
    Fail("an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return value;
}

bool YamlReader::Bool() const {
  if (!node_.IsScalar()) Fail("true or false");
  try {
    return node_.as<bool>();
  } catch (const YAML::Exception&) {
    Fail("true or false");
  }
}

std::string YamlReader::String() const {
  if (!node_.IsScalar() || node_.Scalar().empty()) Fail("a non-empty string");
  return node_.Scalar();
}

int YamlReader::OneOf(std::initializer_list<const char*> words) const {
  std::string expected = "one of {";
  int index = 0;
  for (const char* w : words) expected += std::string(index++ ? ", " : "") + w;
  expected += "}";
  if (!node_.IsScalar()) Fail(expected);
  index = 0;
  for (const char* w : words) {
    if (node_.Scalar() == w) return index;
    ++index;
  }
  Fail(expected);
}

Vec2 YamlReader::Point() const {
  if (!node_.IsSequence() || node_.size() != 2) Fail("a point [x, y] in metres");
  const std::vector<double> xy = Numbers();
  return Vec2{xy[0], xy[1]};
}

std::vector<double> YamlReader::Numbers() const {
  std::vector<double> out;
  for (const YamlReader& item : Items()) out.push_back(item.Number());
  return out;
}

}  // namespace slamo::field::internal
