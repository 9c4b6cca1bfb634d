// The drive base over a serial link to the motor-controller board (platform/PROTOCOL.md):
// commands go out as frames, the board's encoder stream comes back. It never blocks: Poll()
// (also run by every DriveBase call) reads what has arrived, sends a heartbeat every
// heartbeat_period_s on the clock it is given, refreshes the current command, watches the
// link and reopens the port after the device went away.
//
// Link loss: no valid frame from the board for link_timeout_s, or the port reporting a
// hang-up. The host then sends STOP and makes it its current command, re-sent every
// stop_refresh_s while the link is down (the board's own 50 ms watchdog stops the motors only
// when the host falls silent, and the heartbeats go on; after a reconnection the drive stays
// stopped until the next SetSpeedTargets / SetPwm), and, if the port closed, tries to reopen
// it every reconnect_period_s. A port that stays open but silent for
// reopen_after_silence_s is closed and reopened too (a replugged board behind the same path).
//
// Encoder counts continue across a reconnection: the first frame after a link loss rebases
// the board's counts (which restart at 0 if the board reset) onto the last known totals.
// Motion during the outage is not counted.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "field_configs/robot_config.h"
#include "platform/clock.h"
#include "platform/drive_base.h"
#include "platform/serial_protocol.h"

namespace slamo::platform {

// A byte link to the board. No call blocks.
class SerialTransport {
 public:
  virtual ~SerialTransport() = default;
  // Opens the device; false when it is not there (the reason in last_error()).
  virtual bool Open() = 0;
  virtual void Close() = 0;
  virtual bool IsOpen() const = 0;
  // Appends the bytes that have arrived (maybe none) to *out. False when the device went
  // away; the transport is closed then.
  virtual bool Read(std::vector<uint8_t>* out) = 0;
  // False when the device went away (the transport is closed then) or would block (the
  // bytes are dropped; IsOpen() stays true).
  virtual bool Write(const std::vector<uint8_t>& bytes) = 0;
  virtual std::string last_error() const = 0;
};

// A serial device (/dev/ttyACM0, a pseudo-terminal, a symlink to either) through MRPT's
// mrpt::comms::CSerialPort at `baud`, 8N1, polled: reads take only what FIONREAD reports,
// writes only when poll() says the device is writable, and POLLHUP / EIO count as unplugged.
std::unique_ptr<SerialTransport> MakeMrptSerialTransport(const std::string& device,
                                                         int baud = 115200);

struct SerialDriveOptions {
  double heartbeat_period_s = 0.02;
  double link_timeout_s = 0.06;  // no valid board frame for this long: link lost
  double reconnect_period_s = 0.2;
  double reopen_after_silence_s = 1.0;
  double command_refresh_s = 0.1;  // resend the current command this often (lost frames)
  // A stop is resent this often: a lost stop then costs the motors one control period, not a
  // command refresh (seen at the deadline on a link dropping 2 % of frames: 0.1 s driven past
  // it).
  double stop_refresh_s = 0.02;
  std::optional<field::PidGains> pid;  // sent each time the link comes up, when set
};

enum class LinkState {
  kClosed,   // the port is not open (never opened, or the device went away)
  kWaiting,  // open, no valid frame yet since opening or since the link was lost
  kUp,       // a valid board frame within link_timeout_s
};
const char* LinkStateName(LinkState state);

struct SerialDriveStats {
  serial::ParserStats parser;
  uint64_t encoder_frames = 0;
  uint64_t duplicate_encoder_frames = 0;  // same board timestamp as the previous one
  uint64_t board_heartbeats = 0;
  uint64_t acks = 0;
  uint64_t errors = 0;  // ERROR frames from the board
  uint64_t unknown_frames = 0;
  uint64_t frames_sent = 0;
  uint64_t writes_failed = 0;
  uint64_t link_ups = 0;
  uint64_t link_losses = 0;
  uint64_t port_opens = 0;
  uint64_t port_closes = 0;
  std::optional<double> last_rtt_s;  // last heartbeat round trip on the host clock
  double max_rtt_s = 0.0;
  double sum_rtt_s = 0.0;
  uint64_t rtt_samples = 0;
  uint16_t board_rx_errors = 0;  // as the board last reported them
  uint16_t board_watchdog_trips = 0;
};

class SerialDriveBase : public DriveBase {
 public:
  SerialDriveBase(std::unique_ptr<SerialTransport> transport, const Clock& clock,
                  const SerialDriveOptions& options = {});

  // DriveBase; each also runs Poll().
  void SetSpeedTargets(double left_mps, double right_mps) override;
  void SetPwm(int left, int right) override;
  void Stop() override;
  // The cumulative counts at the board's time of the last encoder frame, mapped to this
  // host's clock (smallest observed delay); before any frame, zeros at the clock's now.
  EncoderTicks ReadEncoders() override;

  void Poll();
  // Sends the gains now and on every later link-up.
  void SetPidGains(const field::PidGains& gains);

  LinkState link_state() const { return state_; }
  bool link_up() const { return state_ == LinkState::kUp; }
  const SerialDriveStats& stats() const { return stats_; }
  // The last encoder frame as received (board counts, PWM, flags).
  const std::optional<serial::Encoders>& last_encoder_frame() const { return last_raw_; }

 private:
  void TryOpen(double now_s);
  void ClosePort(double now_s);
  void LoseLink(double now_s);
  void HandleFrame(const serial::Frame& frame, double now_s);
  void HandleEncoders(const serial::Encoders& m, double now_s);
  bool Send(const serial::Message& message);

  std::unique_ptr<SerialTransport> transport_;
  const Clock& clock_;
  SerialDriveOptions options_;
  serial::Parser parser_;
  LinkState state_ = LinkState::kClosed;
  SerialDriveStats stats_;
  uint8_t seq_ = 0;

  // The command to refresh while the link is up, a stop even while it is down (nullopt:
  // nothing to refresh).
  std::optional<serial::Message> command_;
  double next_heartbeat_s_ = 0.0;
  double next_refresh_s_ = 0.0;
  double next_open_attempt_s_ = 0.0;
  double last_rx_s_ = 0.0;
  double opened_s_ = 0.0;
  uint32_t heartbeat_token_ = 0;
  double heartbeat_sent_s_ = 0.0;
  uint32_t heartbeat_sent_token_ = 0;
  bool heartbeat_outstanding_ = false;

  // Encoder continuity.
  std::optional<serial::Encoders> last_raw_;
  bool rebase_ = true;
  int64_t left_total_ = 0;
  int64_t right_total_ = 0;
  uint64_t board_time_us_ = 0;            // unwrapped since the last rebase
  std::optional<double> clock_offset_s_;  // host time - board time, smallest seen
  EncoderTicks last_ticks_;
  bool have_ticks_ = false;
};

}  // namespace slamo::platform
