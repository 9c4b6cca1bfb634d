#include "autonomy/io/robot_rig.h"

#include <unistd.h>

#include <chrono>
#include <iostream>
#include <thread>
#include <utility>

#include "platform/openni2_camera.h"

namespace slamo::autonomy {

Rig::Rig(const RigOptions& options, const field::SeasonConfig& season,
         const field::RobotConfig& robot, const platform::Pose2D& start)
    : options_(options) {
  if (options_.port.empty() == !options_.fake_board)
    throw RigError(2, "give the board's serial device (--port DEV) or --fake-board");
  std::string& camera = options_.camera;
  if (camera.empty()) camera = !options_.recording.empty() ? "recording" : "openni2";
  if (camera == "recording" && options_.recording.empty())
    throw RigError(2, "--camera recording needs --recording PATH");
  if (camera == "sim" && !options_.fake_board) {
    throw RigError(2,
                   "--camera sim renders the simulated field from the fake board's motors: it "
                   "needs --fake-board");
  }
  if (camera != "recording" && camera != "openni2" && camera != "sim")
    throw RigError(2, "--camera: expected openni2, recording or sim, got \"" + camera + "\"");

  // The clock: the machine's on the robot; simulated with the fake board unless real_time.
  sim_time_ = options_.fake_board && !options_.real_time;
  base_clock_ = sim_time_ ? static_cast<const platform::Clock*>(&simulated_) : &steady_;

  // The board: on its serial device, or the fake one on a pseudo-terminal in this process.
  device_ = options_.port;
  if (options_.fake_board) {
    platform::FakeBoardOptions fake;
    fake.seed = options_.seed;
    fake.faults = options_.faults;
    fake_ = std::make_unique<platform::PtyFakeBoard>(robot.drive, fake);
    device_ = fake_->device_path();
  }
  platform::SerialDriveOptions link;
  link.pid = robot.drive.pid;
  board_ = std::make_unique<platform::SerialDriveBase>(
      platform::MakeMrptSerialTransport(device_, options_.baud), *base_clock_, link);
  options_.io.board_name = options_.fake_board ? "fake board on " + device_ : device_;

  // The camera.
  std::unique_ptr<platform::RecordingReader> reader;
  try {
    if (camera == "recording") {
      reader = platform::OpenRecording(options_.recording);
      options_.io.camera_name = "recording " + options_.recording;
    } else if (camera == "sim") {
      sim_camera_ = std::make_unique<FakeBoardCamera>(season, robot, fake_->board(), start,
                                                      *base_clock_, options_.seed);
      options_.io.camera_name = "simulated field seen from the fake board's motors";
      options_.io.truth = [this]() { return Truth(); };
    } else {
      openni2_ = std::make_unique<platform::OpenNI2Camera>(robot.camera);
      options_.io.camera_name = "openni2 " + robot.camera.model;
    }
  } catch (const platform::RecordingError& e) {
    throw RigError(2, e.what());
  } catch (const platform::CameraError& e) {
    throw RigError(3, e.what());
  }
  io_ = std::make_unique<HardwareIo>(
      board_.get(), &forward_, *base_clock_, [this](double dt_s) { Pace(dt_s); }, options_.io);
  io_view_ = io_.get();
  // A recorded stream plays against the match clock, which starts with the HardwareIo.
  if (reader)
    stream_ =
        std::make_unique<RecordedStreamCamera>(std::move(reader), io_->clock(), options_.loop);
}

Rig::~Rig() = default;

void Rig::SetRecorder(platform::RecordingWriter* recorder) {
  if (io_view_) io_view_->set_recorder(recorder);
}

void Rig::Connect() {
  if (!io_view_->Connect()) {
    throw RigError(1, "the board on " + device_ + " did not answer within " +
                          std::to_string(options_.io.connect_timeout_s) + " s (link " +
                          platform::LinkStateName(board_->link_state()) +
                          "); check the cable and `slamo board ping --port " + device_ + "`");
  }
}

std::unique_ptr<HardwareIo> Rig::TakeIo() { return std::move(io_); }

std::optional<platform::Pose2D> Rig::Truth() const {
  if (!sim_camera_) return std::nullopt;
  return sim_camera_->Truth();
}

void Rig::Pace(double dt_s) {
  if (fake_) {
    fake_->Pump(dt_s);
    const double now_s = base_clock_->NowS();
    if (options_.unplug_at_s >= 0 && !unplugged_ && now_s >= options_.unplug_at_s) {
      fake_->Unplug();
      unplugged_ = true;
      std::cout << "  [board clock " << now_s << " s] fake board unplugged" << std::endl;
    }
    if (unplugged_ && !replugged_ && options_.replug_at_s >= 0 && now_s >= options_.replug_at_s) {
      fake_->Replug();
      replugged_ = true;
      std::cout << "  [board clock " << now_s << " s] fake board plugged in again" << std::endl;
    }
  }
  if (sim_time_) {
    // The kernel passes the pty's bytes on in its own time: give it a moment per step.
    ::usleep(150);
    simulated_.Advance(dt_s);
  } else {
    std::this_thread::sleep_for(std::chrono::duration<double>(dt_s));
  }
}

std::optional<platform::RgbdFrame> Rig::Grab() {
  if (stream_) return stream_->Grab();
  if (sim_camera_) return sim_camera_->Grab();
  return openni2_->Grab();
}

}  // namespace slamo::autonomy
