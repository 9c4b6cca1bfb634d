// slamo motor-controller board: Arduino Mega 2560 driving four VEX Motor 393 through VEX Motor
// Controller 29 (servo PWM: 0 = full forward, 90 = stop, 180 = full reverse; thesis appendix
// A-B), reading the 393 Integrated Motor Encoders over I2C, running the per-side PID speed
// loop and talking the slamo serial protocol (platform/PROTOCOL.md) to the laptop over USB.
//
// Everything that decides anything (protocol, PID, link watchdog) is in ../board_logic.h,
// which the host's fake board compiles and tests too. This file is only the I/O around it:
//   - UART (USB) at 115200 baud, never blocking on write;
//   - servo pulses from the 16-bit hardware timers 4 and 5 (no Servo library: Debian's
//     arduino-core-avr does not ship it), with Servo.write()'s angle-to-pulse mapping;
//   - the I2C encoder chain (Henning's I2CEncoder register map, which the thesis used);
//   - the AVR hardware watchdog, which resets a hung loop.
//
// NOT VERIFIED WITHOUT HARDWARE (it builds in CI; nothing here has run on a Mega yet):
//   - the IME register map and byte order (from the I2CEncoder library the thesis cites),
//     the address assignment sequence and the chain order / mounting signs below;
//   - that an MC29 stops when its input goes quiet after a watchdog reset (the pins float);
//   - Servo.write(90) = 1472 us being inside the MC29's neutral band on this robot;
//   - that the Mega's bootloader copes with a watchdog reset (old stk500v2 bootloaders loop).
//
// Pins: left motors on 6 and 7 (OC4A, OC4B), right motors on 46 and 45 (OC5A, OC5B); the
// encoder chain on SDA 20 / SCL 21.
#include <Wire.h>
#include <avr/wdt.h>

#include "board_logic.h"

namespace {

// --- Servo pulses ---------------------------------------------------------------------------
// Timers 4 and 5 in mode 14 (fast PWM, TOP = ICRn), prescaler 8: 0.5 us per count, 20 ms
// frames. The pulse for a "PWM" value (0..180) is Servo.write()'s: 544 + value * 1856 / 180 us.
const uint16_t kFrameCounts = 40000;  // 20 ms
const uint16_t kMinPulseUs = 544;
const uint16_t kMaxPulseUs = 2400;

uint16_t PulseCounts(uint8_t value) {
  if (value > 180) value = 180;
  const uint32_t us = kMinPulseUs + (uint32_t)value * (kMaxPulseUs - kMinPulseUs) / 180u;
  return (uint16_t)(us * 2u);
}

void SetupServoTimers(uint8_t stop_value) {
  const uint16_t stop = PulseCounts(stop_value);
  // Compare values first so the first frame already carries the stop pulse.
  OCR4A = stop;
  OCR4B = stop;
  OCR5A = stop;
  OCR5B = stop;
  ICR4 = kFrameCounts - 1;
  ICR5 = kFrameCounts - 1;
  TCCR4A = _BV(COM4A1) | _BV(COM4B1) | _BV(WGM41);
  TCCR4B = _BV(WGM43) | _BV(WGM42) | _BV(CS41);
  TCCR5A = _BV(COM5A1) | _BV(COM5B1) | _BV(WGM51);
  TCCR5B = _BV(WGM53) | _BV(WGM52) | _BV(CS51);
  pinMode(6, OUTPUT);   // OC4A, left front
  pinMode(7, OUTPUT);   // OC4B, left rear
  pinMode(46, OUTPUT);  // OC5A, right front
  pinMode(45, OUTPUT);  // OC5B, right rear
}

// OCRnx is double-buffered in fast PWM: a change takes effect at the next frame, never
// mid-pulse.
void WriteServos(uint8_t left, uint8_t right) {
  const uint16_t l = PulseCounts(left);
  const uint16_t r = PulseCounts(right);
  OCR4A = l;
  OCR4B = l;
  OCR5A = r;
  OCR5B = r;
}

// --- VEX 393 Integrated Motor Encoders on I2C -------------------------------------------------
// Register map of the I2CEncoder library (Henning) the thesis used. Every IME powers up at
// 0x30 and terminated (it hides the rest of the chain); each in turn gets a new address and is
// then unterminated to reach the next one.
const uint8_t kImeDefaultAddress = 0x30;
const uint8_t kImeFirstAddress = 0x20;
const uint8_t kImeRegPosition = 0x40;  // 4 bytes: bits 15..8, 7..0, 31..24, 23..16
const uint8_t kImeRegZero = 0x4A;
const uint8_t kImeRegUnterminate = 0x4B;
const uint8_t kImeRegAddress = 0x4D;  // write the new address, shifted to 8 bits

const uint8_t kImeCount = 4;
// Chain order as cabled: 0 left front, 1 left rear, 2 right front, 3 right rear (UNVERIFIED).
// +1 where the motor counts up driving forward, -1 where it is mounted mirrored (UNVERIFIED:
// check by pushing the robot forward and watching `slamo board ping`).
const int8_t kImeSign[kImeCount] = {-1, -1, 1, 1};
const bool kImeLeftSide[kImeCount] = {true, true, false, false};

int32_t ime_position[kImeCount];

bool ImeCommand(uint8_t address, uint8_t reg) {
  Wire.beginTransmission(address);
  Wire.write(reg);
  return Wire.endTransmission() == 0;
}

bool SetupEncoders() {
  bool ok = true;
  for (uint8_t i = 0; i < kImeCount; ++i) {
    if (i > 0) ok &= ImeCommand(kImeFirstAddress + i - 1, kImeRegUnterminate);
    Wire.beginTransmission(kImeDefaultAddress);
    Wire.write(kImeRegAddress);
    Wire.write((uint8_t)((kImeFirstAddress + i) << 1));
    ok &= Wire.endTransmission() == 0;
    delay(2);
    ok &= ImeCommand(kImeFirstAddress + i, kImeRegZero);
    ime_position[i] = 0;
  }
  return ok;
}

bool ReadImePosition(uint8_t index) {
  const uint8_t address = kImeFirstAddress + index;
  if (!ImeCommand(address, kImeRegPosition)) return false;
  if (Wire.requestFrom(address, (uint8_t)4) != 4) return false;
  uint8_t b[4];
  for (uint8_t i = 0; i < 4; ++i) b[i] = (uint8_t)Wire.read();
  const uint32_t raw = ((uint32_t)b[0] << 8) | (uint32_t)b[1] | ((uint32_t)b[2] << 24) |
                       ((uint32_t)b[3] << 16);
  ime_position[index] = (int32_t)raw;
  return true;
}

// Per-side counts: the mean of the side's two encoders, positive forward. A failed read keeps
// the encoder's last value and raises the ENCODER_FAULT flag.
bool ReadSides(int32_t* left, int32_t* right) {
  bool ok = true;
  int32_t sum_left = 0;
  int32_t sum_right = 0;
  for (uint8_t i = 0; i < kImeCount; ++i) {
    ok &= ReadImePosition(i);
    const int32_t v = kImeSign[i] * ime_position[i];
    if (kImeLeftSide[i]) {
      sum_left += v;
    } else {
      sum_right += v;
    }
  }
  *left = sum_left / 2;
  *right = sum_right / 2;
  return ok;
}

slamo_fw::BoardLogic logic(slamo_fw::ThesisBoardConfig());
int32_t left_ticks = 0;
int32_t right_ticks = 0;

}  // namespace

void setup() {
  // A watchdog reset leaves the watchdog running at its shortest period: off first.
  MCUSR = 0;
  wdt_disable();
  const slamo_fw::BoardConfig config = slamo_fw::ThesisBoardConfig();
  SetupServoTimers((uint8_t)config.pwm.stop);
  Serial.begin(115200);
  Wire.begin();
  Wire.setClock(100000);
  Wire.setWireTimeout(3000, true);  // a stuck bus costs at most 3 ms per transaction
  logic.set_encoder_fault(!SetupEncoders());
  logic.Reset(micros());
  // A loop that hangs for 60 ms resets the board; after a reset the timers are off, the
  // motor pins float and setup() starts the stop pulses again.
  wdt_enable(WDTO_60MS);
}

void loop() {
  wdt_reset();
  while (Serial.available() > 0) logic.OnByte((uint8_t)Serial.read(), micros());
  if (logic.TicksWanted(micros())) {
    logic.set_encoder_fault(!ReadSides(&left_ticks, &right_ticks));
  }
  logic.Poll(micros(), left_ticks, right_ticks);
  WriteServos(logic.left_pwm(), logic.right_pwm());
  while (logic.TxCount() > 0 && Serial.availableForWrite() > 0) Serial.write(logic.TxPop());
}
