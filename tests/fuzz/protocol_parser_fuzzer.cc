// libFuzzer target: the serial protocol's streaming parser (host and firmware share it), the
// message decoder, and the board's logic fed the same bytes. Properties checked: every frame
// the parser passes has its type's exact length; a decoded message re-encodes to a frame that
// parses back to the same bytes; the board never drives a PWM outside 0..180 and is stopped
// once its link watchdog has run out.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "platform/firmware/board_logic.h"
#include "platform/serial_protocol.h"

namespace {

void Check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace slamo::platform::serial;
  if (size == 0) return 0;
  // The first byte picks the chunk size: frames split anywhere across reads.
  const size_t chunk = 1 + data[0] % 40;
  ++data;
  --size;

  Parser parser;
  slamo_fw::BoardLogic board(slamo_fw::ThesisBoardConfig());
  uint32_t now_us = 0;
  for (size_t pos = 0; pos < size; pos += chunk) {
    const size_t n = std::min(chunk, size - pos);
    for (const Frame& frame : parser.Feed(data + pos, n)) {
      Check(static_cast<int>(frame.payload.size()) == slamo_expected_length(frame.type));
      const auto message = Decode(frame);
      Check(message.has_value());
      const std::vector<uint8_t> again = Encode(*message, frame.seq);
      Parser reparse;
      const std::vector<Frame> back = reparse.Feed(again);
      Check(back.size() == 1 && back[0].type == frame.type && back[0].seq == frame.seq &&
            back[0].payload == frame.payload);
    }
    for (size_t i = 0; i < n; ++i) board.OnByte(data[pos + i], now_us);
    // Encoder counts from the input too, so the PID sees wild speeds.
    const int32_t ticks = n >= 4 ? static_cast<int32_t>(slamo_get_u32(data + pos)) : 0;
    board.Poll(now_us, ticks, static_cast<int32_t>(0u - static_cast<uint32_t>(ticks)));
    Check(board.left_pwm() <= 180 && board.right_pwm() <= 180);
    while (board.TxCount() > 0) board.TxPop();
    now_us += 1000u * (1 + static_cast<uint32_t>(n % 7));
  }
  const ParserStats s = parser.stats();
  Check(s.bytes_skipped <= size);
  // Silence: the watchdog must stop the motors.
  board.Poll(now_us + 60000u, 0, 0);
  board.Poll(now_us + 120000u, 0, 0);
  Check(board.left_pwm() == 90 && board.right_pwm() == 90);
  return 0;
}
