// The robot on match day behind RobotIo: the motor-controller board over its serial link
// (SerialDriveBase: speed targets out, encoder ticks back, heartbeats, reconnection) and an
// RGB-D camera (OpenNI2, or a recorded stream played back against the match clock).
//
// Time: a base clock runs (SteadyClock on the robot; a SimClock when the fake board runs in
// the same process) and `pace(dt_s)` lets dt_s of it pass (sleeping; or pumping the fake
// board and advancing the SimClock). Advance() paces in steps of at most 1 ms and services
// the link after each, so heartbeats and encoder frames flow whatever the match loop does.
// The match clock reads 0 at Start().
//
// What hardware cannot know: the true pose and the points (no referee), and what the intake
// did: the board's protocol has no intake channel and the thesis robot no intake sensor, so
// a pick is taken to hold its target and a release to land in the goal it was aimed at
// (IntakeItem::assumed). No yaw gyro either: run with MatchSetup::gyro = false.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "autonomy/loop/robot_io.h"
#include "platform/clock.h"
#include "platform/recording.h"
#include "platform/rgbd.h"
#include "platform/serial_drive_base.h"
#include "platform/sim/fake_board.h"
#include "platform/sim/sim_renderer.h"
#include "platform/sim/sim_world.h"

namespace slamo::autonomy {

// A recorded RGB-D stream as a live camera: at match time t it shows the recording's last
// frame at or before t after its first frame (frames between two grabs are skipped, as a live
// camera's would be); at the end it starts again from the first frame when `loop`, else it
// has nothing more.
class RecordedStreamCamera : public platform::RgbdCamera {
 public:
  RecordedStreamCamera(std::unique_ptr<platform::RecordingReader> reader,
                       const platform::Clock& match_clock, bool loop);
  std::optional<platform::RgbdFrame> Grab() override;
  const platform::RecordingReader& reader() const { return *reader_; }
  int loops() const { return loops_; }

 private:
  bool ReadNext();
  std::unique_ptr<platform::RecordingReader> reader_;
  const platform::Clock& clock_;
  bool loop_;
  std::optional<platform::RgbdFrame> next_;  // read ahead, not shown yet
  double first_t_s_ = 0.0;
  bool have_first_ = false;
  double loop_offset_s_ = 0.0;  // added to recording times after each loop
  double last_t_s_ = 0.0;
  int loops_ = 0;
  int64_t shown_ = -1;
};

// The simulated field's camera on the fake board (platform/sim/fake_board.h): renders the field
// (objects placed by CreateWorld for `seed`) from where the board's motor model has really
// taken the robot: the start pose on the field composed with the motors' own pose, which
// starts at the origin. A camera streaming at the robot's frame rate: a new frame once per
// frame period of `clock`. No collisions: the motor model drives through walls.
class FakeBoardCamera : public platform::RgbdCamera {
 public:
  FakeBoardCamera(const field::SeasonConfig& season, const field::RobotConfig& robot,
                  const platform::FakeBoard& board, const platform::Pose2D& start,
                  const platform::Clock& clock, uint64_t seed);
  // Where the fake board's motors have taken the robot, on the field.
  platform::Pose2D Truth() const;
  std::optional<platform::RgbdFrame> Grab() override;

 private:
  platform::SimWorld world_;
  platform::SimRenderer renderer_;
  const platform::FakeBoard& board_;
  platform::Pose2D start_;
  const platform::Clock& clock_;
  double period_s_;
  double next_s_ = 0.0;
};

struct HardwareIoOptions {
  field::Alliance alliance = field::Alliance::kRed;  // for the preload's colour
  // True distance per encoder distance, measured by the team (drive 1 m, tape measure).
  double odometry_scale = 1.0;
  double connect_timeout_s = 3.0;  // for the link to come up before the match starts
  double frame_wait_s = 0.1;       // how long Capture() waits for a camera frame
  std::string board_name;          // for reports: the device path
  std::string camera_name;         // for reports: "openni2", "recording DIR"
  // The true pose on the field, where something knows it (the fake board's motor model):
  // the report's pose ATE is measured against it.
  std::function<std::optional<platform::Pose2D>()> truth;
  // Where the run is recorded (not owned; nothing when null): every camera frame used, the
  // encoder ticks every control period and the truth when known, on the match clock, so
  // `slamo dry-run --from-recording` can run SLAM-O over the match again.
  platform::RecordingWriter* recorder = nullptr;
};

class HardwareIo : public RobotIo {
 public:
  // `board` and `camera` must outlive this; `base_clock` is the clock `board` was given.
  HardwareIo(platform::SerialDriveBase* board, platform::RgbdCamera* camera,
             const platform::Clock& base_clock, std::function<void(double)> pace,
             const HardwareIoOptions& options);

  // Services the link until it is up; false after connect_timeout_s (the reason is the
  // link's state). Call before the match.
  bool Connect();
  // Records from now on (HardwareIoOptions::recorder).
  void set_recorder(platform::RecordingWriter* recorder) { options_.recorder = recorder; }

  void Start(const field::SeasonConfig& field, const field::RobotConfig& robot,
             const platform::Pose2D& start) override;
  const platform::Clock& clock() const override { return match_clock_; }
  platform::DriveBase& drive() override { return *board_; }
  void Advance(double dt_s) override;
  platform::Pose2D OdometryPose() const override;
  bool MotorsDriven() const override;
  std::optional<double> GyroHeadingRad() override { return std::nullopt; }
  std::optional<platform::RgbdFrame> Capture() override;
  std::optional<platform::RgbdFrame> CaptureReady() override;
  std::optional<IntakeItem> Pick(const strategy::ObjectBelief& target) override;
  std::optional<ReleaseOutcome> Release(int intended_goal) override;
  std::optional<IntakeItem> Preload() const override { return preload_; }
  double OdometryScale() override { return options_.odometry_scale; }
  std::optional<platform::Pose2D> TruePose() const override {
    return options_.truth ? options_.truth() : std::nullopt;
  }
  std::optional<int> Points() const override { return std::nullopt; }
  std::string Describe() const override;
  std::map<std::string, double> Status() const override;

 private:
  // Match time: the base clock from Start().
  class MatchClock : public platform::Clock {
   public:
    explicit MatchClock(const platform::Clock& base) : base_(base) {}
    double NowS() const override { return base_.NowS() - origin_s_; }
    void StartNow() { origin_s_ = base_.NowS(); }

   private:
    const platform::Clock& base_;
    double origin_s_ = 0.0;
  };

  // The camera's frame if it has one now (counted, and recorded when recording).
  std::optional<platform::RgbdFrame> GrabOnce();

  platform::SerialDriveBase* board_;
  platform::RgbdCamera* camera_;
  const platform::Clock& base_clock_;
  std::function<void(double)> pace_;
  HardwareIoOptions options_;
  MatchClock match_clock_;
  field::RobotConfig robot_;
  std::optional<platform::EncoderOdometry> odometry_;
  std::optional<IntakeItem> preload_;
  bool held_ = false;
  int frames_ = 0;
  int frames_missed_ = 0;
  int picks_assumed_ = 0;
  int releases_assumed_ = 0;
  uint64_t link_losses_at_start_ = 0;
  bool started_ = false;
  double last_frame_s_ = -1.0;
};

}  // namespace slamo::autonomy
