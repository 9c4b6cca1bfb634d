// The robot: footprint, drive train, motor PWM convention, PID gains, encoders, intake and
// the RGB-D camera (model, intrinsics, mount, noise, depth correction). Loaded and validated
// from field_configs/robots/<robot>.yaml by LoadRobotConfig(); plain data afterwards.
#pragma once

#include <optional>
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

// The motors behind the drive, for the record and for checking max_speed_mps against the free
// speed they allow (optional in the file; the thesis robot's 393 motors are described in a
// comment only).
struct MotorConfig {
  std::string type;          // e.g. v5_smart_motor
  double cartridge_rpm = 0;  // V5: 100 (red), 200 (green) or 600 (blue) free speed
  double gear_ratio = 1.0;   // wheel rpm / motor rpm (36:48 -> 0.75)
  int count = 0;             // motors on the drive
  // No-load wheel surface speed (m/s).
  double FreeSpeedMps(double wheel_diameter_m) const {
    return cartridge_rpm * gear_ratio * 3.14159265358979 * wheel_diameter_m / 60.0;
  }
};

// The simulator's slip model for this drive (optional in the file; the defaults are the
// thesis robot's calibration, platform/sim/sim_drive.h). Fractions as in SimDriveOptions.
struct SlipConfig {
  double straight_mean = 0.165;
  double straight_stddev = 0.06;
  double side_stddev = 0.04;
  double turn_mean = 0.01;
  double turn_stddev = 0.03;
  double pivot_offset_m = 0.07;
  double pivot_stddev_m = 0.01;
  double motor_time_constant_s = 0.08;
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
  std::optional<MotorConfig> motor;
  std::optional<SlipConfig> slip;
};

// A yaw gyro / inertial sensor on the robot (optional in the file: without it the simulator's
// default gyro is used, SimGyroOptions).
struct ImuConfig {
  std::string model;                  // e.g. v5_inertial_sensor
  double noise_deg = 0.2;             // white noise of one heading reading
  double drift_deg_per_sqrt_s = 0.1;  // bias random walk
};

// The odometry's error, as SLAM-O's EKF models it: sigmas growing with the distance travelled
// and the angle turned in one step (mapping::MotionNoise).
struct OdometryNoiseConfig {
  double forward_sigma_per_m = 0.0;    // forward error per metre travelled
  double lateral_sigma_per_m = 0.0;    // sideways error per metre travelled
  double forward_sigma_per_rad = 0.0;  // forward error per radian turned (turn slip)
  double lateral_sigma_per_rad = 0.0;  // sideways error per radian turned
  double heading_sigma_per_rad = 0.0;  // heading error per radian turned
  double heading_sigma_per_m = 0.0;    // heading error per metre travelled
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
  // The error a stop's repeated frames share (one per stop, not averaged away by more frames):
  // SLAM-O's iterated-frame covariance (mapping::IteratedFrameCovariance) for its markers.
  double stop_bias_range_sigma_m = 0.0;
  double stop_bias_bearing_sigma_deg = 0.0;
  // From a frame's exposure to when the program has it (s): a frame taken on the move shows
  // the robot where it was this long before the encoders' latest reading. The simulator
  // renders it so; SLAM-O pairs such a frame with the odometry of its exposure.
  double latency_s = 0.0;
};

struct IntakeConfig {
  double reach_m = 0.0;    // how far in front of the bumper an object can be picked
  int capacity = 1;        // objects held at once
  double pick_s = 1.0;     // the intake taking an object in, once the bumper is at it
  double release_s = 1.0;  // letting a held object out
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
  std::optional<ImuConfig> imu;
  OdometryNoiseConfig odometry_noise;
};

}  // namespace slamo::field
