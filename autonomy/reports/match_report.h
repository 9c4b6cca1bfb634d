// What a dry run leaves behind: report.json, trajectory.tum, map.png and replay.avi, and the
// summary printed on the terminal.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "autonomy/loop/executive.h"

namespace slamo::autonomy {

// report.json's content: season, seed, strategy, points, duration_s, deadline_s, pose_ate_m,
// objects [{class, est_x, est_y, true_x, true_y, error_m}], timeline [{t_s, action, ...}] and
// the time split.
nlohmann::json ReportJson(const MatchResult& result);
// One pick or score attempt as report.json and tune.json keep it, and back.
nlohmann::json AttemptJson(const AttemptCheck& attempt);
AttemptCheck AttemptFromJson(const nlohmann::json& j);

// The estimated trajectory in TUM format (t x y z qx qy qz qw), one line per filter update.
void WriteTum(const MatchResult& result, const std::string& path);
// And the simulator's truth at the same instants.
void WriteTruthTum(const MatchResult& result, const std::string& path);

// The field from above: true and estimated trajectories, covariance ellipses, landmark and
// object estimates against the truth, the planned paths, and a legend with the figures.
cv::Mat DrawMatchMap(const MatchResult& result);

// One picture of the match at snapshot k (for the replay): the map from above and, on its
// right, the camera panel (DrawCameraPanel).
cv::Mat DrawSnapshot(const MatchResult& result, size_t k);
// What the robot saw at a snapshot, `size` large: its last camera frame (CameraView), scaled
// to fit below a title, each detection boxed and labelled with its kind, colour and range in
// the season's colour, those not tracked (dropped by the field gate, or without a range)
// greyed; before the first frame, a placeholder saying so.
cv::Mat DrawCameraPanel(const field::SeasonConfig& season, const Snapshot& snapshot, cv::Size size);
// The camera panel's width in a replay frame.
inline constexpr int kCameraPanelWidth = 2 * kCameraViewWidth + 20;
// The replay as a Motion-JPEG AVI (OpenCV's built-in writer), fps frames per match second
// shown at `speedup` times real time. Returns the frames written; throws on a write failure.
int WriteReplay(const MatchResult& result, const std::string& path, double speedup = 4.0);

void PrintSummary(const MatchResult& result, std::ostream& out);

// report.json, trajectory.tum, map.png, and (when the truth is known) groundtruth.tum, and
// (when `video`) replay.avi into dir. Returns the names written; throws std::runtime_error
// naming a file that cannot be written.
std::vector<std::string> WriteMatchFiles(const MatchResult& result, const std::string& dir,
                                         bool video);

// "a, b, c".
inline std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace slamo::autonomy
