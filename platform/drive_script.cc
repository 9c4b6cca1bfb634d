#include "platform/drive_script.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <deque>
#include <sstream>
#include <utility>

namespace slamo::platform {
namespace {

std::string Trim(const std::string& text) {
  const auto not_space = [](unsigned char c) { return !std::isspace(c); };
  const auto begin = std::find_if(text.begin(), text.end(), not_space);
  const auto end = std::find_if(text.rbegin(), text.rend(), not_space).base();
  return begin < end ? std::string(begin, end) : std::string();
}

[[noreturn]] void Fail(int index, const std::string& statement, const std::string& problem) {
  throw DriveScriptError("drive script statement " + std::to_string(index) + " \"" + statement +
                         "\": " + problem);
}

// The whole token as a finite number, or a DriveScriptError naming it.
double ParseNumber(int index, const std::string& statement, const std::string& token,
                   const std::string& what) {
  double value = 0.0;
  size_t used = 0;
  try {
    value = std::stod(token, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != token.size() || !std::isfinite(value)) {
    Fail(index, statement, "expected " + what + ", got \"" + token + "\"");
  }
  return value;
}

DriveStep ParseStatement(int index, const std::string& statement) {
  std::istringstream in(statement);
  std::vector<std::string> tokens;
  for (std::string token; in >> token;) tokens.push_back(token);
  const std::string& verb = tokens[0];
  if (verb != "forward" && verb != "back" && verb != "turn" && verb != "wait") {
    Fail(index, statement,
         "unknown command \"" + verb + "\" (expected forward, back, turn or wait)");
  }
  const std::string what = verb == "turn"   ? "an angle in degrees"
                           : verb == "wait" ? "a time in seconds"
                                            : "a distance in metres";
  if (tokens.size() < 2) Fail(index, statement, "missing " + what + " after \"" + verb + "\"");
  if (tokens.size() > 2) Fail(index, statement, "unexpected \"" + tokens[2] + "\"");
  const double value = ParseNumber(index, statement, tokens[1], what);

  DriveStep step;
  step.text = statement;
  step.amount = value;
  if (verb == "turn") {
    step.kind = DriveStepKind::kTurn;
  } else if (verb == "wait") {
    if (value < 0.0) Fail(index, statement, "expected a time >= 0, got \"" + tokens[1] + "\"");
    step.kind = DriveStepKind::kWait;
  } else {
    if (value <= 0.0) {
      Fail(index, statement, "expected a distance > 0, got \"" + tokens[1] + "\"");
    }
    step.kind = DriveStepKind::kDrive;
    if (verb == "back") step.amount = -value;
  }
  return step;
}

// The controller: sees the encoders (and a gyro's heading, when the link has one). `advance`
// lets one control period pass on the clock (the simulator steps; on hardware the link is
// serviced while real time runs).
class Runner {
 public:
  Runner(const DriveControllerOptions& options, const DriveBodyLink& body)
      : options_(options),
        base_(body.base),
        clock_(body.clock),
        advance_(body.advance),
        truth_(body.truth),
        gyro_(body.gyro),
        correct_(body.correct),
        half_track_m_(0.5 * body.track_width_m),
        odometry_(body.metres_per_tick, body.track_width_m, body.base->ReadEncoders(),
                  body.odometry_start),
        heading_rad_(odometry_.pose().theta_rad),
        intended_heading_rad_(heading_rad_) {
    if (gyro_) last_gyro_rad_ = gyro_();
  }

  DriveStepResult Run(const DriveStep& step) {
    DriveStepResult result;
    result.step = step;
    bool done = true;
    if (clock_->NowS() >= options_.hard_deadline_s) {
      base_->Stop();
      result.status = DriveStepStatus::kDeadline;
      Finish(&result);
      return result;
    }
    switch (step.kind) {
      case DriveStepKind::kTurn: {
        const double amount_rad = step.amount * kPi / 180.0;
        intended_heading_rad_ += amount_rad;
        const double nominal_s = std::abs(amount_rad) * half_track_m_ / options_.cruise_speed_mps;
        done = Turn(intended_heading_rad_ - heading_rad_, Deadline(nominal_s));
        break;
      }
      case DriveStepKind::kDrive: {
        const double nominal_s = std::abs(step.amount) / options_.cruise_speed_mps;
        done = Drive(step.amount, Deadline(nominal_s));
        break;
      }
      case DriveStepKind::kWait: {
        base_->Stop();
        const long ticks = std::lround(step.amount / options_.control_dt_s);
        long i = 0;
        for (; i < ticks && clock_->NowS() < options_.hard_deadline_s; ++i) Tick();
        done = i == ticks;
        break;
      }
    }
    result.status = done                                         ? DriveStepStatus::kDone
                    : clock_->NowS() >= options_.hard_deadline_s ? DriveStepStatus::kDeadline
                                                                 : DriveStepStatus::kTimedOut;
    Finish(&result);
    return result;
  }

 private:
  void Finish(DriveStepResult* result) const {
    result->end_time_s = clock_->NowS();
    result->odometry_pose = odometry_.pose();
    result->truth_known = static_cast<bool>(truth_);
    result->true_pose = truth_ ? truth_() : odometry_.pose();
  }

  double Deadline(double nominal_s) const {
    return std::min(options_.hard_deadline_s, clock_->NowS() + options_.timeout_factor * nominal_s +
                                                  options_.timeout_margin_s);
  }

  // One controller period passes, then the encoders are read.
  void Tick() {
    advance_(options_.control_dt_s);
    const double before_rad = odometry_.pose().theta_rad;
    odometry_.Update(base_->ReadEncoders());
    const std::optional<double> gyro = gyro_ ? gyro_() : std::nullopt;
    if (gyro && last_gyro_rad_) {
      heading_rad_ += WrapAngleRad(*gyro - *last_gyro_rad_);
    } else {
      heading_rad_ += WrapAngleRad(odometry_.pose().theta_rad - before_rad);
    }
    last_gyro_rad_ = gyro;  // after a missing reading the next one only starts afresh
  }

  // The next wheel speed of a ramp: accelerate to cruise, decelerate to reach 0 at the end.
  double RampSpeed(double speed_mps, double remaining_m) const {
    const double ramp = std::min(
        {speed_mps + options_.accel_mps2 * options_.control_dt_s, options_.cruise_speed_mps,
         std::sqrt(2.0 * options_.accel_mps2 * std::max(0.0, remaining_m))});
    return std::max(ramp, std::min(options_.min_speed_mps, options_.cruise_speed_mps));
  }

  // Turns in place by amount_rad by the heading (the encoders', or the gyro's); false on
  // timeout.
  bool Turn(double amount_rad, double deadline_s) {
    const double target_rad = heading_rad_ + amount_rad;
    const double sign = amount_rad >= 0.0 ? 1.0 : -1.0;
    double speed_mps = 0.0;
    double last_rad = heading_rad_;
    while (true) {
      const double remaining_m = sign * (target_rad - heading_rad_) * half_track_m_;
      // The wheels lag the ramp down, so they turn faster than commanded and coast further
      // once cut: the cut is timed at the faster of the two.
      const double turning_mps =
          options_.lead_on_measured_speed
              ? sign * (heading_rad_ - last_rad) * half_track_m_ / options_.control_dt_s
              : 0.0;
      last_rad = heading_rad_;
      if (remaining_m <= std::max(speed_mps, turning_mps) * options_.stop_lead_s) break;
      if (clock_->NowS() >= deadline_s) {
        Settle();
        return false;
      }
      speed_mps = RampSpeed(speed_mps, remaining_m);
      base_->SetSpeedTargets(-sign * speed_mps, sign * speed_mps);
      Tick();
    }
    Settle();
    return true;
  }

  // Turn-then-drive: aligns with the intended heading, then drives distance_m (negative =
  // backwards) holding it; false on timeout.
  bool Drive(double distance_m, double deadline_s) {
    const double misalignment_rad = intended_heading_rad_ - heading_rad_;
    if (std::abs(misalignment_rad) > options_.align_tolerance_deg * kPi / 180.0) {
      if (!Turn(misalignment_rad, deadline_s)) return false;
    }
    Pose2D start = odometry_.pose();
    double ux = std::cos(intended_heading_rad_);
    double uy = std::sin(intended_heading_rad_);
    const double sign = distance_m >= 0.0 ? 1.0 : -1.0;
    double speed_mps = 0.0;
    while (true) {
      if (const std::optional<DriveCorrection> c = correct_ ? correct_() : std::nullopt) {
        // Measured from here on: the new heading, and what is left to go along it.
        intended_heading_rad_ = heading_rad_ + c->heading_change_rad;
        ux = std::cos(intended_heading_rad_);
        uy = std::sin(intended_heading_rad_);
        start = odometry_.pose();
        distance_m = sign * std::max(0.0, c->remaining_m);
      }
      const Pose2D& pose = odometry_.pose();
      const double along_m = (pose.x_m - start.x_m) * ux + (pose.y_m - start.y_m) * uy;
      const double remaining_m = std::abs(distance_m) - sign * along_m;
      if (remaining_m <= speed_mps * options_.stop_lead_s) break;
      if (clock_->NowS() >= deadline_s) {
        Settle();
        return false;
      }
      speed_mps = RampSpeed(speed_mps, remaining_m);
      // Hold the heading: a yaw-rate command becomes a wheel speed difference.
      const double yaw_rate_rps =
          options_.heading_gain_per_s * (intended_heading_rad_ - heading_rad_);
      const double steer_mps =
          std::clamp(yaw_rate_rps * half_track_m_, -0.5 * speed_mps, 0.5 * speed_mps);
      base_->SetSpeedTargets(sign * speed_mps - steer_mps, sign * speed_mps + steer_mps);
      Tick();
    }
    Settle();
    return true;
  }

  // Stops and waits until the encoders have been still for settle_s (or max_settle_s).
  void Settle() {
    base_->Stop();
    if (options_.settle_ticks > 0) {
      // The readings since the stop. Settled once, over the newest stretch of at least settle_s
      // by the readings' own clock (a repeated reading from a late link adds no time), each
      // wheel moved at most settle_ticks in all, back and forth counted.
      std::deque<EncoderTicks> readings = {odometry_.last()};
      const double span_s = options_.settle_s - 1e-9;
      for (double waited_s = 0.0; waited_s < options_.max_settle_s;
           waited_s += options_.control_dt_s) {
        Tick();
        readings.push_back(odometry_.last());
        while (readings.size() > 2 && readings.back().t_s - readings[1].t_s >= span_s) {
          readings.pop_front();
        }
        if (readings.back().t_s - readings.front().t_s < span_s) continue;
        int64_t left = 0, right = 0;
        for (size_t k = 1; k < readings.size(); ++k) {
          left += std::abs(readings[k].left - readings[k - 1].left);
          right += std::abs(readings[k].right - readings[k - 1].right);
        }
        if (left <= options_.settle_ticks && right <= options_.settle_ticks) return;
      }
      return;
    }
    double still_s = 0.0;
    for (double waited_s = 0.0; still_s < options_.settle_s && waited_s < options_.max_settle_s;
         waited_s += options_.control_dt_s) {
      const EncoderTicks before = odometry_.last();
      Tick();
      const bool moved =
          odometry_.last().left != before.left || odometry_.last().right != before.right;
      still_s = moved ? 0.0 : still_s + options_.control_dt_s;
    }
  }

  DriveControllerOptions options_;
  DriveBase* base_;
  const Clock* clock_;
  std::function<void(double)> advance_;
  std::function<Pose2D()> truth_;
  std::function<std::optional<double>()> gyro_;
  std::function<std::optional<DriveCorrection>()> correct_;
  std::optional<double> last_gyro_rad_;  // the gyro's last reading
  double half_track_m_;
  EncoderOdometry odometry_;
  double heading_rad_;           // heading (encoders, or the gyro's changes), unwrapped
  double intended_heading_rad_;  // sum of the script's turns, unwrapped
};

}  // namespace

std::vector<DriveStep> ParseDriveScript(const std::string& script) {
  std::vector<DriveStep> steps;
  std::string statement;
  int index = 0;
  const auto flush = [&]() {
    const std::string trimmed = Trim(statement);
    statement.clear();
    if (trimmed.empty()) return;
    steps.push_back(ParseStatement(++index, trimmed));
  };
  for (const char c : script) {
    if (c == ';' || c == '\n') {
      flush();
    } else {
      statement += c;
    }
  }
  flush();
  return steps;
}

DriveControllerOptions DriveControllerOptionsFor(const field::DriveConfig& drive) {
  DriveControllerOptions options;
  options.cruise_speed_mps = drive.cruise_speed_mps;
  options.accel_mps2 = drive.accel_mps2;
  return options;
}

std::vector<DriveStepResult> RunDriveScript(const std::vector<DriveStep>& steps,
                                            const DriveControllerOptions& options,
                                            const DriveBodyLink& body) {
  if (body.base == nullptr || body.clock == nullptr || !body.advance ||
      body.metres_per_tick <= 0.0 || body.track_width_m <= 0.0) {
    throw std::invalid_argument(
        "RunDriveScript: a drive base, a clock, an advance function and a positive wheel geometry "
        "are needed");
  }
  Runner runner(options, body);
  std::vector<DriveStepResult> results;
  results.reserve(steps.size());
  for (const DriveStep& step : steps) results.push_back(runner.Run(step));
  return results;
}

}  // namespace slamo::platform
