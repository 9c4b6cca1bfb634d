#include "platform/serial_protocol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "field_configs/loader.h"
#include "platform/firmware/board_logic.h"
#include "platform/motor.h"

namespace slamo::platform::serial {
namespace {

std::vector<Message> OneOfEach() {
  return {SetSpeed{-67, 32767},
          SetPwm{0, 180},
          Stop{},
          SetPid{60000, 300000, -1, 2147483647},
          HostHeartbeat{0xDEADBEEF},
          Encoders{0xFFFFFFF0u, -2147483647 - 1, 123456, 12, 168,
                   SLAMO_FLAG_SPEED_MODE | SLAMO_FLAG_LINK_UP},
          BoardHeartbeat{7, 123456789, 65535, 3},
          Ack{SLAMO_MSG_SET_PID, 200},
          Error{SLAMO_ERR_BAD_VALUE, SLAMO_MSG_SET_PWM, 9}};
}

bool SameMessage(const Message& a, const Message& b) {
  // Compare through the encoding: equal messages encode to equal bytes.
  return Encode(a, 0) == Encode(b, 0);
}

TEST(SerialProtocolTest, Crc16IsCcittFalse) {
  const char* check = "123456789";
  EXPECT_EQ(slamo_crc16(reinterpret_cast<const uint8_t*>(check), 9), 0x29B1);
}

TEST(SerialProtocolTest, EveryMessageRoundTrips) {
  uint8_t seq = 250;
  for (const Message& message : OneOfEach()) {
    const std::vector<uint8_t> bytes = Encode(message, seq);
    ASSERT_GE(bytes.size(), 6u);
    EXPECT_EQ(bytes[0], kFrameStart);
    EXPECT_EQ(bytes[1], static_cast<uint8_t>(TypeOf(message)));
    EXPECT_EQ(bytes[2], seq);
    EXPECT_EQ(bytes[3], bytes.size() - 6);
    EXPECT_EQ(static_cast<int>(bytes[3]), slamo_expected_length(bytes[1]));
    Parser parser;
    const std::vector<Frame> frames = parser.Feed(bytes);
    ASSERT_EQ(frames.size(), 1u) << TypeName(bytes[1]);
    EXPECT_EQ(frames[0].seq, seq);
    const std::optional<Message> decoded = Decode(frames[0]);
    ASSERT_TRUE(decoded.has_value()) << TypeName(bytes[1]);
    EXPECT_EQ(decoded->index(), message.index());
    EXPECT_TRUE(SameMessage(*decoded, message)) << TypeName(bytes[1]);
    ++seq;
  }
}

TEST(SerialProtocolTest, FieldsDecodeToTheValuesSent) {
  Parser parser;
  const auto frames =
      parser.Feed(Encode(Encoders{4000000000u, -5, 70000, 3, 177, SLAMO_FLAG_WATCHDOG_STOP}, 1));
  ASSERT_EQ(frames.size(), 1u);
  const auto m = std::get<Encoders>(*Decode(frames[0]));
  EXPECT_EQ(m.t_us, 4000000000u);
  EXPECT_EQ(m.left_ticks, -5);
  EXPECT_EQ(m.right_ticks, 70000);
  EXPECT_EQ(m.left_pwm, 3);
  EXPECT_EQ(m.right_pwm, 177);
  EXPECT_EQ(m.flags, SLAMO_FLAG_WATCHDOG_STOP);
  // Little-endian on the wire (PROTOCOL.md): t_us 4000000000 = 0xEE6B2800.
  const std::vector<uint8_t> bytes = Encode(Encoders{4000000000u, 0, 0, 90, 90, 0}, 1);
  EXPECT_EQ(bytes[4], 0x00);
  EXPECT_EQ(bytes[5], 0x28);
  EXPECT_EQ(bytes[6], 0x6B);
  EXPECT_EQ(bytes[7], 0xEE);
}

TEST(SerialProtocolTest, ConversionsFromRobotUnits) {
  const SetPid pid = SetPidFromGains(field::LoadRobotConfig("thesis_robot").drive.pid);
  EXPECT_EQ(pid.kp_milli, 60000);
  EXPECT_EQ(pid.ki_milli, 300000);
  EXPECT_EQ(pid.kd_milli, 0);
  EXPECT_EQ(pid.integral_limit_milli, 60000);
  const SetSpeed speed = SetSpeedFromMps(0.067, -0.0674);
  EXPECT_EQ(speed.left_mm_s, 67);
  EXPECT_EQ(speed.right_mm_s, -67);
  EXPECT_EQ(SetSpeedFromMps(1e9, std::nan("")).left_mm_s, 32767);
  EXPECT_EQ(SetSpeedFromMps(1e9, std::nan("")).right_mm_s, 0);
}

TEST(SerialProtocolTest, EveryCorruptedByteIsRejectedAndCounted) {
  const std::vector<uint8_t> good = Encode(SetPid{1, 2, 3, 4}, 17);
  for (size_t i = 1; i < good.size(); ++i) {
    for (uint8_t flip : {0x01, 0x80, 0xFF}) {
      std::vector<uint8_t> bad = good;
      bad[i] ^= flip;
      Parser parser;
      EXPECT_TRUE(parser.Feed(bad).empty()) << "byte " << i << " flip " << int(flip);
      // A good frame right after is still found.
      const auto frames = parser.Feed(good);
      ASSERT_EQ(frames.size(), 1u) << "byte " << i << " flip " << int(flip);
      const ParserStats s = parser.stats();
      EXPECT_GE(s.crc_errors + s.length_errors + s.type_errors, 1u) << "byte " << i;
    }
  }
}

TEST(SerialProtocolTest, WrongLengthForAKnownTypeIsALengthError) {
  // A SET_SPEED claiming 5 payload bytes (it has 4), with a correct CRC.
  uint8_t payload[5] = {1, 2, 3, 4, 5};
  uint8_t frame[SLAMO_MAX_FRAME];
  const uint8_t n = slamo_encode_frame(SLAMO_MSG_SET_SPEED, 0, payload, 5, frame);
  Parser parser;
  EXPECT_TRUE(parser.Feed(frame, n).empty());
  EXPECT_EQ(parser.stats().length_errors, 1u);
  // Over the maximum payload.
  const uint8_t too_long[] = {kFrameStart, SLAMO_MSG_SET_PWM, 0, SLAMO_MAX_PAYLOAD + 1};
  EXPECT_TRUE(parser.Feed(too_long, sizeof(too_long)).empty());
  EXPECT_EQ(parser.stats().length_errors, 2u);
  // A type the codec does not know is rejected at its header, even with a valid CRC.
  const uint8_t m = slamo_encode_frame(0x42, 3, payload, 3, frame);
  EXPECT_TRUE(parser.Feed(frame, m).empty());
  EXPECT_EQ(parser.stats().type_errors, 1u);
  // A hand-built frame of an unknown type does not decode.
  Frame unknown;
  unknown.type = 0x42;
  unknown.payload = {1, 2, 3};
  EXPECT_FALSE(Decode(unknown).has_value());
  unknown.type = SLAMO_MSG_SET_SPEED;
  EXPECT_FALSE(Decode(unknown).has_value());  // 3 bytes, SET_SPEED has 4
  EXPECT_STREQ(TypeName(0x42), "UNKNOWN");
}

TEST(SerialProtocolTest, ResyncsAfterGarbageIncludingFalseStartBytes) {
  std::vector<uint8_t> stream = {0x00, 0x13, kFrameStart, kFrameStart, 0x81, 0x07, kFrameStart};
  const std::vector<uint8_t> a = Encode(SetSpeed{100, -100}, 1);
  const std::vector<uint8_t> b = Encode(HostHeartbeat{42}, 2);
  stream.insert(stream.end(), a.begin(), a.end());
  // A false start with an unknown type and a long claimed length swallows the next frame;
  // the parser must find it again inside the rejected bytes.
  const std::vector<uint8_t> trap = {kFrameStart, 0x77, 0x00, 30};
  stream.insert(stream.end(), trap.begin(), trap.end());
  stream.insert(stream.end(), b.begin(), b.end());
  stream.insert(stream.end(), a.begin(), a.end());
  stream.insert(stream.end(), a.begin(), a.end());
  Parser parser;
  std::vector<Frame> frames;
  for (uint8_t byte : stream) {  // byte by byte, as a UART delivers them
    for (Frame& f : parser.Feed(&byte, 1)) frames.push_back(std::move(f));
  }
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0].type, SLAMO_MSG_SET_SPEED);
  EXPECT_EQ(frames[1].type, SLAMO_MSG_HOST_HEARTBEAT);
  EXPECT_EQ(frames[2].type, SLAMO_MSG_SET_SPEED);
  EXPECT_EQ(frames[3].type, SLAMO_MSG_SET_SPEED);
  EXPECT_GT(parser.stats().bytes_skipped, 0u);
  const ParserStats s = parser.stats();
  EXPECT_GE(s.crc_errors + s.length_errors + s.type_errors, 3u);
}

TEST(SerialProtocolTest, RandomGarbageBetweenFramesLosesNoFrame) {
  std::mt19937 rng(7);
  std::vector<uint8_t> stream;
  const std::vector<Message> all = OneOfEach();
  int sent = 0;
  for (int i = 0; i < 2000; ++i) {
    const int garbage = static_cast<int>(rng() % 12);
    for (int g = 0; g < garbage; ++g) {
      stream.push_back(rng() % 4 == 0 ? kFrameStart : static_cast<uint8_t>(rng()));
    }
    const std::vector<uint8_t> f = Encode(all[rng() % all.size()], static_cast<uint8_t>(i));
    stream.insert(stream.end(), f.begin(), f.end());
    ++sent;
  }
  Parser parser;
  size_t pos = 0;
  size_t received = 0;
  while (pos < stream.size()) {  // random chunking
    const size_t n = std::min(stream.size() - pos, static_cast<size_t>(1 + rng() % 64));
    for (const Frame& f : parser.Feed(stream.data() + pos, n)) {
      received += Decode(f).has_value() ? 1 : 0;
    }
    pos += n;
  }
  // Garbage would need a known type, its exact length and a matching CRC to pass; a false
  // start can delay a real frame but never hide it.
  EXPECT_EQ(received, static_cast<size_t>(sent));
}

// The firmware's PWM maths agree with the host's motor model.
TEST(SerialProtocolTest, FirmwarePwmCurveMatchesMotorModel) {
  const field::DriveConfig drive = field::LoadRobotConfig("thesis_robot").drive;
  slamo_fw::PwmConfig pwm{
      static_cast<int16_t>(drive.pwm.full_forward), static_cast<int16_t>(drive.pwm.stop),
      static_cast<int16_t>(drive.pwm.full_reverse), static_cast<int16_t>(drive.pwm.deadband),
      static_cast<float>(drive.pwm.curve_exponent)};
  for (double fraction = -1.2; fraction <= 1.2; fraction += 0.01) {
    const double host = SpeedFractionToPwmOffset(drive.pwm, fraction);
    const float board = slamo_fw::SpeedFractionToPwmOffset(pwm, static_cast<float>(fraction));
    EXPECT_NEAR(board, host, 1e-3) << fraction;
  }
  for (double offset = -100.0; offset <= 100.0; offset += 0.37) {
    // float and double may round an exact half differently
    if (std::abs(std::abs(offset - std::trunc(offset)) - 0.5) < 1e-3) continue;
    EXPECT_EQ(slamo_fw::PwmFromOffset(pwm, static_cast<float>(offset)),
              PwmFromOffset(drive.pwm, offset))
        << offset;
  }
}

}  // namespace
}  // namespace slamo::platform::serial
