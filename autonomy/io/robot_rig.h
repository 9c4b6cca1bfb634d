// The robot's hardware as `slamo match` and `slamo record` open it: the board (its serial
// device, or the fake board on a pseudo-terminal in this process), the camera (OpenNI2, a
// recorded stream played against the match clock, or the simulated field seen from the fake
// board's motors), the clock and how time passes, behind one HardwareIo.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "autonomy/io/hardware_io.h"
#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "platform/clock.h"
#include "platform/recording.h"
#include "platform/serial_drive_base.h"
#include "platform/sim/fake_board.h"

namespace slamo::autonomy {

struct RigOptions {
  std::string port;  // the board's serial device (or fake_board)
  int baud = 115200;
  bool fake_board = false;
  bool real_time = false;  // with fake_board: the machine's clock, not simulated time
  // openni2 | recording | sim (fake board only); empty: recording when `recording` is set,
  // else openni2.
  std::string camera;
  std::string recording;
  bool loop = false;  // a recorded stream starts again at its end
  uint64_t seed = 1;  // the fake board's and the simulated camera's
  platform::LinkFaults faults;
  double unplug_at_s = -1.0;  // the fake board's cable, on the base clock (< 0: never)
  double replug_at_s = -1.0;
  HardwareIoOptions io;  // alliance, odometry scale, waits (names and truth: filled here)
};

// Options that do not fit together, or hardware that cannot be opened: the message, and the
// exit status a command gives for it (2 bad input, 1 the board, 3 the camera).
class RigError : public std::runtime_error {
 public:
  RigError(int exit_status, const std::string& what)
      : std::runtime_error(what), exit_status(exit_status) {}
  int exit_status;
};

class Rig {
 public:
  // Checks the options and opens the board's port and the camera (throws RigError). `start`
  // is where the robot stands on the field (the simulated camera renders from there).
  Rig(const RigOptions& options, const field::SeasonConfig& season, const field::RobotConfig& robot,
      const platform::Pose2D& start);
  ~Rig();
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  // Records what the HardwareIo sees from now on (not owned; null: nothing).
  void SetRecorder(platform::RecordingWriter* recorder);
  // Services the link until it is up; throws RigError (status 1) after the timeout.
  void Connect();
  // The HardwareIo, once (the rig must outlive it).
  std::unique_ptr<HardwareIo> TakeIo();

  platform::SerialDriveBase& board() { return *board_; }
  platform::PtyFakeBoard* fake() { return fake_.get(); }
  const platform::Clock& base_clock() const { return *base_clock_; }
  // The true pose on the field, where it is known (the fake board's motors).
  std::optional<platform::Pose2D> Truth() const;
  const std::string& board_name() const { return options_.io.board_name; }
  const std::string& camera_name() const { return options_.io.camera_name; }
  const std::string& device() const { return device_; }

 private:
  void Pace(double dt_s);
  std::optional<platform::RgbdFrame> Grab();

  // Forwards the HardwareIo's camera calls to whichever camera the rig opened.
  class ForwardCamera : public platform::RgbdCamera {
   public:
    explicit ForwardCamera(Rig* rig) : rig_(rig) {}
    std::optional<platform::RgbdFrame> Grab() override { return rig_->Grab(); }

   private:
    Rig* rig_;
  };

  RigOptions options_;
  platform::SteadyClock steady_;
  platform::SimClock simulated_;
  const platform::Clock* base_clock_ = nullptr;
  bool sim_time_ = false;
  std::string device_;
  std::unique_ptr<platform::PtyFakeBoard> fake_;
  std::unique_ptr<platform::SerialDriveBase> board_;
  bool unplugged_ = false;
  bool replugged_ = false;
  std::unique_ptr<platform::RgbdCamera> openni2_;
  std::unique_ptr<FakeBoardCamera> sim_camera_;
  std::unique_ptr<RecordedStreamCamera> stream_;
  ForwardCamera forward_{this};
  std::unique_ptr<HardwareIo> io_;
  HardwareIo* io_view_ = nullptr;
};

}  // namespace slamo::autonomy
