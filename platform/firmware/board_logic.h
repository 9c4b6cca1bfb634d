// The motor-controller board's logic, hardware-free: the protocol endpoint, the per-side PID
// speed loop (with speed feedforward through the servo PWM curve) and the link watchdog.
// The Arduino Mega 2560 firmware (slamo_board/slamo_board.ino) and the host's fake board
// (platform/sim/fake_board.cc) both compile this header, so the fake board runs exactly the code
// the board runs; only the I/O around it differs (UART + Timer PWM + I2C encoders there, a
// pseudo-terminal + the simulator's motor model here).
//
// C++11, no heap, no standard library: avr-gcc 5.4 with the Arduino core compiles it. Times
// are uint32 microseconds (micros() on the board); every interval is an unsigned difference,
// so the 71.6-minute wrap of micros() is harmless.
//
// Watchdog: any valid frame from the host (a heartbeat at the latest every 20 ms, or a
// command) proves the link. When none has arrived for link_timeout_us (50 ms), the next
// Poll() sets both sides to stop (PWM 90), resets the speed loop and keeps them stopped until
// the host sends a new SET_SPEED or SET_PWM: a replugged cable never resumes old motion.
#ifndef SLAMO_PLATFORM_FIRMWARE_BOARD_LOGIC_H_
#define SLAMO_PLATFORM_FIRMWARE_BOARD_LOGIC_H_

#include <math.h>
#include <stdint.h>

#include "protocol_codec.h"

namespace slamo_fw {

// Servo PWM of the VEX Motor Controller 29 (the robot file's drive.pwm).
struct PwmConfig {
  int16_t full_forward;
  int16_t stop;
  int16_t full_reverse;
  int16_t deadband;
  float curve_exponent;
};

struct PidConfig {
  float kp;  // PWM units per m/s of speed error
  float ki;
  float kd;
  float integral_limit;  // |ki * integral| <= this (PWM units); 0 = no clamp
};

struct BoardConfig {
  PwmConfig pwm;
  PidConfig pid;
  float max_speed_mps;         // wheel speed at full PWM (feedforward)
  float metres_per_tick;       // wheel surface travel per encoder tick
  uint32_t pid_period_us;      // speed loop period
  uint32_t encoder_period_us;  // ENCODERS frame period
  uint32_t link_timeout_us;    // watchdog: stop after this long without a valid host frame
  bool speed_feedforward;      // add the nominal PWM for the target to the PID output
};

// The thesis robot (field_configs/robots/thesis_robot.yaml): 2.75 in wheels, 627.2 ticks per
// revolution, PWM 0/90/180 with deadband 8 and curve 1.6, PID 60/300/0 at 50 Hz.
inline BoardConfig ThesisBoardConfig() {
  BoardConfig c;
  c.pwm.full_forward = 0;
  c.pwm.stop = 90;
  c.pwm.full_reverse = 180;
  c.pwm.deadband = 8;
  c.pwm.curve_exponent = 1.6f;
  c.pid.kp = 60.0f;
  c.pid.ki = 300.0f;
  c.pid.kd = 0.0f;
  c.pid.integral_limit = 60.0f;
  c.max_speed_mps = 0.37f;
  c.metres_per_tick = 3.14159265f * 0.06985f / 627.2f;
  c.pid_period_us = 20000;
  c.encoder_period_us = 20000;
  c.link_timeout_us = 50000;
  c.speed_feedforward = true;
  return c;
}

// Signed PWM offset from stop (positive towards full_forward) that gives `fraction` of full
// speed: the inverse of the motor curve (platform/motor.h SpeedFractionToPwmOffset).
inline float SpeedFractionToPwmOffset(const PwmConfig& pwm, float fraction) {
  if (fraction == 0.0f || fraction != fraction) return 0.0f;
  const bool forward = fraction > 0.0f;
  const int16_t end = forward ? pwm.full_forward : pwm.full_reverse;
  const float span = (float)(end > pwm.stop ? end - pwm.stop : pwm.stop - end);
  float magnitude_fraction = forward ? fraction : -fraction;
  if (magnitude_fraction > 1.0f) magnitude_fraction = 1.0f;
  const float x = powf(magnitude_fraction, 1.0f / pwm.curve_exponent);
  const float magnitude = (float)pwm.deadband + x * (span - (float)pwm.deadband);
  return forward ? magnitude : -magnitude;
}

// Signed offset -> PWM value, rounded and saturated at full_forward / full_reverse.
inline uint8_t PwmFromOffset(const PwmConfig& pwm, float offset) {
  if (offset != offset) return (uint8_t)pwm.stop;
  const bool forward = offset >= 0.0f;
  const int16_t end = forward ? pwm.full_forward : pwm.full_reverse;
  const float span = (float)(end > pwm.stop ? end - pwm.stop : pwm.stop - end);
  float magnitude = forward ? offset : -offset;
  if (magnitude > span) magnitude = span;
  const int16_t steps = (int16_t)lroundf(magnitude);
  return (uint8_t)(end > pwm.stop ? pwm.stop + steps : pwm.stop - steps);
}

class BoardLogic {
 public:
  enum { kTxCapacity = 160 };

  explicit BoardLogic(const BoardConfig& config) : config_(config) { Reset(0); }

  // Power-on state: stopped, link down, counters zero, nothing to send.
  void Reset(uint32_t now_us) {
    slamo_parser_init(&parser_);
    now_us_ = now_us;
    left_.ticks_at_last_pid = right_.ticks_at_last_pid = 0;
    left_.Clear(config_.pwm.stop);
    right_.Clear(config_.pwm.stop);
    speed_mode_ = false;
    link_up_ = false;
    watchdog_stopped_ = false;
    encoder_fault_ = false;
    last_rx_us_ = now_us;
    next_pid_us_ = now_us + config_.pid_period_us;
    next_encoder_us_ = now_us + config_.encoder_period_us;
    last_pid_us_ = now_us;
    have_ticks_ = false;
    tx_head_ = tx_tail_ = tx_count_ = 0;
    tx_dropped_ = 0;
    watchdog_trips_ = 0;
    last_token_ = 0;
    seq_ = 0;
    bad_values_ = 0;
  }

  // A byte from the host.
  void OnByte(uint8_t byte, uint32_t now_us) {
    now_us_ = now_us;
    slamo_parser_push(&parser_, byte, &BoardLogic::HandleFrameThunk, this);
  }

  // Every loop iteration: the watchdog first, then the speed loop and the encoder stream when
  // due. left/right_ticks are the latest cumulative encoder counts (positive forward).
  void Poll(uint32_t now_us, int32_t left_ticks, int32_t right_ticks) {
    now_us_ = now_us;
    if (!have_ticks_) {
      left_.ticks_at_last_pid = left_ticks;
      right_.ticks_at_last_pid = right_ticks;
      have_ticks_ = true;
    }
    CheckWatchdog(now_us);
    if ((int32_t)(now_us - next_pid_us_) >= 0) {
      const uint32_t dt_us = now_us - last_pid_us_;
      RunPid(&left_, left_ticks, dt_us);
      RunPid(&right_, right_ticks, dt_us);
      last_pid_us_ = now_us;
      next_pid_us_ += config_.pid_period_us;
      // Far behind (a stalled loop): restart the schedule instead of bursting.
      if ((int32_t)(now_us - next_pid_us_) >= 0) next_pid_us_ = now_us + config_.pid_period_us;
    }
    if ((int32_t)(now_us - next_encoder_us_) >= 0) {
      SendEncoders(now_us, left_ticks, right_ticks);
      next_encoder_us_ += config_.encoder_period_us;
      if ((int32_t)(now_us - next_encoder_us_) >= 0) {
        next_encoder_us_ = now_us + config_.encoder_period_us;
      }
    }
  }

  // True when the next Poll() at now_us runs the speed loop or sends encoder counts: the
  // firmware reads the I2C encoders only then.
  bool TicksWanted(uint32_t now_us) const {
    return (int32_t)(now_us - next_pid_us_) >= 0 || (int32_t)(now_us - next_encoder_us_) >= 0;
  }

  // Watchdog only (the firmware calls it between slow encoder reads too).
  void CheckWatchdog(uint32_t now_us) {
    if (link_up_ && now_us - last_rx_us_ > config_.link_timeout_us) {
      link_up_ = false;
      if (speed_mode_ || left_.pwm != config_.pwm.stop || right_.pwm != config_.pwm.stop) {
        StopMotors();
        watchdog_stopped_ = true;
        if (watchdog_trips_ < 0xFFFFu) ++watchdog_trips_;
      }
    }
  }

  void set_encoder_fault(bool fault) { encoder_fault_ = fault; }

  // Outgoing bytes, oldest first.
  uint16_t TxCount() const { return tx_count_; }
  uint8_t TxPop() {
    const uint8_t b = tx_[tx_tail_];
    tx_tail_ = (uint16_t)((tx_tail_ + 1) % kTxCapacity);
    --tx_count_;
    return b;
  }

  uint8_t left_pwm() const { return left_.pwm; }
  uint8_t right_pwm() const { return right_.pwm; }
  bool speed_mode() const { return speed_mode_; }
  bool link_up() const { return link_up_; }
  bool watchdog_stopped() const { return watchdog_stopped_; }
  uint16_t watchdog_trips() const { return watchdog_trips_; }
  uint32_t last_rx_us() const { return last_rx_us_; }
  const slamo_parser& parser() const { return parser_; }
  uint32_t tx_dropped() const { return tx_dropped_; }
  uint32_t bad_values() const { return bad_values_; }
  const PidConfig& pid() const { return config_.pid; }
  float left_target_mps() const { return left_.target_mps; }
  float right_target_mps() const { return right_.target_mps; }

 private:
  struct Side {
    float target_mps;
    uint8_t pwm;
    float integral;
    float prev_error;
    int32_t ticks_at_last_pid;
    void Clear(int16_t stop) {
      target_mps = 0.0f;
      pwm = (uint8_t)stop;
      integral = 0.0f;
      prev_error = 0.0f;
    }
    void ResetPid() {
      integral = 0.0f;
      prev_error = 0.0f;
    }
  };

  static void HandleFrameThunk(void* context, const slamo_frame* frame) {
    static_cast<BoardLogic*>(context)->HandleFrame(*frame);
  }

  void HandleFrame(const slamo_frame& frame) {
    last_rx_us_ = now_us_;
    link_up_ = true;
    switch (frame.type) {
      case SLAMO_MSG_SET_SPEED: {
        slamo_set_speed m;
        if (!slamo_unpack_set_speed(&frame, &m)) break;
        if (!speed_mode_) {
          left_.ResetPid();
          right_.ResetPid();
        }
        speed_mode_ = true;
        watchdog_stopped_ = false;
        left_.target_mps = 0.001f * (float)m.left_mm_s;
        right_.target_mps = 0.001f * (float)m.right_mm_s;
        SendAck(frame);
        return;
      }
      case SLAMO_MSG_SET_PWM: {
        slamo_set_pwm m;
        if (!slamo_unpack_set_pwm(&frame, &m)) break;
        if (!PwmValid(m.left) || !PwmValid(m.right)) {
          SendError(SLAMO_ERR_BAD_VALUE, frame);
          return;
        }
        speed_mode_ = false;
        watchdog_stopped_ = false;
        left_.Clear(config_.pwm.stop);
        right_.Clear(config_.pwm.stop);
        left_.pwm = m.left;
        right_.pwm = m.right;
        SendAck(frame);
        return;
      }
      case SLAMO_MSG_STOP:
        StopMotors();
        watchdog_stopped_ = false;
        SendAck(frame);
        return;
      case SLAMO_MSG_SET_PID: {
        slamo_set_pid m;
        if (!slamo_unpack_set_pid(&frame, &m)) break;
        if (m.kp_milli < 0 || m.ki_milli < 0 || m.kd_milli < 0 || m.integral_limit_milli < 0) {
          SendError(SLAMO_ERR_BAD_VALUE, frame);
          return;
        }
        config_.pid.kp = 0.001f * (float)m.kp_milli;
        config_.pid.ki = 0.001f * (float)m.ki_milli;
        config_.pid.kd = 0.001f * (float)m.kd_milli;
        config_.pid.integral_limit = 0.001f * (float)m.integral_limit_milli;
        left_.ResetPid();
        right_.ResetPid();
        SendAck(frame);
        return;
      }
      case SLAMO_MSG_HOST_HEARTBEAT: {
        slamo_host_heartbeat m;
        if (!slamo_unpack_host_heartbeat(&frame, &m)) break;
        last_token_ = m.token;
        slamo_board_heartbeat reply;
        reply.token = m.token;
        reply.t_us = now_us_;
        const uint32_t errors = parser_.crc_errors + parser_.length_errors + parser_.type_errors;
        reply.rx_errors = errors > 0xFFFFu ? (uint16_t)0xFFFFu : (uint16_t)errors;
        reply.watchdog_trips = watchdog_trips_;
        uint8_t payload[SLAMO_LEN_BOARD_HEARTBEAT];
        Send(SLAMO_MSG_BOARD_HEARTBEAT, payload, slamo_pack_board_heartbeat(&reply, payload));
        return;
      }
      default:
        break;
    }
    SendError(SLAMO_ERR_UNKNOWN_TYPE, frame);
  }

  bool PwmValid(uint8_t value) const {
    const int16_t lo = config_.pwm.full_forward < config_.pwm.full_reverse
                           ? config_.pwm.full_forward
                           : config_.pwm.full_reverse;
    const int16_t hi = config_.pwm.full_forward < config_.pwm.full_reverse
                           ? config_.pwm.full_reverse
                           : config_.pwm.full_forward;
    return (int16_t)value >= lo && (int16_t)value <= hi;
  }

  void StopMotors() {
    speed_mode_ = false;
    left_.Clear(config_.pwm.stop);
    right_.Clear(config_.pwm.stop);
  }

  // One side of the speed loop: speed from the ticks since the last run, PID plus
  // feedforward -> PWM. A zero target stops the side and resets its loop.
  void RunPid(Side* side, int32_t ticks, uint32_t dt_us) {
    const int32_t delta = (int32_t)((uint32_t)ticks - (uint32_t)side->ticks_at_last_pid);
    side->ticks_at_last_pid = ticks;
    if (!speed_mode_) return;
    if (side->target_mps == 0.0f || dt_us == 0) {
      side->pwm = (uint8_t)config_.pwm.stop;
      side->ResetPid();
      return;
    }
    const float dt_s = 1e-6f * (float)dt_us;
    const float measured_mps = (float)delta * config_.metres_per_tick / dt_s;
    const float error = side->target_mps - measured_mps;
    side->integral += error * dt_s;
    if (config_.pid.integral_limit > 0.0f && config_.pid.ki > 0.0f) {
      const float max_integral = config_.pid.integral_limit / config_.pid.ki;
      if (side->integral > max_integral) side->integral = max_integral;
      if (side->integral < -max_integral) side->integral = -max_integral;
    }
    const float derivative = (error - side->prev_error) / dt_s;
    side->prev_error = error;
    float offset =
        config_.pid.kp * error + config_.pid.ki * side->integral + config_.pid.kd * derivative;
    if (config_.speed_feedforward && config_.max_speed_mps > 0.0f) {
      offset += SpeedFractionToPwmOffset(config_.pwm, side->target_mps / config_.max_speed_mps);
    }
    side->pwm = PwmFromOffset(config_.pwm, offset);
  }

  void SendEncoders(uint32_t now_us, int32_t left_ticks, int32_t right_ticks) {
    slamo_encoders m;
    m.t_us = now_us;
    m.left_ticks = left_ticks;
    m.right_ticks = right_ticks;
    m.left_pwm = left_.pwm;
    m.right_pwm = right_.pwm;
    m.flags = (uint8_t)((speed_mode_ ? SLAMO_FLAG_SPEED_MODE : 0) |
                        (watchdog_stopped_ ? SLAMO_FLAG_WATCHDOG_STOP : 0) |
                        (encoder_fault_ ? SLAMO_FLAG_ENCODER_FAULT : 0) |
                        (link_up_ ? SLAMO_FLAG_LINK_UP : 0));
    uint8_t payload[SLAMO_LEN_ENCODERS];
    Send(SLAMO_MSG_ENCODERS, payload, slamo_pack_encoders(&m, payload));
  }

  void SendAck(const slamo_frame& frame) {
    slamo_ack m;
    m.type = frame.type;
    m.seq = frame.seq;
    uint8_t payload[SLAMO_LEN_ACK];
    Send(SLAMO_MSG_ACK, payload, slamo_pack_ack(&m, payload));
  }

  void SendError(uint8_t code, const slamo_frame& frame) {
    if (code == SLAMO_ERR_BAD_VALUE) ++bad_values_;
    slamo_error m;
    m.code = code;
    m.type = frame.type;
    m.seq = frame.seq;
    uint8_t payload[SLAMO_LEN_ERROR];
    Send(SLAMO_MSG_ERROR, payload, slamo_pack_error(&m, payload));
  }

  // Queues a whole frame, or drops it (counted) when the queue is too full.
  void Send(uint8_t type, const uint8_t* payload, uint8_t len) {
    uint8_t frame[SLAMO_MAX_FRAME];
    const uint8_t n = slamo_encode_frame(type, seq_++, payload, len, frame);
    if (n == 0 || tx_count_ + n > kTxCapacity) {
      ++tx_dropped_;
      return;
    }
    for (uint8_t i = 0; i < n; ++i) {
      tx_[tx_head_] = frame[i];
      tx_head_ = (uint16_t)((tx_head_ + 1) % kTxCapacity);
    }
    tx_count_ = (uint16_t)(tx_count_ + n);
  }

  BoardConfig config_;
  slamo_parser parser_;
  Side left_;
  Side right_;
  bool speed_mode_;
  bool link_up_;
  bool watchdog_stopped_;
  bool encoder_fault_;
  bool have_ticks_;
  uint32_t now_us_;
  uint32_t last_rx_us_;
  uint32_t next_pid_us_;
  uint32_t last_pid_us_;
  uint32_t next_encoder_us_;
  uint8_t tx_[kTxCapacity];
  uint16_t tx_head_;
  uint16_t tx_tail_;
  uint16_t tx_count_;
  uint32_t tx_dropped_;
  uint16_t watchdog_trips_;
  uint32_t last_token_;
  uint8_t seq_;
  uint32_t bad_values_;
};

}  // namespace slamo_fw

#endif  // SLAMO_PLATFORM_FIRMWARE_BOARD_LOGIC_H_
