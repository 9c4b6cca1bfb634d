// The robot: footprint, drive train, motor PWM convention, PID gains, encoders, intake and
// the RGB-D camera (model, intrinsics, mount, noise, depth correction). Loaded and validated
// from field_configs/robots/<robot>.yaml by LoadRobotConfig(); plain data afterwards.
#pragma once

#include <string>
#include <vector>

namespace slamo::field {

// Servo-style PWM of the VEX Motor Controller 29 as the thesis robot drives it.
struct PwmConvention {
  int full_forward = 0;         // PWM value for full forward
  int stop = 90;                // PWM value for stop
  int full_reverse = 180;       // PWM value for full reverse
  int deadband = 5;             // |pwm - stop| below which the motor does not turn
  double curve_exponent = 1.0;  // speed fraction = (pwm fraction)^exponent (nonlinear)
};

struct PidGains {
  double kp = 0.0;
  double ki = 0.0;
  double kd = 0.0;
  double rate_hz = 50.0;        // control loop rate in the firmware
  double integral_limit = 0.0;  // anti-windup clamp on the integral term (PWM units)
};

struct DriveConfig {
  double wheel_diameter_m = 0.06985;   // 2.75 in
  double track_width_m = 0.0;          // distance between left and right wheel contact lines
  double max_speed_mps = 0.0;          // wheel surface speed at full PWM
  double cruise_speed_mps = 0.067;     // speed used when driving between stops
  double match_speed_mps = 0.067;      // speed in a match's autonomous period (default: cruise)
  double turn_rate_dps = 0.0;          // turn-in-place rate used for planning
  double accel_mps2 = 0.0;             // acceleration limit of the speed ramps
  double encoder_ticks_per_rev = 0.0;  // at the wheel
  PwmConvention pwm;
  PidGains pid;
};

// Depth noise: standard deviation of one depth reading by distance, interpolated linearly.
struct DepthNoise {
  std::vector<double> distance_m;
  std::vector<double> sigma_m;
};

// Linear depth correction d_c = (d_measured - b) / a (thesis ch. 3), depth in millimetres.
struct DepthCorrection {
  double a = 1.0;
  double b_mm = 0.0;
};

struct CameraMount {
  double x_m = 0.0;        // forward of the robot centre
  double y_m = 0.0;        // left of the robot centre
  double height_m = 0.5;   // optical centre above the floor
  double pitch_deg = 0.0;  // positive looks down
  double yaw_deg = 0.0;
};

struct CameraConfig {
  std::string model;  // e.g. kinect_v2, primesense_carmine_1_08, kinect_v1
  int width_px = 0;
  int height_px = 0;
  double cx = 0.0;
  double cy = 0.0;
  double fx = 0.0;
  double fy = 0.0;
  double min_range_m = 0.0;
  double max_range_m = 0.0;
  double frame_rate_hz = 30.0;
  double colour_depth_baseline_m = 0.0;  // lateral offset of the colour camera from the IR camera
  CameraMount mount;
  DepthNoise noise;
  DepthCorrection depth_correction;
};

struct IntakeConfig {
  double reach_m = 0.0;  // how far in front of the bumper an object can be picked
  int capacity = 1;      // objects held at once
};

struct RobotConfig {
  std::string source_file;
  std::string name;
  double length_m = 0.0;  // footprint along the heading
  double width_m = 0.0;
  double height_m = 0.0;
  double mass_kg = 0.0;
  DriveConfig drive;
  IntakeConfig intake;
  CameraConfig camera;
};

}  // namespace slamo::field
