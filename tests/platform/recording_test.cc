#include "platform/recording.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <mrpt/core/Clock.h>
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/serialization/CArchive.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "field_configs/loader.h"
#include "platform/drive_script.h"
#include "platform/sim/sim_recording.h"

namespace slamo::platform {
namespace {

namespace fs = std::filesystem;

// A fresh, empty temporary path for one test, removed with everything under it at the end.
class TempPath {
 public:
  explicit TempPath(const std::string& name)
      : path_((fs::path(testing::TempDir()) /
               ("recording_test_" + std::to_string(getpid()) + "_" + name))
                  .string()) {
    fs::remove_all(path_);
  }
  ~TempPath() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempPath(const TempPath&) = delete;
  TempPath& operator=(const TempPath&) = delete;
  const std::string& str() const { return path_; }

 private:
  std::string path_;
};

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// What a recording holds, in memory.
struct RunData {
  RecordingInfo info;
  std::vector<RgbdFrame> frames;
  std::vector<EncoderTicks> encoders;
  std::vector<StampedPose> truth;
};

// Random images (every colour byte, depth over TUM's whole range with holes), Unix-time
// stamps a few tens of ms apart, encoder ticks of both signs, headings all round the circle.
RunData MakeRun(int frames, uint64_t seed, int max_depth_mm = 13107) {
  RunData run;
  run.info.source = "test";
  run.info.robot = "test_robot";
  run.info.description = "random data";
  run.info.camera_model = "kinect_v1";
  run.info.width_px = 32;
  run.info.height_px = 24;
  run.info.fx = run.info.fy = 36.5;
  run.info.cx = 15.5;
  run.info.cy = 11.5;
  run.info.metres_per_tick = 0.00035;
  run.info.track_width_m = 0.36;
  cv::RNG rng(seed);
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> gap(0.001, 0.05);
  double t = 1700000000.0 + 0.123456;
  for (int k = 0; k < frames; ++k) {
    RgbdFrame f;
    f.t_s = t;
    f.index = k;
    f.colour.create(run.info.height_px, run.info.width_px, CV_8UC3);
    rng.fill(f.colour, cv::RNG::UNIFORM, 0, 256);
    f.depth_mm.create(run.info.height_px, run.info.width_px, CV_16UC1);
    rng.fill(f.depth_mm, cv::RNG::UNIFORM, 0, max_depth_mm + 1);
    f.depth_mm.at<uint16_t>(0, 0) = 0;  // no reading
    f.depth_mm.at<uint16_t>(0, 1) = static_cast<uint16_t>(max_depth_mm);
    f.depth_mm.at<uint16_t>(0, 2) = 1;
    run.frames.push_back(f);
    t += gap(gen);
  }
  std::uniform_int_distribution<int64_t> step(-40, 60);
  int64_t left = -5, right = 7;
  t = 1700000000.0;
  for (int k = 0; k < 5 * frames; ++k) {
    // Two readings at one time stamp once: times may repeat, they may not go back.
    if (k != 3) t += gap(gen) / 5.0;
    left += step(gen);
    right += step(gen);
    run.encoders.push_back({t, left, right});
  }
  std::uniform_real_distribution<double> heading(-3.14159, 3.14159), position(-1.8, 1.8);
  t = 1700000000.0;
  for (int k = 0; k < 3 * frames; ++k) {
    t += gap(gen);
    run.truth.push_back({t, Pose2D{position(gen), position(gen), heading(gen)}});
  }
  run.truth.push_back({t, Pose2D{0.25, -0.5, kPi}});  // the wrap point
  return run;
}

void WriteRun(RecordingWriter* writer, const RunData& run) {
  for (const RgbdFrame& f : run.frames) writer->AddFrame(f);
  for (const EncoderTicks& e : run.encoders) writer->AddEncoders(e);
  for (const StampedPose& p : run.truth) writer->AddGroundTruth(p);
  writer->Close();
}

std::vector<RgbdFrame> GrabAll(RecordingReader* reader) {
  std::vector<RgbdFrame> frames;
  while (std::optional<RgbdFrame> f = reader->Grab()) frames.push_back(std::move(*f));
  return frames;
}

bool SameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

void ExpectSameFrames(const std::vector<RgbdFrame>& expected, const std::vector<RgbdFrame>& got) {
  ASSERT_EQ(got.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    EXPECT_NEAR(got[k].t_s, expected[k].t_s, 1e-6);
    EXPECT_EQ(got[k].index, static_cast<int64_t>(k));
    EXPECT_EQ(got[k].colour.type(), CV_8UC3);
    EXPECT_EQ(got[k].depth_mm.type(), CV_16UC1);
    EXPECT_TRUE(SameImage(got[k].colour, expected[k].colour)) << "colour bytes differ";
    EXPECT_TRUE(SameImage(got[k].depth_mm, expected[k].depth_mm)) << "depth differs";
  }
}

void ExpectSameRun(const RunData& run, RecordingReader* reader) {
  EXPECT_EQ(reader->frame_count(), run.frames.size());
  ExpectSameFrames(run.frames, GrabAll(reader));
  EXPECT_FALSE(reader->Grab().has_value()) << "nothing after the last frame";

  ASSERT_EQ(reader->encoders().size(), run.encoders.size());
  for (size_t k = 0; k < run.encoders.size(); ++k) {
    EXPECT_NEAR(reader->encoders()[k].t_s, run.encoders[k].t_s, 1e-6) << k;
    EXPECT_EQ(reader->encoders()[k].left, run.encoders[k].left) << k;
    EXPECT_EQ(reader->encoders()[k].right, run.encoders[k].right) << k;
  }
  ASSERT_EQ(reader->ground_truth().size(), run.truth.size());
  for (size_t k = 0; k < run.truth.size(); ++k) {
    const StampedPose& got = reader->ground_truth()[k];
    const StampedPose& want = run.truth[k];
    EXPECT_NEAR(got.t_s, want.t_s, 1e-6) << k;
    EXPECT_NEAR(got.pose.x_m, want.pose.x_m, 1e-6) << k;
    EXPECT_NEAR(got.pose.y_m, want.pose.y_m, 1e-6) << k;
    EXPECT_NEAR(WrapAngleRad(got.pose.theta_rad - want.pose.theta_rad), 0.0, 1e-6) << k;
  }
  const RecordingInfo& info = reader->info();
  EXPECT_EQ(info.source, run.info.source);
  EXPECT_EQ(info.robot, run.info.robot);
  EXPECT_EQ(info.description, run.info.description);
  EXPECT_EQ(info.camera_model, run.info.camera_model);
  EXPECT_EQ(info.width_px, run.info.width_px);
  EXPECT_EQ(info.height_px, run.info.height_px);
  EXPECT_DOUBLE_EQ(info.fx, run.info.fx);
  EXPECT_DOUBLE_EQ(info.fy, run.info.fy);
  EXPECT_DOUBLE_EQ(info.cx, run.info.cx);
  EXPECT_DOUBLE_EQ(info.cy, run.info.cy);
  EXPECT_DOUBLE_EQ(info.metres_per_tick, run.info.metres_per_tick);
  EXPECT_DOUBLE_EQ(info.track_width_m, run.info.track_width_m);
}

// Expects `f` to throw RecordingError whose message contains every one of `parts`.
template <typename F>
void ExpectRecordingError(F f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no RecordingError";
  } catch (const RecordingError& e) {
    for (const std::string& part : parts) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "'" << e.what() << "' lacks '" << part << "'";
    }
  }
}

// ---- Round trips ----

TEST(RecordingTest, TumRoundTripIsExact) {
  const TempPath dir_tmp("tum_round_trip");
  const std::string& dir = dir_tmp.str();
  const RunData run = MakeRun(6, 1);
  WriteRun(OpenTumWriter(dir, run.info).get(), run);
  ExpectSameRun(run, OpenTumRecording(dir).get());
  ExpectSameRun(run, OpenRecording(dir).get());  // a folder is read as TUM
}

TEST(RecordingTest, RawlogRoundTripIsExact) {
  const TempPath path_tmp("round_trip.rawlog");
  const std::string& path = path_tmp.str();
  // MRPT's depth is uint16 too: the whole 16-bit range survives.
  const RunData run = MakeRun(6, 2, 65535);
  WriteRun(OpenRawlogWriter(path, run.info).get(), run);
  ExpectSameRun(run, OpenRawlogRecording(path).get());
  ExpectSameRun(run, OpenRecording(path).get());  // a file is read as a rawlog
}

TEST(RecordingTest, BothFormatsOfOneRunReadTheSame) {
  const TempPath dir_tmp("both");
  const std::string& dir = dir_tmp.str();
  const RunData run = MakeRun(4, 3);
  {
    auto tum = OpenTumWriter(dir, run.info);
    auto rawlog = OpenRawlogWriter(dir + "/recording.rawlog", run.info);
    WriteRun(tum.get(), run);
    WriteRun(rawlog.get(), run);
  }
  auto tum = OpenTumRecording(dir);
  auto rawlog = OpenRawlogRecording(dir + "/recording.rawlog");
  ExpectSameFrames(GrabAll(tum.get()), GrabAll(rawlog.get()));
  EXPECT_EQ(tum->encoders().size(), rawlog->encoders().size());
}

TEST(RecordingTest, TumFolderFollowsTheBenchmarkLayout) {
  const TempPath dir_tmp("tum_layout");
  const std::string& dir = dir_tmp.str();
  RunData run = MakeRun(2, 4);
  run.frames[0].t_s = 12.5;
  run.frames[1].t_s = 12.7;
  WriteRun(OpenTumWriter(dir, run.info).get(), run);

  const std::string rgb_txt = ReadText(fs::path(dir) / "rgb.txt");
  EXPECT_EQ(rgb_txt.rfind("# ", 0), 0u) << "TUM's comment header";
  EXPECT_NE(rgb_txt.find("\n12.500000 rgb/12.500000.png\n12.700000 rgb/12.700000.png\n"),
            std::string::npos)
      << rgb_txt;
  EXPECT_NE(ReadText(fs::path(dir) / "depth.txt").find("\n12.500000 depth/12.500000.png\n"),
            std::string::npos);
  EXPECT_NE(ReadText(fs::path(dir) / "groundtruth.txt").find("# timestamp tx ty tz qx qy qz qw"),
            std::string::npos);
  EXPECT_NE(ReadText(fs::path(dir) / "encoders.txt").find("# timestamp left right"),
            std::string::npos);
  EXPECT_NE(ReadText(fs::path(dir) / "recording.json").find("\"depth_units_per_metre\""),
            std::string::npos);

  // Depth PNGs are 16-bit with TUM's 5000 units per metre: 5 per millimetre.
  const cv::Mat depth =
      cv::imread((fs::path(dir) / "depth/12.500000.png").string(), cv::IMREAD_ANYDEPTH);
  ASSERT_EQ(depth.type(), CV_16UC1);
  cv::Mat expected;
  run.frames[0].depth_mm.convertTo(expected, CV_16UC1, 5.0);
  EXPECT_TRUE(SameImage(depth, expected));
  // Colour PNGs are ordinary 8-bit colour images.
  const cv::Mat colour = cv::imread((fs::path(dir) / "rgb/12.500000.png").string());
  EXPECT_TRUE(SameImage(colour, run.frames[0].colour));
}

// A sequence as the TUM benchmark ships it: no recording.json or encoders.txt, colour and depth
// stamped apart, depth not a multiple of 5, a 3D ground truth.
TEST(RecordingTest, ReadsATumBenchmarkStyleSequence) {
  const TempPath dir_tmp("tum_benchmark");
  const fs::path dir = dir_tmp.str();
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  cv::Mat colour(4, 6, CV_8UC3, cv::Scalar(10, 20, 30));
  cv::Mat depth(4, 6, CV_16UC1, cv::Scalar(5003));  // 1000.6 mm -> 1001
  depth.at<uint16_t>(1, 1) = 5002;                  // 1000.4 mm -> 1000
  ASSERT_TRUE(cv::imwrite((dir / "rgb/1305031102.175304.png").string(), colour));
  ASSERT_TRUE(cv::imwrite((dir / "rgb/1305031102.211214.png").string(), colour));
  ASSERT_TRUE(cv::imwrite((dir / "rgb/1305031102.975304.png").string(), colour));
  ASSERT_TRUE(cv::imwrite((dir / "depth/1305031102.160407.png").string(), depth));
  ASSERT_TRUE(cv::imwrite((dir / "depth/1305031102.226738.png").string(), depth));
  ASSERT_TRUE(cv::imwrite((dir / "depth/1305031102.262886.png").string(), depth));
  WriteText(dir / "rgb.txt",
            "# color images\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n"
            "1305031102.175304 rgb/1305031102.175304.png\n"
            "1305031102.211214 rgb/1305031102.211214.png\n"
            "1305031102.975304 rgb/1305031102.975304.png\n");  // no depth near: dropped
  WriteText(dir / "depth.txt",
            "# depth maps\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n"
            "1305031102.160407 depth/1305031102.160407.png\n"
            "1305031102.226738 depth/1305031102.226738.png\n"
            "1305031102.262886 depth/1305031102.262886.png\n");
  // A quarter turn and a half turn about z.
  WriteText(dir / "groundtruth.txt",
            "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
            "1305031098.6659 1.3563 0.6305 1.6380 0 0 0.7071067811865476 0.7071067811865476\n"
            "1305031098.6758 1.3543 0.6306 1.6360 0.0 0.0 1.0 0.0\n");
  auto reader = OpenTumRecording(dir.string());
  ASSERT_EQ(reader->frame_count(), 2u);
  const std::vector<RgbdFrame> frames = GrabAll(reader.get());
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_NEAR(frames[0].t_s, 1305031102.175304, 1e-6);
  EXPECT_NEAR(frames[1].t_s, 1305031102.211214, 1e-6);
  EXPECT_EQ(frames[0].depth_mm.at<uint16_t>(0, 0), 1001);
  EXPECT_EQ(frames[0].depth_mm.at<uint16_t>(1, 1), 1000);
  EXPECT_TRUE(SameImage(frames[1].colour, colour));
  EXPECT_TRUE(reader->encoders().empty());
  ASSERT_EQ(reader->ground_truth().size(), 2u);
  EXPECT_NEAR(reader->ground_truth()[0].pose.x_m, 1.3563, 1e-9);
  EXPECT_NEAR(reader->ground_truth()[0].pose.theta_rad, kPi / 2, 1e-9);
  EXPECT_NEAR(reader->ground_truth()[1].pose.theta_rad, kPi, 1e-9);
}

// ---- Writers refuse what they cannot keep ----

TEST(RecordingTest, WritersRejectBadFrames) {
  const TempPath dir_tmp("bad_frames");
  const std::string& dir = dir_tmp.str();
  const RunData run = MakeRun(2, 5);
  auto tum = OpenTumWriter(dir + "/tum", run.info);
  auto rawlog = OpenRawlogWriter(dir + "/x.rawlog", run.info);
  for (RecordingWriter* w : {tum.get(), rawlog.get()}) {
    w->AddFrame(run.frames[1]);
    ExpectRecordingError([&] { w->AddFrame(run.frames[0]); }, {"does not increase"});
    RgbdFrame same_microsecond = run.frames[1];
    same_microsecond.t_s += 1e-7;
    ExpectRecordingError([&] { w->AddFrame(same_microsecond); }, {"does not increase"});
    RgbdFrame grey = run.frames[1];
    grey.t_s += 1.0;
    grey.colour = cv::Mat(grey.depth_mm.size(), CV_8UC1, cv::Scalar(0));
    ExpectRecordingError([&] { w->AddFrame(grey); }, {"CV_8UC3"});
    RgbdFrame unregistered = run.frames[1];
    unregistered.t_s += 1.0;
    unregistered.depth_mm = cv::Mat(3, 3, CV_16UC1, cv::Scalar(0));
    ExpectRecordingError([&] { w->AddFrame(unregistered); }, {"registered"});
    w->AddEncoders({5.0, 1, 2});
    ExpectRecordingError([&] { w->AddEncoders({4.0, 1, 2}); }, {"goes backwards"});
    w->AddGroundTruth({5.0, {}});
    ExpectRecordingError([&] { w->AddGroundTruth({4.0, {}}); }, {"goes backwards"});
  }
  // TUM's PNG scale stops at 13.107 m.
  RgbdFrame deep = run.frames[1];
  deep.t_s += 2.0;
  deep.depth_mm.at<uint16_t>(2, 2) = 13108;
  ExpectRecordingError([&] { tum->AddFrame(deep); }, {"13108 mm", "13107"});
  // MRPT's encoder fields are 32-bit.
  ExpectRecordingError([&] { rawlog->AddEncoders({6.0, int64_t{1} << 31, 0}); }, {"32-bit"});
}

TEST(RecordingTest, TumWriterDoesNotOverwriteARecording) {
  const TempPath dir_tmp("no_overwrite");
  const std::string& dir = dir_tmp.str();
  const RunData run = MakeRun(1, 6);
  WriteRun(OpenTumWriter(dir, run.info).get(), run);
  ExpectRecordingError([&] { OpenTumWriter(dir, run.info); }, {dir, "already holds a recording"});
}

// ---- Bad TUM input: the file and line ----

class TumBadInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ =
        std::make_unique<TempPath>(::testing::UnitTest::GetInstance()->current_test_info()->name());
    dir_ = tmp_->str();
    const RunData run = MakeRun(3, 7);
    WriteRun(OpenTumWriter(dir_.string(), run.info).get(), run);
    rgb_txt_ = ReadText(dir_ / "rgb.txt");
  }
  // Line n (1-based) of a written index file.
  static std::string Line(const std::string& text, int n) {
    std::istringstream lines(text);
    std::string line;
    for (int i = 0; i < n; ++i) std::getline(lines, line);
    return line;
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  std::unique_ptr<TempPath> tmp_;
  fs::path dir_;
  std::string rgb_txt_;  // 3 comment lines, then 3 frames
};

TEST_F(TumBadInputTest, MissingFolderOrIndex) {
  ExpectRecordingError([&] { OpenTumRecording(Path("nowhere")); },
                       {Path("nowhere"), "no such folder"});
  fs::remove(dir_ / "depth.txt");
  ExpectRecordingError([&] { OpenTumRecording(dir_.string()); }, {Path("depth.txt"), "missing"});
}

TEST_F(TumBadInputTest, TruncatedLine) {
  WriteText(dir_ / "rgb.txt", rgb_txt_ + "1800000000.5\n");
  ExpectRecordingError([&] { OpenTumRecording(dir_.string()); },
                       {Path("rgb.txt") + ":7:", "truncated line", "timestamp filename"});
}

TEST_F(TumBadInputTest, TimestampNotANumber) {
  WriteText(dir_ / "rgb.txt", rgb_txt_ + "12:30 rgb/x.png\n");
  ExpectRecordingError([&] { OpenTumRecording(dir_.string()); },
                       {Path("rgb.txt") + ":7:", "timestamp `12:30` is not a number"});
}

TEST_F(TumBadInputTest, TimeGoesBackwards) {
  const std::string depth_txt = ReadText(dir_ / "depth.txt");
  WriteText(dir_ / "depth.txt", depth_txt + Line(depth_txt, 5) + "\n");
  ExpectRecordingError([&] { OpenTumRecording(dir_.string()); },
                       {Path("depth.txt") + ":7:", "time does not increase"});
}

TEST_F(TumBadInputTest, BadEncoderLines) {
  const std::string encoders = ReadText(dir_ / "encoders.txt");
  WriteText(dir_ / "encoders.txt", encoders + "1800000000.0 12.5 3\n");
  ExpectRecordingError([&] { OpenTumRecording(dir_.string()); },
                       {Path("encoders.txt") + ":", "left `12.5` is not an integer"});
  WriteText(dir_ / "encoders.txt", encoders + "1600000000.0 1 3\n");
  ExpectRecordingError([&] { OpenTumRecording(dir_.string()); },
                       {Path("encoders.txt") + ":", "time goes backwards"});
}

TEST_F(TumBadInputTest, BadGroundTruthLines) {
  const std::string truth = ReadText(dir_ / "groundtruth.txt");
  WriteText(dir_ / "groundtruth.txt", truth + "1800000000.0 1 2 0 0 0 1\n");
  ExpectRecordingError([&] { OpenTumRecording(dir_.string()); },
                       {Path("groundtruth.txt") + ":", "truncated line", "qw"});
  WriteText(dir_ / "groundtruth.txt", truth + "1800000000.0 1 2 0 0 0 1 1\n");
  ExpectRecordingError([&] { OpenTumRecording(dir_.string()); },
                       {Path("groundtruth.txt") + ":", "not a unit quaternion"});
}

TEST_F(TumBadInputTest, MissingOrWrongImage) {
  // The second frame's colour image is gone: the first still reads, the second names the line.
  const std::string second = Line(rgb_txt_, 5);
  const std::string file = second.substr(second.find(' ') + 1);
  fs::remove(dir_ / file);
  auto reader = OpenTumRecording(dir_.string());
  EXPECT_TRUE(reader->Grab().has_value());
  ExpectRecordingError([&] { reader->Grab(); }, {Path("rgb.txt") + ":5:", file, "no such image"});

  // An 8-bit depth image.
  const std::string depth_txt = ReadText(dir_ / "depth.txt");
  const std::string first = Line(depth_txt, 4);
  const std::string depth_file = first.substr(first.find(' ') + 1);
  ASSERT_TRUE(cv::imwrite((dir_ / depth_file).string(), cv::Mat(24, 32, CV_8UC1, cv::Scalar(9))));
  auto again = OpenTumRecording(dir_.string());
  ExpectRecordingError([&] { again->Grab(); }, {Path("depth.txt") + ":4:", "not a 16-bit"});
}

// ---- Bad rawlog input: the file and record ----

TEST(RecordingTest, BadRawlogs) {
  const TempPath dir_tmp("bad_rawlogs");
  const std::string& dir = dir_tmp.str();
  fs::create_directories(dir);
  ExpectRecordingError([&] { OpenRawlogRecording(dir + "/missing.rawlog"); },
                       {dir + "/missing.rawlog", "no such file"});

  WriteText(dir + "/text.rawlog", "this is not a rawlog\n");
  ExpectRecordingError([&] { OpenRawlogRecording(dir + "/text.rawlog"); },
                       {dir + "/text.rawlog", "record 1"});

  const RunData run = MakeRun(3, 8);
  WriteRun(OpenRawlogWriter(dir + "/whole.rawlog", run.info).get(), run);
  const std::string whole = ReadText(dir + "/whole.rawlog");
  WriteText(dir + "/cut.rawlog", whole.substr(0, whole.size() / 2));
  ExpectRecordingError([&] { OpenRawlogRecording(dir + "/cut.rawlog"); },
                       {dir + "/cut.rawlog", "record "});

  // One that crashes MRPT's own deserialiser (tests/fuzz/known_crashes/): in a child process.
  const std::string crash = std::string(SLAMO_SOURCE_DIR) +
                            "/tests/fuzz/known_crashes/mrpt_action_robot_movement_2d_segv.rawlog";
  ExpectRecordingError([&] { OpenRawlogRecording(crash); },
                       {crash, "MRPT's rawlog deserialiser", "record 1"});
}

// A rawlog of one 4x3 scan, changed by `change` before it is written.
void WriteScanRawlog(const std::string& path,
                     const std::function<void(mrpt::obs::CObservation3DRangeScan&)>& change) {
  mrpt::obs::CObservation3DRangeScan scan;
  scan.timestamp = mrpt::Clock::fromDouble(1.0);
  scan.hasRangeImage = true;
  scan.range_is_depth = true;
  scan.rangeUnits = 0.001f;
  scan.rangeImage_setSize(3, 4);
  scan.rangeImage.fill(1000);
  scan.hasIntensityImage = true;
  scan.intensityImage =
      mrpt::img::CImage(cv::Mat(3, 4, CV_8UC3, cv::Scalar(1, 2, 3)), mrpt::img::DEEP_COPY);
  change(scan);
  scan.cameraParams.ncols = static_cast<uint32_t>(scan.rangeImage.cols());
  scan.cameraParams.nrows = static_cast<uint32_t>(scan.rangeImage.rows());
  scan.cameraParamsIntensity = scan.cameraParams;
  mrpt::io::CFileGZOutputStream file(path);
  auto archive = mrpt::serialization::archiveFrom(file);
  archive << scan;
}

TEST(RecordingTest, RawlogScansOtherThanRegisteredDepthAndColourAreRejected) {
  const TempPath dir_tmp("scan_rawlogs");
  const std::string& dir = dir_tmp.str();
  fs::create_directories(dir);
  const std::string good = dir + "/good.rawlog";
  WriteScanRawlog(good, [](auto&) {});
  auto reader = OpenRawlogRecording(good);
  const std::optional<RgbdFrame> frame = reader->Grab();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->depth_mm.at<uint16_t>(2, 3), 1000);
  EXPECT_EQ(frame->colour.at<cv::Vec3b>(2, 3), cv::Vec3b(1, 2, 3));

  const std::vector<
      std::pair<std::function<void(mrpt::obs::CObservation3DRangeScan&)>, std::string>>
      cases = {
          {[](auto& s) { s.hasRangeImage = false; }, "without a depth image"},
          {[](auto& s) { s.rangeImage_setSize(0, 0); }, "an empty depth image"},
          {[](auto& s) { s.range_is_depth = false; }, "of ranges, not depth"},
          {[](auto& s) { s.hasIntensityImage = false; }, "without an intensity image"},
          {[](auto& s) { s.intensityImage.setExternalStorage("elsewhere.png"); },
           "externally stored images"},
          {[](auto& s) {
             s.intensityImage =
                 mrpt::img::CImage(cv::Mat(2, 4, CV_8UC3, cv::Scalar(0)), mrpt::img::DEEP_COPY);
           },
           "colour must be registered to depth"},
      };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string path = dir + "/bad" + std::to_string(i) + ".rawlog";
    WriteScanRawlog(path, cases[i].first);
    ExpectRecordingError([&] { OpenRawlogRecording(path); }, {path, "record 1", cases[i].second});
  }
}

// ---- The simulator as the recorder ----

// Keeps what it is given, to compare the files with.
class MemoryWriter : public RecordingWriter {
 public:
  void AddFrame(const RgbdFrame& frame) override {
    RgbdFrame copy = frame;
    copy.colour = frame.colour.clone();
    copy.depth_mm = frame.depth_mm.clone();
    run.frames.push_back(copy);
  }
  void AddEncoders(const EncoderTicks& ticks) override { run.encoders.push_back(ticks); }
  void AddGroundTruth(const StampedPose& pose) override { run.truth.push_back(pose); }
  void Close() override {}
  const std::string& path() const override { return path_; }

  RunData run;

 private:
  std::string path_ = "memory";
};

TEST(RecordingTest, SimulatorWritesBothFormats) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  const TempPath dir_tmp("sim");
  const std::string& dir = dir_tmp.str();
  RecordingInfo info = RecordingInfoFor(robot);
  info.source = "sim";
  MemoryWriter memory;
  memory.run.info = info;
  auto tum = OpenTumWriter(dir, info);
  auto rawlog = OpenRawlogWriter(dir + "/recording.rawlog", info);
  SimRecordingOptions options;
  options.seed = 1;
  options.start = Pose2D{-0.9, -0.6, 0.0};
  options.script = "forward 0.1";
  options.fps = 5.0;
  int progress_calls = 0;
  const SimRecordingSummary summary =
      RecordSimulatedRun(season, robot, options, {&memory, tum.get(), rawlog.get()},
                         [&](const SimRecordingSummary&, double) { ++progress_calls; });
  tum->Close();
  rawlog->Close();

  ASSERT_EQ(summary.steps.size(), 1u);
  EXPECT_EQ(summary.steps[0].status, DriveStepStatus::kDone);
  // A frame at t = 0 and every 0.2 s after; readings every 20 ms control step.
  EXPECT_EQ(summary.frames, static_cast<int>(std::floor(summary.duration_s * 5.0 + 1e-6)) + 1);
  EXPECT_EQ(progress_calls, summary.frames);
  ASSERT_EQ(static_cast<int>(memory.run.frames.size()), summary.frames);
  EXPECT_EQ(memory.run.frames[0].t_s, 0.0);
  for (size_t k = 1; k < memory.run.frames.size(); ++k) {
    EXPECT_NEAR(memory.run.frames[k].t_s - memory.run.frames[k - 1].t_s, 0.2, 1e-9);
  }
  EXPECT_EQ(static_cast<int>(memory.run.encoders.size()), summary.encoder_readings);
  EXPECT_NEAR(summary.encoder_readings, summary.duration_s / 0.02 + 1, 1.0);
  // The robot drove about 0.1 m forward; the encoders counted it (and some slip).
  const double metres_per_tick = info.metres_per_tick;
  const EncoderTicks& last = memory.run.encoders.back();
  EXPECT_NEAR(0.5 * (last.left + last.right) * metres_per_tick, 0.1, 0.03);
  const Pose2D& end = memory.run.truth.back().pose;
  EXPECT_NEAR(end.x_m - options.start.x_m, 0.1, 0.04);
  EXPECT_GT(cv::countNonZero(memory.run.frames.back().depth_mm), 1000) << "the camera sees";

  // Both files read back exactly what was recorded.
  ExpectSameRun(memory.run, OpenTumRecording(dir).get());
  ExpectSameRun(memory.run, OpenRawlogRecording(dir + "/recording.rawlog").get());
  EXPECT_TRUE(fs::exists(fs::path(dir) / "rgb/0.000000.png"));
  EXPECT_TRUE(fs::exists(fs::path(dir) / "depth/0.000000.png"));
}

TEST(RecordingTest, SimulatorRejectsABadScript) {
  const field::SeasonConfig season = field::LoadSeasonConfig("toss_up");
  const field::RobotConfig robot = field::LoadRobotConfig("thesis_robot");
  SimRecordingOptions options;
  options.script = "forwrd 0.1";
  EXPECT_THROW(RecordSimulatedRun(season, robot, options, {}), DriveScriptError);
  options.script = "forward 0.1";
  options.fps = 0.0;
  EXPECT_THROW(RecordSimulatedRun(season, robot, options, {}), RecordingError);
}

}  // namespace
}  // namespace slamo::platform
