#include "mapping/metrics.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace slamo::mapping {
namespace {

std::runtime_error FileError(const std::string& path, int line, const std::string& what) {
  return std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

// True, with the value, when the whole token is a finite number.
bool ParseFinite(const std::string& token, double* value) {
  if (token.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(token.c_str(), &end);
  if (end != token.c_str() + token.size() || errno == ERANGE || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

std::vector<std::string> Split(const std::string& line, char separator) {
  std::vector<std::string> fields;
  if (separator == ' ') {
    std::istringstream in(line);
    std::string token;
    while (in >> token) fields.push_back(token);
    return fields;
  }
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, separator)) {
    const auto first = field.find_first_not_of(" \t\r");
    const auto last = field.find_last_not_of(" \t\r");
    fields.push_back(first == std::string::npos ? "" : field.substr(first, last - first + 1));
  }
  return fields;
}

bool IsBlankOrComment(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

}  // namespace

Eigen::Vector2d Rigid2d::Apply(const Eigen::Vector2d& p) const {
  return Eigen::Rotation2Dd(theta_rad) * p + translation_m;
}

TimedPose Rigid2d::Apply(const TimedPose& pose) const {
  const Eigen::Vector2d p = Apply(Eigen::Vector2d(pose.x_m, pose.y_m));
  return {pose.t_s, p.x(), p.y(), std::remainder(pose.theta_rad + theta_rad, 2.0 * M_PI)};
}

void WriteTumTrajectory(const std::string& path, const std::vector<TimedPose>& poses,
                        const std::string& what) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out << "# " << (what.empty() ? "" : what + ": ") << "timestamp tx ty tz qx qy qz qw\n";
  char line[256];
  for (const TimedPose& p : poses) {
    std::snprintf(line, sizeof(line), "%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", p.t_s, p.x_m, p.y_m,
                  std::sin(0.5 * p.theta_rad), std::cos(0.5 * p.theta_rad));
    out << line;
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

std::vector<TimedPose> ReadTumTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<TimedPose> poses;
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    if (IsBlankOrComment(line)) continue;
    const std::vector<std::string> fields = Split(line, ' ');
    if (fields.size() != 8) {
      throw FileError(path, line_number,
                      "expected 8 fields `timestamp tx ty tz qx qy qz qw`, found " +
                          std::to_string(fields.size()));
    }
    double v[8];
    for (int i = 0; i < 8; ++i) {
      if (!ParseFinite(fields[i], &v[i])) {
        throw FileError(
            path, line_number,
            "field " + std::to_string(i + 1) + " `" + fields[i] + "` is not a finite number");
      }
    }
    const double qx = v[4], qy = v[5], qz = v[6], qw = v[7];
    if (std::abs(std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw) - 1.0) > 1e-3) {
      throw FileError(path, line_number, "quaternion is not of unit norm");
    }
    const double yaw = std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
    poses.push_back({v[0], v[1], v[2], yaw});
  }
  return poses;
}

std::vector<std::pair<int, int>> AssociateByTime(const std::vector<TimedPose>& truth,
                                                 const std::vector<TimedPose>& estimate,
                                                 double max_dt_s) {
  // Candidate pairs within the window, found through the estimate sorted by time.
  std::vector<int> order(estimate.size());
  for (size_t j = 0; j < order.size(); ++j) order[j] = static_cast<int>(j);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return estimate[a].t_s < estimate[b].t_s; });
  struct Candidate {
    double dt;
    int i, j;
  };
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < truth.size(); ++i) {
    const double t = truth[i].t_s;
    auto it = std::lower_bound(order.begin(), order.end(), t - max_dt_s,
                               [&](int j, double value) { return estimate[j].t_s < value; });
    for (; it != order.end() && estimate[*it].t_s < t + max_dt_s; ++it) {
      const double dt = std::abs(estimate[*it].t_s - t);
      if (dt < max_dt_s) candidates.push_back({dt, static_cast<int>(i), *it});
    }
  }
  // Greedy: closest first, each timestamp once.
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.dt < b.dt; });
  std::vector<bool> truth_used(truth.size(), false), estimate_used(estimate.size(), false);
  std::vector<std::pair<int, int>> pairs;
  for (const Candidate& c : candidates) {
    if (truth_used[c.i] || estimate_used[c.j]) continue;
    truth_used[c.i] = estimate_used[c.j] = true;
    pairs.emplace_back(c.i, c.j);
  }
  std::sort(pairs.begin(), pairs.end(),
            [&](const auto& a, const auto& b) { return truth[a.first].t_s < truth[b.first].t_s; });
  return pairs;
}

Rigid2d AlignRigid(const std::vector<Eigen::Vector2d>& from,
                   const std::vector<Eigen::Vector2d>& to) {
  if (from.empty() || from.size() != to.size()) {
    throw std::invalid_argument("AlignRigid: needs equally many points, at least one");
  }
  // Centroids, cross-covariance, and its SVD with the reflection removed (Umeyama 1991).
  Eigen::Vector2d from_mean = Eigen::Vector2d::Zero(), to_mean = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < from.size(); ++k) from_mean += from[k], to_mean += to[k];
  from_mean /= static_cast<double>(from.size());
  to_mean /= static_cast<double>(to.size());
  Eigen::Matrix2d sigma = Eigen::Matrix2d::Zero();
  for (size_t k = 0; k < from.size(); ++k) {
    sigma += (to[k] - to_mean) * (from[k] - from_mean).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix2d s = Eigen::Matrix2d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s(1, 1) = -1.0;
  const Eigen::Matrix2d r = svd.matrixU() * s * svd.matrixV().transpose();
  Rigid2d result;
  result.theta_rad = std::atan2(r(1, 0), r(0, 0));
  result.translation_m = to_mean - Eigen::Rotation2Dd(result.theta_rad) * from_mean;
  return result;
}

AteResult PairedTrajectoryError(const std::vector<Eigen::Vector2d>& truth,
                                const std::vector<Eigen::Vector2d>& estimate, bool align) {
  if (truth.empty() || truth.size() != estimate.size()) {
    throw std::invalid_argument("trajectory error: " + std::to_string(truth.size()) + " true and " +
                                std::to_string(estimate.size()) +
                                " estimated positions; expected as many of each, at least one");
  }
  AteResult result;
  if (align) result.alignment = AlignRigid(estimate, truth);
  std::vector<double> errors;
  double sum = 0.0, sum_sq = 0.0;
  for (size_t k = 0; k < estimate.size(); ++k) {
    const double e2 = (result.alignment.Apply(estimate[k]) - truth[k]).squaredNorm();
    const double e = std::sqrt(e2);
    errors.push_back(e);
    sum += e;
    sum_sq += e2;
    result.max_m = std::max(result.max_m, e);
  }
  const double n = static_cast<double>(errors.size());
  result.pairs = static_cast<int>(errors.size());
  result.rmse_m = std::sqrt(sum_sq / n);
  result.mean_m = sum / n;
  std::sort(errors.begin(), errors.end());
  const size_t mid = errors.size() / 2;
  result.median_m = errors.size() % 2 ? errors[mid] : 0.5 * (errors[mid - 1] + errors[mid]);
  return result;
}

AteResult AbsoluteTrajectoryError(const std::vector<TimedPose>& truth,
                                  const std::vector<TimedPose>& estimate, double max_dt_s,
                                  bool align) {
  const std::vector<std::pair<int, int>> pairs = AssociateByTime(truth, estimate, max_dt_s);
  if (pairs.empty()) {
    throw std::invalid_argument("ATE: no estimated pose within " + std::to_string(max_dt_s) +
                                " s of a truth pose; are both trajectories on the same clock?");
  }
  std::vector<Eigen::Vector2d> from, to;
  for (const auto& [i, j] : pairs) {
    to.emplace_back(truth[i].x_m, truth[i].y_m);
    from.emplace_back(estimate[j].x_m, estimate[j].y_m);
  }
  return PairedTrajectoryError(to, from, align);
}

LandmarkError LandmarkRmse(const std::vector<LandmarkPoint>& truth,
                           const std::vector<LandmarkPoint>& estimate, const Rigid2d& alignment) {
  std::vector<bool> matched(truth.size(), false);
  double sum_sq = 0.0;
  LandmarkError result;
  auto add = [&](size_t i, const Eigen::Vector2d& p) {
    matched[i] = true;
    sum_sq += (p - Eigen::Vector2d(truth[i].x_m, truth[i].y_m)).squaredNorm();
    ++result.pairs;
  };
  // By id first, then the id-less estimates to the nearest free truth landmark.
  std::vector<Eigen::Vector2d> unnamed;
  for (const LandmarkPoint& e : estimate) {
    const Eigen::Vector2d p = alignment.Apply(Eigen::Vector2d(e.x_m, e.y_m));
    if (e.id < 0) {
      unnamed.push_back(p);
      continue;
    }
    for (size_t i = 0; i < truth.size(); ++i) {
      if (truth[i].id == e.id && !matched[i]) {
        add(i, p);
        break;
      }
    }
  }
  for (const Eigen::Vector2d& p : unnamed) {
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < truth.size(); ++i) {
      const double d2 = (p - Eigen::Vector2d(truth[i].x_m, truth[i].y_m)).squaredNorm();
      if (!matched[i] && d2 < best_d2) best_d2 = d2, best = static_cast<int>(i);
    }
    if (best >= 0) add(best, p);
  }
  if (result.pairs == 0) throw std::invalid_argument("landmark RMSE: no landmark matches");
  result.rmse_m = std::sqrt(sum_sq / result.pairs);
  result.missing = static_cast<int>(std::count(matched.begin(), matched.end(), false));
  return result;
}

std::vector<LandmarkPoint> ReadLandmarkCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<LandmarkPoint> landmarks;
  std::string line;
  bool first = true;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    if (IsBlankOrComment(line)) continue;
    const std::vector<std::string> fields = Split(line, ',');
    double v[3];
    bool numeric = fields.size() >= 3;
    for (int i = 0; numeric && i < 3; ++i) numeric = ParseFinite(fields[i], &v[i]);
    if (first && !numeric) {  // the header
      first = false;
      continue;
    }
    first = false;
    if (fields.size() < 3) {
      throw FileError(path, line_number,
                      "expected `id,x_m,y_m`, found " + std::to_string(fields.size()) + " fields");
    }
    if (!numeric) throw FileError(path, line_number, "id, x_m and y_m must be finite numbers");
    if (v[0] != std::floor(v[0]) || v[0] < -1) {
      throw FileError(path, line_number, "id `" + fields[0] + "` is not an integer >= -1");
    }
    landmarks.push_back({static_cast<int>(v[0]), v[1], v[2]});
  }
  return landmarks;
}

namespace {

// The numeric rows of a whitespace-separated file, `%` lines skipped; each row has at least
// `min_fields` finite numbers (errors name the file and the line). Calls `row` with the
// 1-based line number and the numbers.
template <typename RowFn>
void ReadNumericRows(const std::string& path, size_t min_fields, const char* expected, RowFn row) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '%') continue;
    const std::vector<std::string> fields = Split(line, ' ');
    if (fields.size() < min_fields) {
      throw FileError(path, line_number,
                      std::string("expected `") + expected + "`, found " +
                          std::to_string(fields.size()) + " fields");
    }
    std::vector<double> v(fields.size());
    for (size_t i = 0; i < fields.size(); ++i) {
      if (!ParseFinite(fields[i], &v[i])) {
        throw FileError(
            path, line_number,
            "field " + std::to_string(i + 1) + " `" + fields[i] + "` is not a finite number");
      }
    }
    row(line_number, v);
  }
}

}  // namespace

std::vector<SimulLandmarksPose> ReadSimulLandmarksPath(const std::string& path) {
  std::vector<SimulLandmarksPose> poses;
  ReadNumericRows(path, 4, "x y z yaw pitch roll", [&](int, const std::vector<double>& v) {
    poses.push_back({v[0], v[1], v[3]});
  });
  return poses;
}

std::vector<LandmarkPoint> ReadSimulLandmarksMap(const std::string& path) {
  std::vector<LandmarkPoint> landmarks;
  ReadNumericRows(path, 7, "x y z a b c id", [&](int line_number, const std::vector<double>& v) {
    if (v[6] != std::floor(v[6]) || v[6] < 0 || v[6] > std::numeric_limits<int>::max()) {
      throw FileError(path, line_number, "the id (field 7) is not an integer >= 0");
    }
    landmarks.push_back({static_cast<int>(v[6]), v[0], v[1]});
  });
  return landmarks;
}

TruthFormat DetectTruthFormat(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (line[first] == '%') return TruthFormat::kSimulLandmarksPath;
    if (line[first] == '#' || line.find(',') != std::string::npos) return TruthFormat::kTumOrCsv;
    const std::vector<std::string> fields = Split(line, ' ');
    double v;
    const bool numeric = std::all_of(fields.begin(), fields.end(),
                                     [&](const std::string& f) { return ParseFinite(f, &v); });
    return numeric && fields.size() == 7 ? TruthFormat::kSimulLandmarksMap : TruthFormat::kTumOrCsv;
  }
  return TruthFormat::kTumOrCsv;
}

}  // namespace slamo::mapping
