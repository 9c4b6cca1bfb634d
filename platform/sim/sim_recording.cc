#include "platform/sim/sim_recording.h"

#include <cmath>
#include <string>

#include "platform/clock.h"
#include "platform/sim/sim_drive_script.h"
#include "platform/sim/sim_field.h"

namespace slamo::platform {

SimRecordingSummary RecordSimulatedRun(
    const field::SeasonConfig& season, const field::RobotConfig& robot,
    const SimRecordingOptions& options, const std::vector<RecordingWriter*>& writers,
    const std::function<void(const SimRecordingSummary&, double t_s)>& progress) {
  if (!(options.fps > 0.0) || !std::isfinite(options.fps)) {
    throw RecordingError("frames per second must be positive, got " + std::to_string(options.fps));
  }
  if (!(options.encoder_rate_hz >= 0.0) || !std::isfinite(options.encoder_rate_hz)) {
    throw RecordingError("the encoder rate must be >= 0, got " +
                         std::to_string(options.encoder_rate_hz));
  }
  const std::vector<DriveStep> steps = ParseDriveScript(options.script);
  SimField field(season, robot, field::Alliance::kRed, options.seed, options.start,
                 SimDriveOptionsFor(robot.drive));
  SimRenderer renderer(season, robot.camera, options.render, options.seed);
  SimClock clock;
  SimRecordingSummary summary;

  constexpr double kEpsilonS = 1e-9;
  const double frame_period_s = 1.0 / options.fps;
  const double reading_period_s =
      options.encoder_rate_hz > 0.0 ? 1.0 / options.encoder_rate_hz : 0.0;
  int64_t frame_number = 0, reading_number = 0;
  // After every simulation step: the readings and frames that are due (at most one frame per
  // step: the controller's 50 Hz caps the frame rate).
  auto log = [&]() {
    const double t = field.time_s();
    if (t >= reading_number * reading_period_s - kEpsilonS) {
      const EncoderTicks ticks = field.drive().ReadEncoders();
      const StampedPose truth{t, field.robot_pose()};
      for (RecordingWriter* w : writers) {
        w->AddEncoders(ticks);
        w->AddGroundTruth(truth);
      }
      ++summary.encoder_readings;
      ++summary.ground_truth_poses;
      while (reading_period_s > 0.0 && reading_number * reading_period_s <= t + kEpsilonS) {
        ++reading_number;
      }
    }
    if (t >= frame_number * frame_period_s - kEpsilonS) {
      const RgbdFrame frame = renderer.Render(field.world(), field.robot_pose(), t, nullptr);
      for (RecordingWriter* w : writers) w->AddFrame(frame);
      ++summary.frames;
      while (frame_number * frame_period_s <= t + kEpsilonS) ++frame_number;
      summary.duration_s = t;
      if (progress) progress(summary, t);
    }
  };
  log();
  summary.steps = RunDriveScript(steps, DriveControllerOptionsFor(robot.drive), &field.drive(),
                                 &clock, [&](double dt_s) {
                                   field.Step(dt_s);
                                   log();
                                 });
  summary.duration_s = field.time_s();
  return summary;
}

}  // namespace slamo::platform
