// The host side of the motor-controller board's serial protocol (byte tables:
// platform/PROTOCOL.md): typed messages, encoding to frames and a streaming parser that
// resyncs after garbage and counts what it rejects. The frame and CRC code is the firmware's
// own (platform/firmware/protocol_codec.h), so host and board cannot drift apart.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

#include "field_configs/robot_config.h"
#include "platform/firmware/protocol_codec.h"

namespace slamo::platform::serial {

inline constexpr uint8_t kFrameStart = SLAMO_FRAME_START;
inline constexpr size_t kMaxPayload = SLAMO_MAX_PAYLOAD;
inline constexpr size_t kMaxFrame = SLAMO_MAX_FRAME;

enum class MessageType : uint8_t {
  kSetSpeed = SLAMO_MSG_SET_SPEED,
  kSetPwm = SLAMO_MSG_SET_PWM,
  kStop = SLAMO_MSG_STOP,
  kSetPid = SLAMO_MSG_SET_PID,
  kHostHeartbeat = SLAMO_MSG_HOST_HEARTBEAT,
  kEncoders = SLAMO_MSG_ENCODERS,
  kBoardHeartbeat = SLAMO_MSG_BOARD_HEARTBEAT,
  kAck = SLAMO_MSG_ACK,
  kError = SLAMO_MSG_ERROR,
};

// Host -> board.
struct SetSpeed {
  int16_t left_mm_s = 0;
  int16_t right_mm_s = 0;
};
struct SetPwm {
  uint8_t left = 90;
  uint8_t right = 90;
};
struct Stop {};
struct SetPid {
  int32_t kp_milli = 0;  // gains x 1000 (PWM units per m/s, as in the robot file)
  int32_t ki_milli = 0;
  int32_t kd_milli = 0;
  int32_t integral_limit_milli = 0;
};
struct HostHeartbeat {
  uint32_t token = 0;
};
// Board -> host.
struct Encoders {
  uint32_t t_us = 0;
  int32_t left_ticks = 0;
  int32_t right_ticks = 0;
  uint8_t left_pwm = 90;
  uint8_t right_pwm = 90;
  uint8_t flags = 0;  // SLAMO_FLAG_*
};
struct BoardHeartbeat {
  uint32_t token = 0;
  uint32_t t_us = 0;
  uint16_t rx_errors = 0;
  uint16_t watchdog_trips = 0;
};
struct Ack {
  uint8_t type = 0;
  uint8_t seq = 0;
};
struct Error {
  uint8_t code = 0;
  uint8_t type = 0;
  uint8_t seq = 0;
};

using Message = std::variant<SetSpeed, SetPwm, Stop, SetPid, HostHeartbeat, Encoders,
                             BoardHeartbeat, Ack, Error>;

MessageType TypeOf(const Message& message);
const char* TypeName(uint8_t type);

// A frame that passed the length and CRC checks.
struct Frame {
  uint8_t type = 0;
  uint8_t seq = 0;
  std::vector<uint8_t> payload;
};

// The bytes of one frame.
std::vector<uint8_t> Encode(const Message& message, uint8_t seq);
// The message in a frame, or nullopt for an unknown type or a wrong length (a Frame built by
// hand; the Parser passes neither).
std::optional<Message> Decode(const Frame& frame);

// Gains of the robot file -> SET_PID (rounded to 0.001; saturating).
SetPid SetPidFromGains(const field::PidGains& gains);
// m/s -> SET_SPEED (rounded to mm/s, saturating at +-32.767 m/s; NaN -> 0).
SetSpeed SetSpeedFromMps(double left_mps, double right_mps);

struct ParserStats {
  uint64_t frames_ok = 0;
  uint64_t crc_errors = 0;
  uint64_t length_errors = 0;
  uint64_t type_errors = 0;
  uint64_t bytes_skipped = 0;
};

// Streaming: feed whatever arrived, get the complete valid frames. See protocol_codec.h for
// the resync rule.
class Parser {
 public:
  Parser();
  std::vector<Frame> Feed(const uint8_t* data, size_t n);
  std::vector<Frame> Feed(const std::vector<uint8_t>& data) {
    return Feed(data.data(), data.size());
  }
  ParserStats stats() const;

 private:
  slamo_parser parser_;
};

}  // namespace slamo::platform::serial
