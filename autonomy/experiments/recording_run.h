// SLAM-O on a recorded run instead of the simulator (`slamo dry-run --from-recording DIR`): the
// recording's encoder ticks predict the EKF at every frame time, the season's surveyed markers
// correct it, and the object tracker and the OctoMap object map follow every few frames.
#pragma once

#include <string>

#include "autonomy/loop/executive.h"
#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"

namespace slamo::autonomy {

struct RecordingRunOptions {
  int object_every_n_frames = 5;  // objects are detected on every N-th frame (and the last)
  int max_frames = 0;             // stop after this many frames (0: all)
};

// Replays the recording at `dir` (a TUM folder or a rawlog; platform::OpenRecording) through
// SLAM-O. The EKF starts at the first ground-truth pose when the recording has one, else at
// the season's first red starting tile. Samples hold the estimate at every frame and the
// ground truth interpolated at the frame's time; without ground truth the truth is the
// estimate and pose_ate_m is NaN. Objects are reported unmatched (matched = false). When
// out_dir is set the object map is written there as objects.bt. Throws
// platform::RecordingError for an unreadable recording.
MatchResult RunRecording(const field::SeasonConfig& season, const field::RobotConfig& robot,
                         const std::string& dir, const RecordingRunOptions& options = {},
                         const std::string& out_dir = "");

}  // namespace slamo::autonomy
