// SLAM-O on a recording: a short simulated run written as a TUM folder, replayed through
// RunRecording, against the recording's own ground truth.
#include "autonomy/experiments/recording_run.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "autonomy/reports/match_report.h"
#include "field_configs/loader.h"
#include "platform/recording.h"
#include "platform/sim/sim_recording.h"

namespace slamo::autonomy {
namespace {

using platform::kPi;

TEST(RecordingRun, ReplaysASimulatedRecordingWithinTenCentimetres) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  const std::string rec = ::testing::TempDir() + "/recording_run_rec";
  const std::string out = ::testing::TempDir() + "/recording_run_out";
  std::filesystem::remove_all(rec);
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out);
  platform::SimRecordingOptions options;
  options.seed = 1;
  options.script = "forward 0.3; turn 45";
  for (const field::StartTile& s : season.starts) {
    if (s.alliance != field::Alliance::kRed) continue;
    options.start = {s.center_m.x, s.center_m.y, s.heading_deg * kPi / 180.0};
    break;
  }
  {
    const std::unique_ptr<platform::RecordingWriter> writer =
        platform::OpenTumWriter(rec, platform::RecordingInfoFor(robot));
    const platform::SimRecordingSummary summary =
        platform::RecordSimulatedRun(season, robot, options, {writer.get()});
    writer->Close();
    ASSERT_GT(summary.frames, 3);
  }

  const MatchResult r = RunRecording(season, robot, rec, {}, out);
  EXPECT_EQ(r.strategy, "recording");
  EXPECT_GT(r.frames_taken, 3);
  EXPECT_EQ(r.samples.size(), static_cast<size_t>(r.frames_taken));
  ASSERT_FALSE(std::isnan(r.pose_ate_m));
  EXPECT_LT(r.pose_ate_m, 0.10);
  // The estimate followed the drive: it ends where the truth ends, not at the start.
  const PoseSample& last = r.samples.back();
  EXPECT_GT((last.truth - r.samples.front().truth).head<2>().norm(), 0.2);
  EXPECT_LT((last.estimate - last.truth).head<2>().norm(), 0.15);
  ASSERT_FALSE(r.timeline.empty());
  EXPECT_EQ(r.timeline.front().action, "REPLAY");
  for (const ObjectReport& o : r.objects) EXPECT_FALSE(o.matched);

  // The report files the command writes.
  const std::string dir = out + "/";
  WriteTum(r, dir + "trajectory.tum");
  WriteTruthTum(r, dir + "groundtruth.tum");
  std::ofstream(dir + "report.json") << ReportJson(r).dump(2);
  EXPECT_TRUE(cv::imwrite(dir + "map.png", DrawMatchMap(r)));
  for (const char* f :
       {"objects.bt", "trajectory.tum", "groundtruth.tum", "report.json", "map.png"})
    EXPECT_GT(std::filesystem::file_size(dir + f), 0u) << f;
}

TEST(RecordingRun, AMissingRecordingThrows) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  EXPECT_THROW(RunRecording(season, robot, ::testing::TempDir() + "/no_such_recording"),
               platform::RecordingError);
}

}  // namespace
}  // namespace slamo::autonomy
