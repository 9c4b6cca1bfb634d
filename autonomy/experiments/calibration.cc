#include "autonomy/experiments/calibration.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

namespace slamo::autonomy {
namespace {

Eigen::Vector4d Features(double range_m, double bearing_rad, double sigma_m) {
  return Eigen::Vector4d(1.0, range_m, std::abs(bearing_rad), sigma_m);
}

double Logistic(double z) { return 1.0 / (1.0 + std::exp(-z)); }

// Models fitted on `samples` for every (action, kind) with enough attempts, and per action
// over every kind.
std::vector<SuccessModel> FitAll(const std::vector<AttemptSample>& samples) {
  std::set<std::pair<std::string, std::string>> keys;
  std::map<std::string, int> per_action;
  std::map<std::pair<std::string, std::string>, int> per_kind;
  for (const AttemptSample& s : samples) ++per_action[s.action], ++per_kind[{s.action, s.kind}];
  std::vector<SuccessModel> out;
  for (const auto& [action, n] : per_action) {
    if (n >= kMinSamples) out.push_back(FitSuccessModel(samples, action, ""));
  }
  for (const auto& [key, n] : per_kind) {
    if (n >= kMinSamples) out.push_back(FitSuccessModel(samples, key.first, key.second));
  }
  return out;
}

const SuccessModel* FindIn(const std::vector<SuccessModel>& models, const std::string& action,
                           const std::string& kind) {
  const SuccessModel* any = nullptr;
  for (const SuccessModel& m : models) {
    if (m.action != action) continue;
    if (m.kind == kind) return &m;
    if (m.kind.empty()) any = &m;
  }
  return any;
}

}  // namespace

double SuccessModel::Predict(double range_m, double bearing_rad, double sigma_m) const {
  const Eigen::Vector4d x = Features(range_m, bearing_rad, sigma_m);
  return Logistic(x.dot(Eigen::Vector4d(weights[0], weights[1], weights[2], weights[3])));
}

std::vector<AttemptSample> SamplesOf(const std::vector<MatchOutcome>& outcomes) {
  std::vector<AttemptSample> out;
  for (const MatchOutcome& o : outcomes) {
    if (o.failed) continue;
    for (const AttemptCheck& a : o.records) {
      if (a.outcome.empty()) continue;       // not judged (no truth)
      if (a.outcome == "skipped") continue;  // given up before the approach: no attempt
      AttemptSample s;
      s.action = a.action;
      s.kind = a.kind;
      s.range_m = a.range_m;
      s.bearing_rad = a.bearing_rad;
      s.sigma_m = a.three_sigma_m / 3.0;
      s.success = a.action == "PICK" ? a.outcome == "target" : a.outcome == "scored";
      s.seed = o.seed;
      out.push_back(s);
    }
  }
  return out;
}

SuccessModel FitSuccessModel(const std::vector<AttemptSample>& samples, const std::string& action,
                             const std::string& kind) {
  SuccessModel m;
  m.action = action;
  m.kind = kind;
  std::vector<const AttemptSample*> use;
  for (const AttemptSample& s : samples) {
    if (s.action == action && (kind.empty() || s.kind == kind)) use.push_back(&s);
  }
  m.samples = static_cast<int>(use.size());
  for (const AttemptSample* s : use) m.successes += s->success;
  if (use.empty()) return m;
  // Start from the base rate (smoothed), slopes zero.
  const double rate = (m.successes + 0.5) / (m.samples + 1.0);
  Eigen::Vector4d w(std::log(rate / (1.0 - rate)), 0.0, 0.0, 0.0);
  const double ridge = 1e-2;  // on the slopes only
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::Vector4d gradient = Eigen::Vector4d::Zero();
    Eigen::Matrix4d hessian = Eigen::Matrix4d::Zero();
    for (const AttemptSample* s : use) {
      const Eigen::Vector4d x = Features(s->range_m, s->bearing_rad, s->sigma_m);
      const double p = Logistic(x.dot(w));
      gradient += (p - (s->success ? 1.0 : 0.0)) * x;
      hessian += std::max(p * (1.0 - p), 1e-9) * x * x.transpose();
    }
    for (int k = 1; k < 4; ++k) gradient(k) += ridge * w(k), hessian(k, k) += ridge;
    const Eigen::Vector4d step = hessian.ldlt().solve(gradient);
    w -= step;
    if (step.norm() < 1e-9) break;
  }
  for (int k = 0; k < 4; ++k) m.weights[k] = w(k);
  return m;
}

const SuccessModel* Calibration::Find(const std::string& action, const std::string& kind) const {
  return FindIn(models, action, kind);
}

Calibration Calibrate(const std::vector<AttemptSample>& samples, const std::string& season,
                      const std::string& robot) {
  Calibration c;
  c.season = season;
  c.robot = robot;
  c.models = FitAll(samples);
  return c;
}

nlohmann::json ToJson(const Calibration& c) {
  nlohmann::json j;
  j["season"] = c.season;
  j["robot"] = c.robot;
  j["model"] = "P = 1 / (1 + exp(-(w0 + w1 range_m + w2 |bearing_rad| + w3 sigma_m)))";
  j["models"] = nlohmann::json::array();
  for (const SuccessModel& m : c.models) {
    j["models"].push_back({{"action", m.action},
                           {"kind", m.kind},
                           {"weights", {m.weights[0], m.weights[1], m.weights[2], m.weights[3]}},
                           {"samples", m.samples},
                           {"successes", m.successes}});
  }
  return j;
}

Calibration CalibrationFromJson(const nlohmann::json& j) {
  Calibration c;
  try {
    c.season = j.at("season").get<std::string>();
    c.robot = j.at("robot").get<std::string>();
    for (const nlohmann::json& m : j.at("models")) {
      SuccessModel s;
      s.action = m.at("action").get<std::string>();
      if (s.action != "PICK" && s.action != "SCORE")
        throw std::invalid_argument("models[].action: expected PICK or SCORE, got " + s.action);
      s.kind = m.at("kind").get<std::string>();
      const nlohmann::json& w = m.at("weights");
      if (!w.is_array() || w.size() != 4)
        throw std::invalid_argument("models[].weights: expected 4 numbers");
      for (int k = 0; k < 4; ++k) s.weights[k] = w.at(k).get<double>();
      s.samples = m.at("samples").get<int>();
      s.successes = m.at("successes").get<int>();
      c.models.push_back(s);
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("not a calibration file: ") + e.what());
  }
  return c;
}

Calibration LoadCalibration(const std::string& path, const std::string& season,
                            const std::string& robot) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot read the calibration file");
  Calibration c;
  try {
    c = CalibrationFromJson(nlohmann::json::parse(in));
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
  if (c.season != season || c.robot != robot) {
    throw std::invalid_argument(path + ": fitted for " + c.season + " with " + c.robot +
                                ", not for " + season + " with " + robot);
  }
  return c;
}

std::function<std::optional<double>(const std::string&, const std::string&, double, double, double)>
LearnedSuccess(const Calibration& calibration) {
  return [calibration](const std::string& action, const std::string& kind, double range_m,
                       double bearing_rad, double sigma_m) -> std::optional<double> {
    const SuccessModel* m = calibration.Find(action, kind);
    if (!m) return std::nullopt;
    return m->Predict(range_m, bearing_rad, sigma_m);
  };
}

std::vector<ReliabilityBin> Reliability(const std::vector<AttemptSample>& samples,
                                        const std::string& action, int bins) {
  std::vector<ReliabilityBin> out(bins);
  for (int b = 0; b < bins; ++b) out[b].low = double(b) / bins, out[b].high = double(b + 1) / bins;
  for (int fold = 0; fold < 2; ++fold) {
    std::vector<AttemptSample> train, test;
    for (const AttemptSample& s : samples)
      (s.seed % 2 == uint64_t(fold) ? test : train).push_back(s);
    const std::vector<SuccessModel> models = FitAll(train);
    for (const AttemptSample& s : test) {
      if (s.action != action) continue;
      const SuccessModel* m = FindIn(models, s.action, s.kind);
      if (!m) continue;
      const double p = m->Predict(s.range_m, s.bearing_rad, s.sigma_m);
      const int b = std::min(bins - 1, static_cast<int>(p * bins));
      ++out[b].attempts;
      out[b].successes += s.success;
      out[b].mean_predicted += p;
    }
  }
  for (ReliabilityBin& b : out) {
    if (b.attempts) b.mean_predicted /= b.attempts;
  }
  return out;
}

void PrintCalibration(const Calibration& c, const std::vector<AttemptSample>& samples,
                      std::ostream& out) {
  out << "success models (" << c.season << ", " << c.robot
      << "): P = 1 / (1 + exp(-(w0 + w1 range_m + w2 |bearing_rad| + w3 sigma_m)))\n";
  out << std::left << std::setw(8) << "action" << std::setw(14) << "kind" << std::right
      << std::setw(9) << "attempts" << std::setw(8) << "rate" << std::setw(10) << "w0"
      << std::setw(10) << "w1" << std::setw(10) << "w2" << std::setw(10) << "w3"
      << "\n";
  for (const SuccessModel& m : c.models) {
    out << std::left << std::setw(8) << m.action << std::setw(14)
        << (m.kind.empty() ? "(any)" : m.kind) << std::right << std::setw(9) << m.samples
        << std::setw(8) << std::fixed << std::setprecision(2)
        << (m.samples ? double(m.successes) / m.samples : 0.0);
    for (double w : m.weights) out << std::setw(10) << std::setprecision(3) << w;
    out << "\n";
  }
  for (const std::string action : {"PICK", "SCORE"}) {
    out << "reliability, " << action
        << " (two-fold by seed parity: each attempt predicted by the models of the other half)\n";
    out << std::setw(14) << "predicted" << std::setw(10) << "attempts" << std::setw(12)
        << "mean pred" << std::setw(10) << "observed"
        << "\n";
    for (const ReliabilityBin& b : Reliability(samples, action)) {
      std::ostringstream range;
      range << std::fixed << std::setprecision(1) << b.low << "-" << b.high;
      out << std::setw(14) << range.str() << std::setw(10) << b.attempts << std::setw(12)
          << std::setprecision(3)
          << (b.attempts ? b.mean_predicted : std::numeric_limits<double>::quiet_NaN())
          << std::setw(10)
          << (b.attempts ? double(b.successes) / b.attempts
                         : std::numeric_limits<double>::quiet_NaN())
          << "\n";
    }
  }
}

}  // namespace slamo::autonomy
