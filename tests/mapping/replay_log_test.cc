#include "mapping/replay_log.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <iterator>
#include <random>

#include <mrpt/core/Clock.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>

#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"

namespace slamo::mapping {
namespace {

std::string TempPath(const std::string& name) { return testing::TempDir() + "/" + name; }

void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A recorded run with its truth: two laps of a 2 m square at 0.5 m/s (10 Hz), turning on the
// spot at the corners, seeing four landmarks with known ids; noisy odometry and measurements
// from a fixed seed.
struct SquareRun {
  ReplayLog log;
  std::vector<TimedPose> truth;
  std::vector<TimedPose> dead_reckoning;
  std::vector<LandmarkPoint> landmarks = {
      {0, 1.0, -1.0}, {1, 3.0, 1.0}, {2, 1.0, 3.0}, {3, -1.0, 1.0}};
};

SquareRun MakeSquareRun(int seed, bool known_ids = true) {
  SquareRun run;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double sigma_range = 0.02, sigma_bearing = 0.01;
  Eigen::Vector3d pose = Eigen::Vector3d::Zero(), odometry_pose = pose;
  double t = 0.0;
  int step_index = 0;
  auto step = [&](double dx, double dtheta) {
    t += 0.1;
    pose = EkfSlam::Move(pose, {dx, 0.0, dtheta}, nullptr, nullptr);
    // Odometry: a few per cent scale error per step, a little slip.
    const OdometryStep measured{dx * (1.0 + 0.03 * n01(rng)) + 0.002 * n01(rng), 0.001 * n01(rng),
                                dtheta * (1.0 + 0.02 * n01(rng)) + 0.003 * n01(rng)};
    odometry_pose = EkfSlam::Move(odometry_pose, measured, nullptr, nullptr);
    run.log.events.push_back({t, measured});
    run.truth.push_back({t, pose.x(), pose.y(), pose.z()});
    run.dead_reckoning.push_back({t, odometry_pose.x(), odometry_pose.y(), odometry_pose.z()});
    if (++step_index % 3 != 0) return;
    for (const LandmarkPoint& l : run.landmarks) {
      const Eigen::Vector2d h = EkfSlam::Observe(pose, Eigen::Vector2d(l.x_m, l.y_m));
      if (h.x() > 4.0) continue;
      RangeBearing z;
      z.range_m = h.x() + sigma_range * n01(rng);
      z.bearing_rad = std::remainder(h.y() + sigma_bearing * n01(rng), 2.0 * M_PI);
      z.covariance =
          Eigen::Vector2d(sigma_range * sigma_range, sigma_bearing * sigma_bearing).asDiagonal();
      z.id = known_ids ? l.id : -1;
      run.log.events.push_back({t, z});
    }
  };
  for (int lap = 0; lap < 2; ++lap) {
    for (int side = 0; side < 4; ++side) {
      for (int i = 0; i < 40; ++i) step(0.05, 0.0);
      for (int i = 0; i < 10; ++i) step(0.0, M_PI / 20.0);
    }
  }
  return run;
}

struct ReplayResult {
  std::vector<TimedPose> trajectory;
  std::vector<LandmarkPoint> landmarks;
};

ReplayResult Replay(const ReplayLog& log) {
  EkfSlam ekf(log.start_pose.value_or(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity() * 1e-6);
  ReplayResult result;
  for (const LogEvent& e : log.events) {
    if (e.is_odometry()) {
      ekf.Predict(e.odometry());
      result.trajectory.push_back({e.t_s, ekf.pose().x(), ekf.pose().y(), ekf.pose().z()});
    } else {
      ekf.Update(e.measurement());
    }
  }
  for (int i = 0; i < ekf.landmark_count(); ++i) {
    result.landmarks.push_back({ekf.landmark_id(i), ekf.landmark(i).x(), ekf.landmark(i).y()});
  }
  return result;
}

void ExpectSameEvents(const std::vector<LogEvent>& a, const std::vector<LogEvent>& b,
                      double tolerance) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("event " + std::to_string(i));
    EXPECT_NEAR(a[i].t_s, b[i].t_s, 1e-6);
    ASSERT_EQ(a[i].is_odometry(), b[i].is_odometry());
    if (a[i].is_odometry()) {
      EXPECT_NEAR(a[i].odometry().dx_m, b[i].odometry().dx_m, 1e-9);
      EXPECT_NEAR(a[i].odometry().dy_m, b[i].odometry().dy_m, 1e-9);
      EXPECT_NEAR(a[i].odometry().dtheta_rad, b[i].odometry().dtheta_rad, 1e-9);
    } else {
      const RangeBearing &za = a[i].measurement(), &zb = b[i].measurement();
      EXPECT_EQ(za.id, zb.id);
      EXPECT_NEAR(za.range_m, zb.range_m, tolerance);
      EXPECT_NEAR(za.bearing_rad, zb.bearing_rad, tolerance);
      EXPECT_NEAR((za.covariance - zb.covariance).norm() / za.covariance.norm(), 0.0, 1e-5);
    }
  }
}

// ---- Text logs ----

TEST(TextLogTest, ReadsBothOdometryFormsObservationsAndTheStart) {
  const std::string path = TempPath("forms.log");
  WriteFile(path,
            "# a run\n"
            "start 1.0 -0.5 0.25\n"
            "\n"
            "odom 0.0 0.5 0.1      # velocity form: the first line is a zero step\n"
            "odom 0.5 0.5 0.2\n"
            "odom 0.5 0.1 -0.02 0.03\n"
            "obs 0.6 4 1.5 -0.3\n"
            "obs 0.6 -1 2.5 0.7 0.1 0.05\n");
  ReplayLogOptions options;
  options.sigma_range_m = 0.2;
  const ReplayLog log = ReadTextLog(path, options);
  ASSERT_TRUE(log.start_pose);
  EXPECT_EQ(*log.start_pose, Eigen::Vector3d(1.0, -0.5, 0.25));
  ASSERT_EQ(log.events.size(), 5u);
  EXPECT_EQ(log.events[0].odometry().dx_m, 0.0);
  EXPECT_DOUBLE_EQ(log.events[1].odometry().dx_m, 0.25);
  EXPECT_DOUBLE_EQ(log.events[1].odometry().dtheta_rad, 0.1);
  EXPECT_EQ(log.events[2].odometry().dy_m, -0.02);
  EXPECT_EQ(log.events[3].measurement().id, 4);
  EXPECT_DOUBLE_EQ(log.events[3].measurement().covariance(0, 0), 0.04);
  EXPECT_EQ(log.events[4].measurement().id, -1);
  EXPECT_DOUBLE_EQ(log.events[4].measurement().covariance(1, 1), 0.0025);
  EXPECT_DOUBLE_EQ(log.events[4].t_s, 0.6);
}

TEST(TextLogTest, BadLinesNameTheFileAndLine) {
  struct Case {
    const char* name;
    std::string text;
    int line;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"truncated", "odom 0 0.1 0 0\nobs 0.1 2 1.5\n", 2, "truncated"},
      {"nan", "# header\nodom 0 0.1 0 0\nodom 0.1 nan 0 0\n", 3, "not finite"},
      {"inf", "odom 0 0.1 0 inf\n", 1, "not finite"},
      {"word", "odom 0 0.1 0 0\nodom 0.1 0.1 zero 0\n", 2, "not a number"},
      {"unknown_tag", "odom 0 0.1 0 0\n\nlidar 0.1 3\n", 3, "unknown tag `lidar`"},
      {"backwards", "odom 1.0 0.1 0 0\nobs 1.0 1 2 0\nodom 0.9 0.1 0 0\n", 3, "backwards"},
      {"extra", "obs 0 1 2 0 0.1 0.1 7\n", 1, "too many"},
      {"bad_id", "obs 0 1.5 2 0\n", 1, "id"},
      {"late_start", "odom 0 0 0 0\nstart 0 0 0\n", 2, "start"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = TempPath(std::string("bad_") + c.name + ".log");
    WriteFile(path, c.text);
    try {
      ReadTextLog(path);
      ADD_FAILURE() << "expected an error";
    } catch (const ReplayLogError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path + ":" + std::to_string(c.line) + ":"), std::string::npos) << what;
      EXPECT_NE(what.find(c.says), std::string::npos) << what;
    }
  }
  EXPECT_THROW(ReadTextLog(TempPath("does_not_exist.log")), ReplayLogError);
}

TEST(TextLogTest, WriterRoundTrip) {
  SquareRun run = MakeSquareRun(3);
  run.log.start_pose = Eigen::Vector3d(0.1, 0.2, -0.3);
  const std::string path = TempPath("round_trip.log");
  WriteTextLog(path, run.log);
  const ReplayLog read = ReadTextLog(path);
  ASSERT_TRUE(read.start_pose);
  EXPECT_NEAR((*read.start_pose - *run.log.start_pose).norm(), 0.0, 1e-12);
  ExpectSameEvents(run.log.events, read.events, 1e-9);
}

// The whole chain: a generated run written as a text log, read back and replayed through the
// EKF, scored with the TUM metrics.
TEST(ReplayTest, SquareRunThroughEkfSlam) {
  for (bool known_ids : {true, false}) {
    SCOPED_TRACE(known_ids ? "known ids" : "associated");
    const SquareRun run = MakeSquareRun(1, known_ids);
    const std::string path = TempPath("square.log");
    WriteTextLog(path, run.log);
    const ReplayResult result = Replay(ReadReplayLog(path));

    ASSERT_EQ(result.trajectory.size(), run.truth.size());
    const AteResult ate = AbsoluteTrajectoryError(run.truth, result.trajectory);
    const AteResult dead_reckoning = AbsoluteTrajectoryError(run.truth, run.dead_reckoning);
    EXPECT_EQ(ate.pairs, static_cast<int>(run.truth.size()));
    EXPECT_LT(ate.rmse_m, 0.05);
    EXPECT_LT(ate.rmse_m, 0.5 * dead_reckoning.rmse_m);

    EXPECT_EQ(result.landmarks.size(), 4u);
    const LandmarkError map = LandmarkRmse(run.landmarks, result.landmarks, ate.alignment);
    EXPECT_EQ(map.pairs, 4);
    EXPECT_LT(map.rmse_m, 0.05);
  }
}

// ---- MRPT rawlogs ----

TEST(RawlogTest, WrittenAndReadBackGivesTheSameEvents) {
  SquareRun run = MakeSquareRun(2);
  // A measurement before the first step and two steps in a row, which the layout must carry.
  RangeBearing first;
  first.range_m = 1.25;
  first.bearing_rad = -2.5;
  first.id = 9;
  first.covariance << 0.01, 0.001, 0.001, 0.002;
  run.log.events.insert(run.log.events.begin(), LogEvent{0.0, first});
  run.log.events.insert(run.log.events.begin() + 1, LogEvent{0.05, OdometryStep{0.01, 0, 0}});
  const std::string path = TempPath("square.rawlog");
  WriteRawlog(path, run.log);
  ExpectSameEvents(run.log.events, ReadRawlog(path).events, 1e-5);
  // Recognised by name and by content.
  ExpectSameEvents(run.log.events, ReadReplayLog(path).events, 1e-5);
  const std::string renamed = TempPath("square_rawlog.bin");
  WriteRawlog(renamed, run.log);
  ExpectSameEvents(run.log.events, ReadReplayLog(renamed).events, 1e-5);
}

TEST(RawlogTest, BearingRangeIsMovedFromTheSensorToTheRobotCentre) {
  const std::string path = TempPath("offset.rawlog");
  {
    mrpt::io::CFileGZOutputStream file(path);
    auto archive = mrpt::serialization::archiveFrom(file);
    mrpt::obs::CObservationBearingRange o;
    o.timestamp = mrpt::Clock::fromDouble(2.0);
    // A sensor 0.2 m left of the centre looking left; sees a landmark 1 m straight ahead of it.
    o.sensorLocationOnRobot = mrpt::poses::CPose3D(0.0, 0.2, 0.0, M_PI / 2, 0.0, 0.0);
    o.sensor_std_range = 0.1f;
    o.sensor_std_yaw = 0.05f;
    mrpt::obs::CObservationBearingRange::TMeasurement m;
    m.range = 1.0f;
    m.yaw = 0.0f;
    m.pitch = 0.0f;
    m.landmarkID = 5;
    o.sensedData.push_back(m);
    archive << o;  // the observations-only layout
  }
  const ReplayLog log = ReadRawlog(path);
  ASSERT_EQ(log.events.size(), 1u);
  const RangeBearing& z = log.events[0].measurement();
  EXPECT_NEAR(log.events[0].t_s, 2.0, 1e-6);
  EXPECT_EQ(z.id, 5);
  EXPECT_NEAR(z.range_m, 1.2, 1e-6);
  EXPECT_NEAR(z.bearing_rad, M_PI / 2, 1e-6);
  // Along the line of sight: range sigma unchanged; across it, 1 m of arc at 1.2 m.
  EXPECT_NEAR(z.covariance(0, 0), 0.01, 1e-7);
  EXPECT_NEAR(std::sqrt(z.covariance(1, 1)), 0.05 / 1.2, 1e-7);
}

// The bytes of an uncompressed rawlog of one bearing-range observation with a covariance.
std::string BearingRangeRawlogBytes(bool valid_covariances) {
  const std::string path = TempPath("flag.rawlog");
  {
    mrpt::io::CFileOutputStream file(path);
    auto archive = mrpt::serialization::archiveFrom(file);
    mrpt::obs::CObservationBearingRange o;
    o.timestamp = mrpt::Clock::fromDouble(1.0);
    o.validCovariances = valid_covariances;
    o.sensor_std_range = 0.1f;
    o.sensor_std_yaw = 0.05f;
    mrpt::obs::CObservationBearingRange::TMeasurement m;
    m.range = 2.0f;
    m.yaw = 0.0f;  // MRPT leaves a measurement's fields uninitialised
    m.pitch = 0.0f;
    m.landmarkID = 3;
    m.covariance.setZero();
    m.covariance(0, 0) = 0.04;
    m.covariance(1, 1) = 0.0009;
    m.covariance(2, 2) = 0.0009;
    o.sensedData.push_back(m);
    archive << o;
  }
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// MRPT reads a bool's byte from the file into the bool unchecked (found by
// replay_rawlog_fuzzer: "load of value 78, which is not a valid value for type 'bool'" under
// UBSan). Any non-zero byte means true, and the sanitizer build stays quiet.
TEST(RawlogTest, AFlagByteOtherThanZeroOrOneReadsAsTrue) {
  // MRPT writes the flag, then the sensor's sigmas (flag off) or each entry's covariance (on):
  // the first byte where the two files differ is the flag's.
  const std::string off = BearingRangeRawlogBytes(false);
  std::string corrupt = BearingRangeRawlogBytes(true);
  const size_t flag = static_cast<size_t>(
      std::mismatch(off.begin(), off.end(), corrupt.begin(), corrupt.end()).first - off.begin());
  ASSERT_LT(flag, off.size());
  ASSERT_EQ(off[flag], 0);
  ASSERT_EQ(corrupt[flag], 1);
  corrupt[flag] = 78;
  const std::string path = TempPath("flag78.rawlog");
  WriteFile(path, corrupt);
  const ReplayLog log = ReadRawlog(path);
  ASSERT_EQ(log.events.size(), 1u);
  const RangeBearing& z = log.events[0].measurement();
  EXPECT_EQ(z.id, 3);
  // The file's covariance (0.2 m, 0.03 rad), not the sensor's sigmas (0.1 m, 0.05 rad).
  EXPECT_NEAR(z.covariance(0, 0), 0.04, 1e-9);
  EXPECT_NEAR(z.covariance(1, 1), 0.0009, 1e-9);
}

void ExpectRawlogError(const std::string& path, const std::string& says) {
  try {
    ReadRawlog(path);
    ADD_FAILURE() << "expected an error for " << path;
  } catch (const ReplayLogError& e) {
    EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(RawlogTest, OtherFilesGiveAnErrorNotACrash) {
  // Text.
  const std::string text = TempPath("text.rawlog");
  WriteFile(text, "odom 0 0.1 0 0\nobs 0.1 2 1.5 0.2\n");
  ExpectRawlogError(text, "record 1");
  // Random bytes.
  const std::string noise = TempPath("noise.rawlog");
  {
    std::mt19937 rng(5);
    std::string bytes(4096, '\0');
    for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
    WriteFile(noise, bytes);
  }
  ExpectRawlogError(noise, "record");
  // Another MRPT object.
  const std::string pose = TempPath("pose.rawlog");
  {
    mrpt::io::CFileOutputStream file(pose);
    auto archive = mrpt::serialization::archiveFrom(file);
    archive << mrpt::poses::CPose2D(1.0, 2.0, 0.5);
  }
  ExpectRawlogError(pose, "record 1: a mrpt::poses::CPose2D");
  // A good rawlog cut short.
  const std::string whole = TempPath("whole.rawlog");
  WriteRawlog(whole, MakeSquareRun(4).log);
  std::ifstream in(whole, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string cut = TempPath("cut.rawlog");
  WriteFile(cut, bytes.substr(0, bytes.size() / 2));
  ExpectRawlogError(cut, "record");
  EXPECT_THROW(ReadRawlog(TempPath("missing.rawlog")), ReplayLogError);
}

// A rawlog that crashes MRPT's own deserialiser (found by replay_rawlog_fuzzer): the crash
// happens in a child process and reaches the caller as an error naming the record.
TEST(RawlogTest, ARecordThatCrashesMrptGivesAnErrorNotACrash) {
  const std::string known = std::string(SLAMO_SOURCE_DIR) +
                            "/tests/fuzz/known_crashes/mrpt_action_robot_movement_2d_segv.rawlog";
  ExpectRawlogError(known, "record 1");
  try {
    ReadRawlog(known);
  } catch (const ReplayLogError& e) {
    EXPECT_NE(std::string(e.what()).find("MRPT's rawlog deserialiser"), std::string::npos)
        << e.what();
  }
}

// A rawlog of one odometry movement of MRPT's "Thrun" motion model: MRPT stores the model's
// particle count, not the particles, and draws that many when it reads the record back. A file
// of under 200 bytes can so ask for millions (replay_rawlog_fuzzer's slow inputs: 15 million
// took 10 s under the fuzzer, past its 2 s check, since the check's alarm went to libFuzzer's
// SIGALRM handler).
std::string ThrunMovementRawlog(const std::string& name, uint32_t particles) {
  const std::string path = TempPath(name);
  mrpt::io::CFileOutputStream file(path);
  auto archive = mrpt::serialization::archiveFrom(file);
  mrpt::obs::CActionRobotMovement2D move;
  move.timestamp = mrpt::Clock::fromDouble(1.0);
  move.estimationMethod = mrpt::obs::CActionRobotMovement2D::emOdometry;
  move.rawOdometryIncrementReading = mrpt::poses::CPose2D(0.1, 0.0, 0.01);
  move.motionModelConfiguration.modelSelection = mrpt::obs::CActionRobotMovement2D::mmThrun;
  move.motionModelConfiguration.thrunModel.nParticlesCount = particles;
  mrpt::obs::CActionCollection actions;
  actions.insert(move);
  archive << actions;
  return path;
}

TEST(RawlogTest, AMovementOfMoreThan100000ParticlesIsACorruptCount) {
  // 300 particles (MRPT's default) read as a step; 200000 are refused, naming the count.
  EXPECT_EQ(ReadRawlog(ThrunMovementRawlog("thrun300.rawlog", 300)).events.size(), 1u);
  ExpectRawlogError(ThrunMovementRawlog("thrun200k.rawlog", 200000),
                    "draw more than 100000 particles (a corrupt count?) reading record 1");
}

void IgnoreSignal(int) {}

// The check's time limit holds even when the program handles SIGALRM itself, as libFuzzer
// does: the parent kills the child at the deadline. 15 million particles take MRPT about 4 s
// (and 700 MB); the read must end near the 0.5 s limit instead.
TEST(RawlogTest, TheCheckStopsASlowRecordAtItsDeadlineWhateverTheSignalHandlers) {
  const std::string path = ThrunMovementRawlog("thrun15m.rawlog", 15000000);
  struct sigaction handler = {}, previous = {};
  handler.sa_handler = IgnoreSignal;
  sigemptyset(&handler.sa_mask);
  ASSERT_EQ(sigaction(SIGALRM, &handler, &previous), 0);
  ReplayLogOptions options;
  options.rawlog_check_timeout_s = 0.5;
  const auto start = std::chrono::steady_clock::now();
  try {
    ReadRawlog(path, options);
    ADD_FAILURE() << "expected an error for " << path;
  } catch (const ReplayLogError& e) {
    EXPECT_NE(
        std::string(e.what()).find("took more than 0.5 s (a corrupt count?) reading record 1"),
        std::string::npos)
        << e.what();
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sigaction(SIGALRM, &previous, nullptr);
  EXPECT_LT(elapsed_s, 3.0);
}

}  // namespace
}  // namespace slamo::mapping
