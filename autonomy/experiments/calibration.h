// P(success) learned from the simulator's own outcomes (`slamo tune calibrate`): from the pick
// and release attempts a tune sweep recorded (MatchOutcome::records), a logistic model per
// action and object kind of the chance that the attempt works, against what the robot knew
// when it began: the range and bearing of its target and its pose sigma. A pick works when it
// took its target, a release when it scored in the goal aimed at. The reliability table says
// whether the fitted probabilities can be trusted: attempts binned by predicted probability,
// each bin's mean prediction against its observed rate, every prediction made by the model
// fitted on the other half of the seeds (two-fold, odd against even), so no attempt grades a
// model fitted on itself.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autonomy/experiments/tuning.h"

namespace slamo::autonomy {

// P(success) = 1 / (1 + exp(-(w0 + w1 range_m + w2 |bearing_rad| + w3 sigma_m))).
struct SuccessModel {
  std::string action;  // PICK or SCORE
  std::string kind;    // object kind; empty: every kind
  double weights[4] = {0.0, 0.0, 0.0, 0.0};
  int samples = 0;
  int successes = 0;
  double Predict(double range_m, double bearing_rad, double sigma_m) const;
};

// The attempt features and whether it worked.
struct AttemptSample {
  std::string action, kind;
  double range_m = 0.0, bearing_rad = 0.0, sigma_m = 0.0;
  bool success = false;
  uint64_t seed = 0;
};
std::vector<AttemptSample> SamplesOf(const std::vector<MatchOutcome>& outcomes);

// Logistic regression by Newton's method (iteratively reweighted least squares) with a small
// ridge on the slopes, so that a kind that always (or never) works gets a finite fit.
SuccessModel FitSuccessModel(const std::vector<AttemptSample>& samples, const std::string& action,
                             const std::string& kind);

struct Calibration {
  std::string season, robot;
  std::vector<SuccessModel> models;  // one per (action, kind) with at least kMinSamples
  // The model for an attempt: its action and kind's, else its action's over every kind.
  const SuccessModel* Find(const std::string& action, const std::string& kind) const;
};
inline constexpr int kMinSamples = 10;
Calibration Calibrate(const std::vector<AttemptSample>& samples, const std::string& season,
                      const std::string& robot);
nlohmann::json ToJson(const Calibration& calibration);
// Throws std::invalid_argument naming what is wrong.
Calibration CalibrationFromJson(const nlohmann::json& j);

// Reads a file `slamo tune calibrate` wrote; throws std::invalid_argument naming the file and
// what is wrong, also when it was fitted for another season or robot than those given.
Calibration LoadCalibration(const std::string& path, const std::string& season,
                            const std::string& robot);
// The strategy's learned P(success) (StrategyOptions::learned_success) from a calibration.
std::function<std::optional<double>(const std::string&, const std::string&, double, double, double)>
LearnedSuccess(const Calibration& calibration);

struct ReliabilityBin {
  double low = 0.0, high = 0.0;  // predicted probability range
  int attempts = 0, successes = 0;
  double mean_predicted = 0.0;
};
// Two-fold by seed parity: each attempt predicted by the models fitted on the other fold.
std::vector<ReliabilityBin> Reliability(const std::vector<AttemptSample>& samples,
                                        const std::string& action, int bins = 5);
void PrintCalibration(const Calibration& calibration, const std::vector<AttemptSample>& samples,
                      std::ostream& out);

}  // namespace slamo::autonomy
