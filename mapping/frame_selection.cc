#include "mapping/frame_selection.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace slamo::mapping {

void ParseFrameRule(const std::string& text, FrameSelectionOptions* options) {
  const size_t colon = text.find(':');
  const std::string name = text.substr(0, colon);
  const std::string value = colon == std::string::npos ? "" : text.substr(colon + 1);
  const auto number = [&](double lo, double hi) {
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !(v >= lo && v <= hi)) {
      std::ostringstream out;
      out << "frame rule '" << text << "': expected a number in [" << lo << ", " << hi
          << "] after ':'";
      throw std::invalid_argument(out.str());
    }
    return v;
  };
  if (name == "fixed") {
    options->rule = FrameRule::kFixed;
    options->fixed_frames = static_cast<int>(number(1, 1000));
    options->max_frames = std::max(options->max_frames, options->fixed_frames);
  } else if (name == "covariance") {
    options->rule = FrameRule::kCovariance;
    options->covariance_threshold = value.empty() ? 0.0 : number(1e-9, 10.0);
  } else if (name == "gmm" && value.empty()) {
    options->rule = FrameRule::kGmm;
  } else {
    throw std::invalid_argument("frame rule '" + text +
                                "': expected fixed:N, covariance, covariance:T or gmm");
  }
}

std::string Describe(const FrameSelectionOptions& options) {
  std::ostringstream out;
  switch (options.rule) {
    case FrameRule::kFixed:
      out << "fixed:" << options.fixed_frames;
      break;
    case FrameRule::kCovariance:
      out << "covariance:" << options.covariance_threshold;
      break;
    case FrameRule::kGmm:
      out << "gmm";
      break;
  }
  return out.str();
}

double DerivedCovarianceThreshold(const MotionNoise& noise, double stop_spacing_m) {
  const double sx = noise.sigma_per_m * stop_spacing_m + noise.floor_m;
  const double sy = noise.lateral_sigma_per_m * stop_spacing_m + noise.floor_m;
  return sx * sx + sy * sy;
}

FrameSelector::FrameSelector(const FrameSelectionOptions& options) : options_(options) {}

void FrameSelector::Start(const Eigen::Matrix3d& pose_covariance) {
  frames_ = 0;
  stalled_ = 0;
  last_trace_ = pose_covariance.topLeftCorner<2, 2>().trace();
  reason_.clear();
}

bool FrameSelector::Continue(const Eigen::Vector3d& pose, const Eigen::Matrix3d& pose_covariance) {
  ++frames_;
  const double trace = pose_covariance.topLeftCorner<2, 2>().trace();
  // The covariance stopped improving: more frames of the same scene cannot help.
  stalled_ = trace > (1.0 - options_.min_improvement) * last_trace_ ? stalled_ + 1 : 0;
  last_trace_ = trace;
  const auto stop = [&](const char* why) {
    reason_ = why;
    return false;
  };
  if (frames_ >= options_.max_frames) return stop("max");
  switch (options_.rule) {
    case FrameRule::kFixed:
      return frames_ >= options_.fixed_frames ? stop("count") : true;
    case FrameRule::kCovariance:
      // Algorithm 2 with its loop condition the right way round: observe while above.
      if (trace <= options_.covariance_threshold) return stop("threshold");
      if (stalled_ >= options_.stall_frames) return stop("stalled");
      return true;
    case FrameRule::kGmm: {
      // One Gaussian per stop, started at the first estimate and updated with each.
      if (frames_ == 1) {
        mean_ = pose;
        return true;
      }
      const double distance = (pose.head<2>() - mean_.head<2>()).norm();
      mean_ += (pose - mean_) / frames_;
      if (frames_ >= options_.gmm_min_frames && distance < options_.gmm_threshold_m) {
        return stop("converged");
      }
      if (frames_ >= options_.gmm_max_frames) return stop("max");
      if (stalled_ >= options_.stall_frames && frames_ >= options_.gmm_min_frames)
        return stop("stalled");
      return true;
    }
  }
  return stop("max");
}

}  // namespace slamo::mapping
