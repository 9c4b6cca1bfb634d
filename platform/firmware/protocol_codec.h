// The slamo serial protocol's frame and message codec, shared byte for byte by the host
// (platform/serial_protocol.cc) and the motor-controller board's firmware
// (platform/firmware/slamo_board). Plain C-compatible C++: <stdint.h> and <string.h> only, no
// heap, no exceptions, C++11 (avr-gcc 5.4 with the Arduino core) up to C++17 (the host).
// The byte-level tables are in platform/PROTOCOL.md.
//
// Frame: 0xA5 | type | seq | len | payload (len bytes) | crc16 low | crc16 high
// crc16 = CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final xor) over
// type, seq, len and the payload. Multi-byte fields are little-endian.
#ifndef SLAMO_PLATFORM_FIRMWARE_PROTOCOL_CODEC_H_
#define SLAMO_PLATFORM_FIRMWARE_PROTOCOL_CODEC_H_

#include <stdint.h>
#include <string.h>

#define SLAMO_FRAME_START 0xA5
#define SLAMO_HEADER_BYTES 4
#define SLAMO_CRC_BYTES 2
#define SLAMO_MAX_PAYLOAD 32
#define SLAMO_MAX_FRAME (SLAMO_HEADER_BYTES + SLAMO_MAX_PAYLOAD + SLAMO_CRC_BYTES)

// Message types: host -> board below 0x80, board -> host from 0x80.
enum {
  SLAMO_MSG_SET_SPEED = 0x01,        // int16 left_mm_s, int16 right_mm_s
  SLAMO_MSG_SET_PWM = 0x02,          // uint8 left, uint8 right (servo PWM, 90 = stop)
  SLAMO_MSG_STOP = 0x03,             // no payload
  SLAMO_MSG_SET_PID = 0x04,          // int32 kp, ki, kd, integral_limit, each x 1000
  SLAMO_MSG_HOST_HEARTBEAT = 0x05,   // uint32 token
  SLAMO_MSG_ENCODERS = 0x81,         // uint32 t_us, int32 left, int32 right, uint8 pwm x2, flags
  SLAMO_MSG_BOARD_HEARTBEAT = 0x82,  // uint32 token, uint32 t_us, uint16 rx_errors, trips
  SLAMO_MSG_ACK = 0x83,              // uint8 type, uint8 seq of the acknowledged frame
  SLAMO_MSG_ERROR = 0x84             // uint8 code, uint8 type, uint8 seq
};

// Payload lengths of the known types.
enum {
  SLAMO_LEN_SET_SPEED = 4,
  SLAMO_LEN_SET_PWM = 2,
  SLAMO_LEN_STOP = 0,
  SLAMO_LEN_SET_PID = 16,
  SLAMO_LEN_HOST_HEARTBEAT = 4,
  SLAMO_LEN_ENCODERS = 15,
  SLAMO_LEN_BOARD_HEARTBEAT = 12,
  SLAMO_LEN_ACK = 2,
  SLAMO_LEN_ERROR = 3
};

// ERROR codes.
enum {
  SLAMO_ERR_UNKNOWN_TYPE = 1,  // a valid frame of a type the receiver does not handle (e.g.
                               // a board -> host type sent to the board)
  SLAMO_ERR_BAD_VALUE = 2      // e.g. a PWM outside 0..180 or a negative gain
};

// Bits of the ENCODERS flags byte.
enum {
  SLAMO_FLAG_SPEED_MODE = 0x01,     // the PID speed loop drives the motors
  SLAMO_FLAG_WATCHDOG_STOP = 0x02,  // stopped by the link watchdog, waiting for a command
  SLAMO_FLAG_ENCODER_FAULT = 0x04,  // an encoder did not answer at the last read
  SLAMO_FLAG_LINK_UP = 0x08         // a valid host frame arrived within the link timeout
};

typedef struct {
  uint8_t type;
  uint8_t seq;
  uint8_t len;
  uint8_t payload[SLAMO_MAX_PAYLOAD];
} slamo_frame;

static inline uint16_t slamo_crc16_update(uint16_t crc, uint8_t byte) {
  crc = (uint16_t)(crc ^ ((uint16_t)byte << 8));
  for (uint8_t bit = 0; bit < 8; ++bit) {
    crc = (crc & 0x8000u) ? (uint16_t)((crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
  }
  return crc;
}

static inline uint16_t slamo_crc16(const uint8_t* data, uint16_t n) {
  uint16_t crc = 0xFFFFu;
  for (uint16_t i = 0; i < n; ++i) crc = slamo_crc16_update(crc, data[i]);
  return crc;
}

// The payload length a known type must have, or -1 for a type this codec does not know.
static inline int slamo_expected_length(uint8_t type) {
  switch (type) {
    case SLAMO_MSG_SET_SPEED:
      return SLAMO_LEN_SET_SPEED;
    case SLAMO_MSG_SET_PWM:
      return SLAMO_LEN_SET_PWM;
    case SLAMO_MSG_STOP:
      return SLAMO_LEN_STOP;
    case SLAMO_MSG_SET_PID:
      return SLAMO_LEN_SET_PID;
    case SLAMO_MSG_HOST_HEARTBEAT:
      return SLAMO_LEN_HOST_HEARTBEAT;
    case SLAMO_MSG_ENCODERS:
      return SLAMO_LEN_ENCODERS;
    case SLAMO_MSG_BOARD_HEARTBEAT:
      return SLAMO_LEN_BOARD_HEARTBEAT;
    case SLAMO_MSG_ACK:
      return SLAMO_LEN_ACK;
    case SLAMO_MSG_ERROR:
      return SLAMO_LEN_ERROR;
    default:
      return -1;
  }
}

// Writes one frame into out (at least SLAMO_HEADER_BYTES + len + SLAMO_CRC_BYTES bytes) and
// returns its size, or 0 when len is over SLAMO_MAX_PAYLOAD.
static inline uint8_t slamo_encode_frame(uint8_t type, uint8_t seq, const uint8_t* payload,
                                         uint8_t len, uint8_t* out) {
  if (len > SLAMO_MAX_PAYLOAD) return 0;
  out[0] = SLAMO_FRAME_START;
  out[1] = type;
  out[2] = seq;
  out[3] = len;
  if (len > 0) memcpy(out + SLAMO_HEADER_BYTES, payload, len);
  const uint16_t crc = slamo_crc16(out + 1, (uint16_t)(3 + len));
  out[SLAMO_HEADER_BYTES + len] = (uint8_t)(crc & 0xFFu);
  out[SLAMO_HEADER_BYTES + len + 1] = (uint8_t)(crc >> 8);
  return (uint8_t)(SLAMO_HEADER_BYTES + len + SLAMO_CRC_BYTES);
}

// --- Little-endian field helpers --------------------------------------------------------

static inline void slamo_put_u16(uint8_t* p, uint16_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)(v >> 8);
}
static inline void slamo_put_u32(uint8_t* p, uint32_t v) {
  for (uint8_t i = 0; i < 4; ++i) p[i] = (uint8_t)((v >> (8 * i)) & 0xFFu);
}
static inline uint16_t slamo_get_u16(const uint8_t* p) {
  return (uint16_t)((uint16_t)p[0] | ((uint16_t)p[1] << 8));
}
static inline uint32_t slamo_get_u32(const uint8_t* p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
// Two's complement through the unsigned types: no implementation-defined shifts.
static inline void slamo_put_i16(uint8_t* p, int16_t v) { slamo_put_u16(p, (uint16_t)v); }
static inline void slamo_put_i32(uint8_t* p, int32_t v) { slamo_put_u32(p, (uint32_t)v); }
static inline int16_t slamo_get_i16(const uint8_t* p) {
  const uint16_t u = slamo_get_u16(p);
  return u < 0x8000u ? (int16_t)u : (int16_t)(-(int32_t)(0x10000ul - u));
}
static inline int32_t slamo_get_i32(const uint8_t* p) {
  const uint32_t u = slamo_get_u32(p);
  return u < 0x80000000ul ? (int32_t)u : (int32_t)(-(int64_t)(0x100000000ull - u));
}

// --- Messages -----------------------------------------------------------------------------
// slamo_pack_X writes the payload and returns its length; slamo_unpack_X returns 1 when the
// frame has X's type and length (and fills *m), else 0.

typedef struct {
  int16_t left_mm_s;
  int16_t right_mm_s;
} slamo_set_speed;

typedef struct {
  uint8_t left;
  uint8_t right;
} slamo_set_pwm;

typedef struct {
  int32_t kp_milli;  // PWM units per m/s of speed error, x 1000
  int32_t ki_milli;
  int32_t kd_milli;
  int32_t integral_limit_milli;  // PWM units, x 1000
} slamo_set_pid;

typedef struct {
  uint32_t token;  // echoed by the board's heartbeat
} slamo_host_heartbeat;

typedef struct {
  uint32_t t_us;  // board clock (micros(), wraps every 71.6 min) when the counts were read
  int32_t left_ticks;
  int32_t right_ticks;  // cumulative, positive forward, wrap at 2^31
  uint8_t left_pwm;
  uint8_t right_pwm;  // what the board applies now
  uint8_t flags;      // SLAMO_FLAG_*
} slamo_encoders;

typedef struct {
  uint32_t token;      // the last host heartbeat's token
  uint32_t t_us;       // board clock when sent
  uint16_t rx_errors;  // frames the board rejected (CRC, length, type), saturating
  uint16_t watchdog_trips;
} slamo_board_heartbeat;

typedef struct {
  uint8_t type;
  uint8_t seq;
} slamo_ack;

typedef struct {
  uint8_t code;  // SLAMO_ERR_*
  uint8_t type;
  uint8_t seq;
} slamo_error;

static inline uint8_t slamo_pack_set_speed(const slamo_set_speed* m, uint8_t* p) {
  slamo_put_i16(p, m->left_mm_s);
  slamo_put_i16(p + 2, m->right_mm_s);
  return SLAMO_LEN_SET_SPEED;
}
static inline int slamo_unpack_set_speed(const slamo_frame* f, slamo_set_speed* m) {
  if (f->type != SLAMO_MSG_SET_SPEED || f->len != SLAMO_LEN_SET_SPEED) return 0;
  m->left_mm_s = slamo_get_i16(f->payload);
  m->right_mm_s = slamo_get_i16(f->payload + 2);
  return 1;
}

static inline uint8_t slamo_pack_set_pwm(const slamo_set_pwm* m, uint8_t* p) {
  p[0] = m->left;
  p[1] = m->right;
  return SLAMO_LEN_SET_PWM;
}
static inline int slamo_unpack_set_pwm(const slamo_frame* f, slamo_set_pwm* m) {
  if (f->type != SLAMO_MSG_SET_PWM || f->len != SLAMO_LEN_SET_PWM) return 0;
  m->left = f->payload[0];
  m->right = f->payload[1];
  return 1;
}

static inline uint8_t slamo_pack_set_pid(const slamo_set_pid* m, uint8_t* p) {
  slamo_put_i32(p, m->kp_milli);
  slamo_put_i32(p + 4, m->ki_milli);
  slamo_put_i32(p + 8, m->kd_milli);
  slamo_put_i32(p + 12, m->integral_limit_milli);
  return SLAMO_LEN_SET_PID;
}
static inline int slamo_unpack_set_pid(const slamo_frame* f, slamo_set_pid* m) {
  if (f->type != SLAMO_MSG_SET_PID || f->len != SLAMO_LEN_SET_PID) return 0;
  m->kp_milli = slamo_get_i32(f->payload);
  m->ki_milli = slamo_get_i32(f->payload + 4);
  m->kd_milli = slamo_get_i32(f->payload + 8);
  m->integral_limit_milli = slamo_get_i32(f->payload + 12);
  return 1;
}

static inline uint8_t slamo_pack_host_heartbeat(const slamo_host_heartbeat* m, uint8_t* p) {
  slamo_put_u32(p, m->token);
  return SLAMO_LEN_HOST_HEARTBEAT;
}
static inline int slamo_unpack_host_heartbeat(const slamo_frame* f, slamo_host_heartbeat* m) {
  if (f->type != SLAMO_MSG_HOST_HEARTBEAT || f->len != SLAMO_LEN_HOST_HEARTBEAT) return 0;
  m->token = slamo_get_u32(f->payload);
  return 1;
}

static inline uint8_t slamo_pack_encoders(const slamo_encoders* m, uint8_t* p) {
  slamo_put_u32(p, m->t_us);
  slamo_put_i32(p + 4, m->left_ticks);
  slamo_put_i32(p + 8, m->right_ticks);
  p[12] = m->left_pwm;
  p[13] = m->right_pwm;
  p[14] = m->flags;
  return SLAMO_LEN_ENCODERS;
}
static inline int slamo_unpack_encoders(const slamo_frame* f, slamo_encoders* m) {
  if (f->type != SLAMO_MSG_ENCODERS || f->len != SLAMO_LEN_ENCODERS) return 0;
  m->t_us = slamo_get_u32(f->payload);
  m->left_ticks = slamo_get_i32(f->payload + 4);
  m->right_ticks = slamo_get_i32(f->payload + 8);
  m->left_pwm = f->payload[12];
  m->right_pwm = f->payload[13];
  m->flags = f->payload[14];
  return 1;
}

static inline uint8_t slamo_pack_board_heartbeat(const slamo_board_heartbeat* m, uint8_t* p) {
  slamo_put_u32(p, m->token);
  slamo_put_u32(p + 4, m->t_us);
  slamo_put_u16(p + 8, m->rx_errors);
  slamo_put_u16(p + 10, m->watchdog_trips);
  return SLAMO_LEN_BOARD_HEARTBEAT;
}
static inline int slamo_unpack_board_heartbeat(const slamo_frame* f, slamo_board_heartbeat* m) {
  if (f->type != SLAMO_MSG_BOARD_HEARTBEAT || f->len != SLAMO_LEN_BOARD_HEARTBEAT) return 0;
  m->token = slamo_get_u32(f->payload);
  m->t_us = slamo_get_u32(f->payload + 4);
  m->rx_errors = slamo_get_u16(f->payload + 8);
  m->watchdog_trips = slamo_get_u16(f->payload + 10);
  return 1;
}

static inline uint8_t slamo_pack_ack(const slamo_ack* m, uint8_t* p) {
  p[0] = m->type;
  p[1] = m->seq;
  return SLAMO_LEN_ACK;
}
static inline int slamo_unpack_ack(const slamo_frame* f, slamo_ack* m) {
  if (f->type != SLAMO_MSG_ACK || f->len != SLAMO_LEN_ACK) return 0;
  m->type = f->payload[0];
  m->seq = f->payload[1];
  return 1;
}

static inline uint8_t slamo_pack_error(const slamo_error* m, uint8_t* p) {
  p[0] = m->code;
  p[1] = m->type;
  p[2] = m->seq;
  return SLAMO_LEN_ERROR;
}
static inline int slamo_unpack_error(const slamo_frame* f, slamo_error* m) {
  if (f->type != SLAMO_MSG_ERROR || f->len != SLAMO_LEN_ERROR) return 0;
  m->code = f->payload[0];
  m->type = f->payload[1];
  m->seq = f->payload[2];
  return 1;
}

// --- Streaming parser ---------------------------------------------------------------------
// Feed it bytes as they arrive; it calls the handler for every valid frame. Bytes before a
// start byte are skipped. A header with a type the codec does not know, or a length other
// than that type's fixed length, is rejected as soon as its 4 bytes are in; a frame whose CRC
// does not match is rejected when complete. Each rejection is counted, and the parser resyncs
// at the next start byte *inside* the rejected bytes, so a valid frame hidden behind a false
// start byte is still found. Checking type and length first keeps a false start from holding
// back the frames behind it: it can hold at most one frame's length (21 bytes for ENCODERS).
// It buffers at most one frame.

typedef void (*slamo_frame_handler)(void* context, const slamo_frame* frame);

typedef struct {
  uint8_t buf[SLAMO_MAX_FRAME];
  uint8_t n;  // bytes in buf; buf[0] is a start byte whenever n > 0
  uint32_t frames_ok;
  uint32_t crc_errors;
  uint32_t length_errors;
  uint32_t type_errors;    // a start byte followed by a type this codec does not know
  uint32_t bytes_skipped;  // bytes dropped while looking for a start byte
} slamo_parser;

static inline void slamo_parser_init(slamo_parser* p) { memset(p, 0, sizeof(*p)); }

// Drops buf[0] and everything up to the next start byte.
static inline void slamo_parser_resync(slamo_parser* p) {
  uint8_t i = 1;
  while (i < p->n && p->buf[i] != SLAMO_FRAME_START) ++i;
  p->bytes_skipped += (uint32_t)(i - 1);  // the false start byte itself is counted as an error
  memmove(p->buf, p->buf + i, (size_t)(p->n - i));
  p->n = (uint8_t)(p->n - i);
}

// Consumes complete frames at the front of the buffer.
static inline void slamo_parser_process(slamo_parser* p, slamo_frame_handler handler,
                                        void* context) {
  while (p->n >= SLAMO_HEADER_BYTES) {
    const uint8_t type = p->buf[1];
    const uint8_t len = p->buf[3];
    const int expected = slamo_expected_length(type);
    if (expected < 0) {
      ++p->type_errors;
      slamo_parser_resync(p);
      continue;
    }
    if (len != (uint8_t)expected) {
      ++p->length_errors;
      slamo_parser_resync(p);
      continue;
    }
    const uint8_t total = (uint8_t)(SLAMO_HEADER_BYTES + len + SLAMO_CRC_BYTES);
    if (p->n < total) return;
    const uint16_t crc = slamo_crc16(p->buf + 1, (uint16_t)(3 + len));
    const uint16_t got = slamo_get_u16(p->buf + SLAMO_HEADER_BYTES + len);
    if (crc != got) {
      ++p->crc_errors;
      slamo_parser_resync(p);
      continue;
    }
    slamo_frame frame;
    frame.type = type;
    frame.seq = p->buf[2];
    frame.len = len;
    if (len > 0) memcpy(frame.payload, p->buf + SLAMO_HEADER_BYTES, len);
    memmove(p->buf, p->buf + total, (size_t)(p->n - total));
    p->n = (uint8_t)(p->n - total);
    // Whatever follows a frame must start with a start byte again.
    uint8_t skip = 0;
    while (skip < p->n && p->buf[skip] != SLAMO_FRAME_START) ++skip;
    if (skip > 0) {
      p->bytes_skipped += skip;
      memmove(p->buf, p->buf + skip, (size_t)(p->n - skip));
      p->n = (uint8_t)(p->n - skip);
    }
    ++p->frames_ok;
    if (handler) handler(context, &frame);
  }
}

static inline void slamo_parser_push(slamo_parser* p, uint8_t byte, slamo_frame_handler handler,
                                     void* context) {
  if (p->n == 0 && byte != SLAMO_FRAME_START) {
    ++p->bytes_skipped;
    return;
  }
  p->buf[p->n++] = byte;  // n < SLAMO_MAX_FRAME here: process() leaves at most total - 1 bytes
  slamo_parser_process(p, handler, context);
}

#endif  // SLAMO_PLATFORM_FIRMWARE_PROTOCOL_CODEC_H_
