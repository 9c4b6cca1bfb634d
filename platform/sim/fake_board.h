// A stand-in for the motor-controller board: the firmware's own logic
// (platform/firmware/board_logic.h: protocol, PID speed loop, link watchdog) driving the
// simulator's motor model (SimDriveBase in raw-PWM mode: PWM curve, motor lag, slip, encoder
// quantisation), so the host sees realistic encoder ticks. Faults can be injected on the
// link, per frame and in both directions: garbage bytes, dropped and duplicated frames,
// delays, and unplugging.
//
// FakeBoard itself does no I/O and has no clock: its owner hands it the host's bytes, calls
// Advance(dt_s) and collects the bytes for the host, so tests run it on simulated time.
// PtyFakeBoard puts it on a pseudo-terminal for the real serial stack.
#pragma once

#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include "field_configs/robot_config.h"
#include "platform/firmware/board_logic.h"
#include "platform/serial_protocol.h"
#include "platform/sim/sim_drive.h"

namespace slamo::platform {

struct LinkFaults {
  double drop_probability = 0.0;       // each frame, each direction
  double duplicate_probability = 0.0;  // each frame is sent twice
  double garbage_probability = 0.0;    // random bytes (1-16, start bytes likely) before a frame
  double delay_s = 0.0;                // added to every frame, each direction
  double delay_jitter_s = 0.0;         // plus uniform [0, jitter) (order is kept)
};

struct FakeBoardOptions {
  SimDriveOptions drive;  // the motor model
  LinkFaults faults;
  uint64_t seed = 1;
  double loop_period_s = 0.001;  // the board's main loop
};

// The board configuration for a robot's drive (PWM convention, gains, encoder scale, speed).
slamo_fw::BoardConfig BoardConfigFromDrive(const field::DriveConfig& drive);

struct FakeBoardStats {
  uint64_t frames_to_board = 0;
  uint64_t frames_to_host = 0;
  uint64_t dropped = 0;
  uint64_t duplicated = 0;
  uint64_t garbage_bursts = 0;
  uint64_t bytes_lost_unplugged = 0;
};

class FakeBoard {
 public:
  FakeBoard(const field::DriveConfig& drive, const FakeBoardOptions& options);

  // Bytes from the host, arriving at the board's current time (lost while unplugged).
  void Receive(const uint8_t* data, size_t n);
  void Receive(const std::vector<uint8_t>& data) { Receive(data.data(), data.size()); }
  // Runs the board loop and the motors for dt_s (in loop_period_s steps).
  void Advance(double dt_s);
  // Bytes for the host that have arrived by now.
  std::vector<uint8_t> TakeOutput();

  // The cable: while unplugged nothing passes either way and queued bytes are lost. The
  // board keeps running (powered from the robot); Replug(true) models a USB-powered board
  // that restarts (counts from 0, stopped, link down).
  void Unplug();
  void Replug(bool reset_board = false);
  bool plugged() const { return plugged_; }

  void set_faults(const LinkFaults& faults) { options_.faults = faults; }
  double time_s() const { return time_s_; }
  uint32_t time_us() const;
  const slamo_fw::BoardLogic& logic() const { return logic_; }
  const SimDriveBase& motors() const { return sim_; }
  const FakeBoardStats& stats() const { return stats_; }
  // The cumulative counts the board last read (from 0 at its last reset).
  const EncoderTicks& board_ticks() const { return board_ticks_; }
  // Board time of the last PWM change to stop on both sides (motors commanded stopped).
  double last_stop_s() const { return last_stop_s_; }

 private:
  struct Pending {
    double due_s;
    std::vector<uint8_t> bytes;
  };
  // Splits a byte stream into frames and queues them with the faults applied.
  void Inject(serial::Parser* splitter, const uint8_t* data, size_t n, std::deque<Pending>* queue,
              uint64_t* frame_count);
  void Step(double dt_s);

  field::DriveConfig drive_;
  FakeBoardOptions options_;
  slamo_fw::BoardLogic logic_;
  SimDriveBase sim_;
  std::mt19937_64 rng_;
  double time_s_ = 0.0;
  double loop_debt_s_ = 0.0;
  bool plugged_ = true;
  serial::Parser to_board_splitter_;
  serial::Parser to_host_splitter_;
  std::deque<Pending> to_board_;
  std::deque<Pending> to_host_;
  FakeBoardStats stats_;
  int64_t tick_base_left_ = 0;  // counts at the last reset (the board restarts from 0)
  int64_t tick_base_right_ = 0;
  double last_stop_s_ = 0.0;
  bool was_stopped_ = true;
  EncoderTicks board_ticks_;
};

// A FakeBoard on a pseudo-terminal. The host opens slave_path() (or link_path, a symlink kept
// pointing at the current slave, like /dev/serial/by-id). Unplug() closes the pty (the host
// sees a hang-up); Replug() opens a new one and moves the symlink.
class PtyFakeBoard {
 public:
  PtyFakeBoard(const field::DriveConfig& drive, const FakeBoardOptions& options,
               std::string link_path = "");
  ~PtyFakeBoard();
  PtyFakeBoard(const PtyFakeBoard&) = delete;
  PtyFakeBoard& operator=(const PtyFakeBoard&) = delete;

  // Moves bytes between the pty and the board and advances the board by dt_s. Never blocks.
  void Pump(double dt_s);
  void Unplug();
  void Replug(bool reset_board = false);

  const std::string& slave_path() const { return slave_path_; }
  const std::string& link_path() const { return link_path_; }
  // The path a host should open: the symlink when there is one.
  const std::string& device_path() const { return link_path_.empty() ? slave_path_ : link_path_; }
  FakeBoard& board() { return board_; }
  uint64_t bytes_overflowed() const { return bytes_overflowed_; }

 private:
  void OpenPty();
  void ClosePty();

  FakeBoard board_;
  std::string link_path_;
  std::string slave_path_;
  int master_fd_ = -1;
  int slave_fd_ = -1;  // kept open so the master does not see EIO while the host reopens
  std::vector<uint8_t> pending_out_;
  uint64_t bytes_overflowed_ = 0;
};

}  // namespace slamo::platform
