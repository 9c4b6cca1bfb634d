// Writes small seed corpora for the fuzz targets (scripts/fuzz runs it):
//   make_seeds DIR  ->  DIR/protocol/*, DIR/replay_text/*, DIR/replay_rawlog/*
// (the field-config corpus is the shipped YAML files, copied by the script).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <mrpt/core/Clock.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>

#include "mapping/replay_log.h"
#include "platform/serial_protocol.h"

namespace {

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seeds DIR\n");
    return 2;
  }
  namespace fs = std::filesystem;
  using namespace slamo::platform::serial;
  const fs::path dir = argv[1];
  for (const char* sub : {"protocol", "replay_text", "replay_rawlog"}) {
    fs::create_directories(dir / sub);
  }

  // Protocol: each message alone, then a stream of all of them with garbage between.
  const std::vector<Message> messages = {SetSpeed{67, -67},
                                         SetPwm{40, 140},
                                         Stop{},
                                         SetPid{60000, 300000, 0, 60000},
                                         HostHeartbeat{1},
                                         Encoders{20000, 100, -100, 70, 110, SLAMO_FLAG_SPEED_MODE},
                                         BoardHeartbeat{1, 20000, 0, 0},
                                         Ack{SLAMO_MSG_STOP, 3},
                                         Error{1, 0x81, 4}};
  std::vector<uint8_t> stream = {7};  // chunk-size byte
  for (size_t i = 0; i < messages.size(); ++i) {
    std::vector<uint8_t> one = {static_cast<uint8_t>(i)};
    const std::vector<uint8_t> frame = Encode(messages[i], static_cast<uint8_t>(i));
    one.insert(one.end(), frame.begin(), frame.end());
    WriteBytes((dir / "protocol" / ("msg" + std::to_string(i))).string(), one);
    stream.insert(stream.end(), {0x00, kFrameStart, 0x13});
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  WriteBytes((dir / "protocol" / "stream").string(), stream);

  // Replay logs: a short run, both formats.
  slamo::mapping::ReplayLog log;
  log.start_pose = Eigen::Vector3d(0.1, -0.2, 0.3);
  for (int k = 0; k < 4; ++k) {
    slamo::mapping::LogEvent odom;
    odom.t_s = 1.0 * k;
    odom.data = slamo::mapping::OdometryStep{0.3, 0.001, 0.01};
    log.events.push_back(odom);
    slamo::mapping::LogEvent obs;
    obs.t_s = 1.0 * k + 0.5;
    slamo::mapping::RangeBearing rb;
    rb.range_m = 1.5 - 0.3 * k;
    rb.bearing_rad = 0.2 * k;
    rb.id = k % 2;
    obs.data = rb;
    log.events.push_back(obs);
  }
  slamo::mapping::WriteTextLog((dir / "replay_text" / "run.log").string(), log);
  const fs::path rawlog = dir / "replay_rawlog" / "run.rawlog";
  slamo::mapping::WriteRawlog(rawlog.string(), log);
  // The same records uncompressed (MRPT reads both): mutations of the gzip stream mostly
  // exercise zlib's checks, of these the deserialisers.
  {
    mrpt::io::CFileGZInputStream in(rawlog.string());
    std::vector<uint8_t> bytes;
    uint8_t buffer[4096];
    for (size_t n; (n = in.Read(buffer, sizeof(buffer))) > 0;) {
      bytes.insert(bytes.end(), buffer, buffer + n);
    }
    WriteBytes((dir / "replay_rawlog" / "run_plain.rawlog").string(), bytes);
  }
  // The observations-only layout, uncompressed: absolute odometry, and a bearing-range
  // observation with per-landmark covariances.
  {
    mrpt::io::CFileOutputStream out((dir / "replay_rawlog" / "observations.rawlog").string());
    auto archive = mrpt::serialization::archiveFrom(out);
    mrpt::obs::CObservationOdometry odometry;
    odometry.timestamp = mrpt::Clock::fromDouble(1.0);
    odometry.odometry = mrpt::poses::CPose2D(0.3, 0.1, 0.2);
    archive << odometry;
    mrpt::obs::CObservationBearingRange o;
    o.timestamp = mrpt::Clock::fromDouble(1.5);
    o.validCovariances = true;
    mrpt::obs::CObservationBearingRange::TMeasurement m;
    m.range = 1.5f;
    m.yaw = 0.2f;
    m.pitch = 0.0f;  // MRPT leaves a measurement's fields uninitialised
    m.landmarkID = 4;
    m.covariance.setZero();
    m.covariance(0, 0) = 0.01;
    m.covariance(1, 1) = 0.0004;
    o.sensedData.push_back(m);
    archive << o;
  }
  std::ofstream((dir / "replay_text" / "velocity.log").string())
      << "# velocity form\nstart 0 0 0\nodom 0.0 0.1 0.0\nodom 1.0 0.1 0.5\n"
         "obs 1.5 -1 2.0 0.1 0.05 0.01\n";
  std::printf("seeds in %s\n", dir.string().c_str());
  return 0;
}
