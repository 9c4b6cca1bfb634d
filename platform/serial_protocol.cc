#include "platform/serial_protocol.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace slamo::platform::serial {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

slamo_frame ToCodecFrame(const Frame& frame) {
  slamo_frame f{};
  f.type = frame.type;
  f.seq = frame.seq;
  f.len = static_cast<uint8_t>(std::min(frame.payload.size(), kMaxPayload));
  std::copy_n(frame.payload.begin(), f.len, f.payload);
  return f;
}

int32_t SaturatingMilli(double value) {
  if (std::isnan(value)) return 0;
  const double milli = std::round(value * 1000.0);
  return static_cast<int32_t>(std::clamp(milli, -2147483648.0, 2147483647.0));
}

int16_t SaturatingMmPerS(double mps) {
  if (std::isnan(mps)) return 0;
  return static_cast<int16_t>(std::clamp(std::round(mps * 1000.0), -32767.0, 32767.0));
}

void CollectFrame(void* context, const slamo_frame* frame) {
  auto* out = static_cast<std::vector<Frame>*>(context);
  Frame f;
  f.type = frame->type;
  f.seq = frame->seq;
  f.payload.assign(frame->payload, frame->payload + frame->len);
  out->push_back(std::move(f));
}

}  // namespace

MessageType TypeOf(const Message& message) {
  return std::visit(Overloaded{[](const SetSpeed&) { return MessageType::kSetSpeed; },
                               [](const SetPwm&) { return MessageType::kSetPwm; },
                               [](const Stop&) { return MessageType::kStop; },
                               [](const SetPid&) { return MessageType::kSetPid; },
                               [](const HostHeartbeat&) { return MessageType::kHostHeartbeat; },
                               [](const Encoders&) { return MessageType::kEncoders; },
                               [](const BoardHeartbeat&) { return MessageType::kBoardHeartbeat; },
                               [](const Ack&) { return MessageType::kAck; },
                               [](const Error&) { return MessageType::kError; }},
                    message);
}

const char* TypeName(uint8_t type) {
  switch (type) {
    case SLAMO_MSG_SET_SPEED:
      return "SET_SPEED";
    case SLAMO_MSG_SET_PWM:
      return "SET_PWM";
    case SLAMO_MSG_STOP:
      return "STOP";
    case SLAMO_MSG_SET_PID:
      return "SET_PID";
    case SLAMO_MSG_HOST_HEARTBEAT:
      return "HOST_HEARTBEAT";
    case SLAMO_MSG_ENCODERS:
      return "ENCODERS";
    case SLAMO_MSG_BOARD_HEARTBEAT:
      return "BOARD_HEARTBEAT";
    case SLAMO_MSG_ACK:
      return "ACK";
    case SLAMO_MSG_ERROR:
      return "ERROR";
    default:
      return "UNKNOWN";
  }
}

std::vector<uint8_t> Encode(const Message& message, uint8_t seq) {
  uint8_t payload[SLAMO_MAX_PAYLOAD];
  const uint8_t len = std::visit(
      Overloaded{
          [&](const SetSpeed& m) {
            const slamo_set_speed c{m.left_mm_s, m.right_mm_s};
            return slamo_pack_set_speed(&c, payload);
          },
          [&](const SetPwm& m) {
            const slamo_set_pwm c{m.left, m.right};
            return slamo_pack_set_pwm(&c, payload);
          },
          [&](const Stop&) { return static_cast<uint8_t>(SLAMO_LEN_STOP); },
          [&](const SetPid& m) {
            const slamo_set_pid c{m.kp_milli, m.ki_milli, m.kd_milli, m.integral_limit_milli};
            return slamo_pack_set_pid(&c, payload);
          },
          [&](const HostHeartbeat& m) {
            const slamo_host_heartbeat c{m.token};
            return slamo_pack_host_heartbeat(&c, payload);
          },
          [&](const Encoders& m) {
            const slamo_encoders c{m.t_us,     m.left_ticks, m.right_ticks,
                                   m.left_pwm, m.right_pwm,  m.flags};
            return slamo_pack_encoders(&c, payload);
          },
          [&](const BoardHeartbeat& m) {
            const slamo_board_heartbeat c{m.token, m.t_us, m.rx_errors, m.watchdog_trips};
            return slamo_pack_board_heartbeat(&c, payload);
          },
          [&](const Ack& m) {
            const slamo_ack c{m.type, m.seq};
            return slamo_pack_ack(&c, payload);
          },
          [&](const Error& m) {
            const slamo_error c{m.code, m.type, m.seq};
            return slamo_pack_error(&c, payload);
          }},
      message);
  std::vector<uint8_t> out(kMaxFrame);
  const uint8_t n =
      slamo_encode_frame(static_cast<uint8_t>(TypeOf(message)), seq, payload, len, out.data());
  out.resize(n);
  return out;
}

std::optional<Message> Decode(const Frame& frame) {
  if (frame.payload.size() > kMaxPayload) return std::nullopt;
  const slamo_frame f = ToCodecFrame(frame);
  switch (f.type) {
    case SLAMO_MSG_SET_SPEED: {
      slamo_set_speed c;
      if (!slamo_unpack_set_speed(&f, &c)) return std::nullopt;
      return SetSpeed{c.left_mm_s, c.right_mm_s};
    }
    case SLAMO_MSG_SET_PWM: {
      slamo_set_pwm c;
      if (!slamo_unpack_set_pwm(&f, &c)) return std::nullopt;
      return SetPwm{c.left, c.right};
    }
    case SLAMO_MSG_STOP:
      if (f.len != SLAMO_LEN_STOP) return std::nullopt;
      return Stop{};
    case SLAMO_MSG_SET_PID: {
      slamo_set_pid c;
      if (!slamo_unpack_set_pid(&f, &c)) return std::nullopt;
      return SetPid{c.kp_milli, c.ki_milli, c.kd_milli, c.integral_limit_milli};
    }
    case SLAMO_MSG_HOST_HEARTBEAT: {
      slamo_host_heartbeat c;
      if (!slamo_unpack_host_heartbeat(&f, &c)) return std::nullopt;
      return HostHeartbeat{c.token};
    }
    case SLAMO_MSG_ENCODERS: {
      slamo_encoders c;
      if (!slamo_unpack_encoders(&f, &c)) return std::nullopt;
      return Encoders{c.t_us, c.left_ticks, c.right_ticks, c.left_pwm, c.right_pwm, c.flags};
    }
    case SLAMO_MSG_BOARD_HEARTBEAT: {
      slamo_board_heartbeat c;
      if (!slamo_unpack_board_heartbeat(&f, &c)) return std::nullopt;
      return BoardHeartbeat{c.token, c.t_us, c.rx_errors, c.watchdog_trips};
    }
    case SLAMO_MSG_ACK: {
      slamo_ack c;
      if (!slamo_unpack_ack(&f, &c)) return std::nullopt;
      return Ack{c.type, c.seq};
    }
    case SLAMO_MSG_ERROR: {
      slamo_error c;
      if (!slamo_unpack_error(&f, &c)) return std::nullopt;
      return Error{c.code, c.type, c.seq};
    }
    default:
      return std::nullopt;
  }
}

SetPid SetPidFromGains(const field::PidGains& gains) {
  return {SaturatingMilli(gains.kp), SaturatingMilli(gains.ki), SaturatingMilli(gains.kd),
          SaturatingMilli(gains.integral_limit)};
}

SetSpeed SetSpeedFromMps(double left_mps, double right_mps) {
  return {SaturatingMmPerS(left_mps), SaturatingMmPerS(right_mps)};
}

Parser::Parser() { slamo_parser_init(&parser_); }

std::vector<Frame> Parser::Feed(const uint8_t* data, size_t n) {
  std::vector<Frame> frames;
  for (size_t i = 0; i < n; ++i) slamo_parser_push(&parser_, data[i], &CollectFrame, &frames);
  return frames;
}

ParserStats Parser::stats() const {
  return {parser_.frames_ok, parser_.crc_errors, parser_.length_errors, parser_.type_errors,
          parser_.bytes_skipped};
}

}  // namespace slamo::platform::serial
