// The simulator as the recorder: a drive script driven on the whole simulated field, its camera
// rendered and its encoders and true pose logged into recording writers (platform/recording.h).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "platform/drive_base.h"
#include "platform/drive_script.h"
#include "platform/recording.h"
#include "platform/sim/sim_renderer.h"

namespace slamo::platform {

struct SimRecordingOptions {
  uint64_t seed = 1;
  Pose2D start;                  // robot start pose on the field
  std::string script;            // a drive script (see ParseDriveScript)
  double fps = 5.0;              // camera frames per second of simulated time
  double encoder_rate_hz = 0.0;  // encoder and ground-truth readings; 0 = every control tick
  RenderOptions render;
};

struct SimRecordingSummary {
  int frames = 0;
  int encoder_readings = 0;
  int ground_truth_poses = 0;
  double duration_s = 0.0;
  std::vector<DriveStepResult> steps;
};

// Drives `options.script` on the whole simulated field (SimField: objects, opponents), renders
// the camera at options.fps from the start (t = 0) and logs encoders and the true pose, into
// every writer (not closed here). `progress`, when given, is called after each frame.
// Throws DriveScriptError for a bad script, RecordingError for a write failure.
SimRecordingSummary RecordSimulatedRun(
    const field::SeasonConfig& season, const field::RobotConfig& robot,
    const SimRecordingOptions& options, const std::vector<RecordingWriter*>& writers,
    const std::function<void(const SimRecordingSummary&, double t_s)>& progress = nullptr);

}  // namespace slamo::platform
