// A simulated yaw gyro (a VEX yaw-rate gyro or the V5 Inertial Sensor, integrated to a
// heading): the true heading plus a bias that drifts as a random walk and white noise per
// reading. It sees the body turn, not the wheels, so a turn blocked by a pinned object does
// not fool it the way it fools the encoders.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "field_configs/robot_config.h"
#include "platform/drive_base.h"

namespace slamo::platform {

struct SimGyroOptions {
  double noise_rad = 0.2 * kPi / 180.0;             // white noise of one reading
  double drift_rad_per_sqrt_s = 0.1 * kPi / 180.0;  // bias random walk
};

// The robot file's inertial sensor (imu:) as gyro options.
inline SimGyroOptions SimGyroOptionsFor(const field::ImuConfig& imu) {
  return {imu.noise_deg * kPi / 180.0, imu.drift_deg_per_sqrt_s * kPi / 180.0};
}

class SimGyro {
 public:
  SimGyro(uint64_t seed, const SimGyroOptions& options = {})
      : rng_(seed ^ 0x67F0A1ull), options_(options) {}

  // The heading reading at time t_s for the body's true heading.
  double Read(double true_heading_rad, double t_s) {
    const double dt = std::max(0.0, t_s - last_t_s_);
    last_t_s_ = t_s;
    bias_rad_ += options_.drift_rad_per_sqrt_s * std::sqrt(dt) * normal_(rng_);
    return WrapAngleRad(true_heading_rad + bias_rad_ + options_.noise_rad * normal_(rng_));
  }

 private:
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  SimGyroOptions options_;
  double bias_rad_ = 0.0;
  double last_t_s_ = 0.0;
};

}  // namespace slamo::platform
