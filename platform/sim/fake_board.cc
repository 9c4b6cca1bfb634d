#include "platform/sim/fake_board.h"

#include <fcntl.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <utility>

namespace slamo::platform {

slamo_fw::BoardConfig BoardConfigFromDrive(const field::DriveConfig& drive) {
  slamo_fw::BoardConfig c = slamo_fw::ThesisBoardConfig();
  c.pwm.full_forward = static_cast<int16_t>(drive.pwm.full_forward);
  c.pwm.stop = static_cast<int16_t>(drive.pwm.stop);
  c.pwm.full_reverse = static_cast<int16_t>(drive.pwm.full_reverse);
  c.pwm.deadband = static_cast<int16_t>(drive.pwm.deadband);
  c.pwm.curve_exponent = static_cast<float>(drive.pwm.curve_exponent);
  c.pid.kp = static_cast<float>(drive.pid.kp);
  c.pid.ki = static_cast<float>(drive.pid.ki);
  c.pid.kd = static_cast<float>(drive.pid.kd);
  c.pid.integral_limit = static_cast<float>(drive.pid.integral_limit);
  c.max_speed_mps = static_cast<float>(drive.max_speed_mps);
  c.metres_per_tick =
      static_cast<float>(kPi * drive.wheel_diameter_m / drive.encoder_ticks_per_rev);
  c.pid_period_us = static_cast<uint32_t>(std::lround(1e6 / drive.pid.rate_hz));
  return c;
}

FakeBoard::FakeBoard(const field::DriveConfig& drive, const FakeBoardOptions& options)
    : drive_(drive),
      options_(options),
      logic_(BoardConfigFromDrive(drive)),
      sim_(drive, options.drive, options.seed),
      rng_(options.seed ^ 0x5eedb0a7dULL) {
  sim_.SetPwm(drive.pwm.stop, drive.pwm.stop);
}

uint32_t FakeBoard::time_us() const {
  return static_cast<uint32_t>(static_cast<uint64_t>(std::llround(time_s_ * 1e6)));
}

void FakeBoard::Inject(serial::Parser* splitter, const uint8_t* data, size_t n,
                       std::deque<Pending>* queue, uint64_t* frame_count) {
  const LinkFaults& f = options_.faults;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const serial::Frame& frame : splitter->Feed(data, n)) {
    ++*frame_count;
    Pending p;
    if (f.garbage_probability > 0.0 && unit(rng_) < f.garbage_probability) {
      ++stats_.garbage_bursts;
      const int count = 1 + static_cast<int>(rng_() % 16);
      for (int i = 0; i < count; ++i) {
        // A third of the garbage is false start bytes, the hardest case for resync.
        p.bytes.push_back(rng_() % 3 == 0 ? serial::kFrameStart : static_cast<uint8_t>(rng_()));
      }
    }
    if (f.drop_probability > 0.0 && unit(rng_) < f.drop_probability) {
      ++stats_.dropped;
    } else {
      const std::vector<uint8_t> bytes = [&] {
        std::vector<uint8_t> out(serial::kMaxFrame);
        out.resize(slamo_encode_frame(frame.type, frame.seq, frame.payload.data(),
                                      static_cast<uint8_t>(frame.payload.size()), out.data()));
        return out;
      }();
      p.bytes.insert(p.bytes.end(), bytes.begin(), bytes.end());
      if (f.duplicate_probability > 0.0 && unit(rng_) < f.duplicate_probability) {
        ++stats_.duplicated;
        p.bytes.insert(p.bytes.end(), bytes.begin(), bytes.end());
      }
    }
    if (p.bytes.empty()) continue;
    double delay_s = f.delay_s;
    if (f.delay_jitter_s > 0.0) delay_s += f.delay_jitter_s * unit(rng_);
    p.due_s = time_s_ + delay_s;
    // A serial line keeps order: never before what is already queued.
    if (!queue->empty()) p.due_s = std::max(p.due_s, queue->back().due_s);
    queue->push_back(std::move(p));
  }
}

void FakeBoard::Receive(const uint8_t* data, size_t n) {
  if (!plugged_) {
    stats_.bytes_lost_unplugged += n;
    return;
  }
  Inject(&to_board_splitter_, data, n, &to_board_, &stats_.frames_to_board);
}

void FakeBoard::Advance(double dt_s) {
  loop_debt_s_ += dt_s;
  const double period_s = options_.loop_period_s;
  while (loop_debt_s_ >= period_s - 1e-12) {
    Step(period_s);
    loop_debt_s_ -= period_s;
  }
}

void FakeBoard::Step(double dt_s) {
  // Host bytes that have arrived, then the loop as the firmware runs it.
  while (!to_board_.empty() && to_board_.front().due_s <= time_s_ + 1e-12) {
    const uint32_t now_us = time_us();
    for (uint8_t b : to_board_.front().bytes) logic_.OnByte(b, now_us);
    to_board_.pop_front();
  }
  const EncoderTicks ticks = sim_.ReadEncoders();
  board_ticks_ = {time_s_, ticks.left - tick_base_left_, ticks.right - tick_base_right_};
  logic_.Poll(time_us(), static_cast<int32_t>(static_cast<uint32_t>(ticks.left - tick_base_left_)),
              static_cast<int32_t>(static_cast<uint32_t>(ticks.right - tick_base_right_)));
  const bool stopped =
      logic_.left_pwm() == drive_.pwm.stop && logic_.right_pwm() == drive_.pwm.stop;
  if (stopped && !was_stopped_) last_stop_s_ = time_s_;
  was_stopped_ = stopped;
  sim_.SetPwm(logic_.left_pwm(), logic_.right_pwm());

  std::vector<uint8_t> out;
  while (logic_.TxCount() > 0) out.push_back(logic_.TxPop());
  if (plugged_) {
    Inject(&to_host_splitter_, out.data(), out.size(), &to_host_, &stats_.frames_to_host);
  }

  sim_.Step(dt_s);
  time_s_ += dt_s;
}

std::vector<uint8_t> FakeBoard::TakeOutput() {
  std::vector<uint8_t> out;
  while (!to_host_.empty() && to_host_.front().due_s <= time_s_ + 1e-12) {
    out.insert(out.end(), to_host_.front().bytes.begin(), to_host_.front().bytes.end());
    to_host_.pop_front();
  }
  return out;
}

void FakeBoard::Unplug() {
  plugged_ = false;
  to_board_.clear();
  to_host_.clear();
  to_board_splitter_ = serial::Parser();
  to_host_splitter_ = serial::Parser();
}

void FakeBoard::Replug(bool reset_board) {
  plugged_ = true;
  if (reset_board) {
    const EncoderTicks ticks = sim_.ReadEncoders();
    tick_base_left_ = ticks.left;
    tick_base_right_ = ticks.right;
    logic_ = slamo_fw::BoardLogic(BoardConfigFromDrive(drive_));
    logic_.Reset(time_us());
  }
}

// ---------------------------------------------------------------------------------------

PtyFakeBoard::PtyFakeBoard(const field::DriveConfig& drive, const FakeBoardOptions& options,
                           std::string link_path)
    : board_(drive, options), link_path_(std::move(link_path)) {
  OpenPty();
}

PtyFakeBoard::~PtyFakeBoard() {
  ClosePty();
  if (!link_path_.empty()) {
    std::error_code ignored;
    std::filesystem::remove(link_path_, ignored);
  }
}

void PtyFakeBoard::OpenPty() {
  char name[256] = {};
  if (::openpty(&master_fd_, &slave_fd_, name, nullptr, nullptr) != 0) {
    throw std::runtime_error(std::string("openpty: ") + std::strerror(errno));
  }
  termios raw{};
  if (::tcgetattr(slave_fd_, &raw) == 0) {
    ::cfmakeraw(&raw);
    ::tcsetattr(slave_fd_, TCSANOW, &raw);
  }
  ::fcntl(master_fd_, F_SETFL, ::fcntl(master_fd_, F_GETFL) | O_NONBLOCK);
  ::fcntl(master_fd_, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave_fd_, F_SETFD, FD_CLOEXEC);
  slave_path_ = name;
  if (!link_path_.empty()) {
    const std::string tmp = link_path_ + ".new";
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    std::filesystem::create_symlink(slave_path_, tmp);
    std::filesystem::rename(tmp, link_path_);  // atomic replace
  }
}

void PtyFakeBoard::ClosePty() {
  if (master_fd_ >= 0) ::close(master_fd_);
  if (slave_fd_ >= 0) ::close(slave_fd_);
  master_fd_ = slave_fd_ = -1;
  pending_out_.clear();
}

void PtyFakeBoard::Pump(double dt_s) {
  if (master_fd_ >= 0) {
    uint8_t buf[512];
    for (;;) {
      const ssize_t got = ::read(master_fd_, buf, sizeof(buf));
      if (got <= 0) break;
      board_.Receive(buf, static_cast<size_t>(got));
    }
  }
  board_.Advance(dt_s);
  const std::vector<uint8_t> out = board_.TakeOutput();
  if (master_fd_ < 0) return;
  pending_out_.insert(pending_out_.end(), out.begin(), out.end());
  size_t written = 0;
  while (written < pending_out_.size()) {
    const ssize_t n =
        ::write(master_fd_, pending_out_.data() + written, pending_out_.size() - written);
    if (n <= 0) break;
    written += static_cast<size_t>(n);
  }
  pending_out_.erase(pending_out_.begin(), pending_out_.begin() + written);
  // A host that does not read: keep at most 4 KiB, as a USB-serial adapter would drop.
  if (pending_out_.size() > 4096) {
    bytes_overflowed_ += pending_out_.size() - 4096;
    pending_out_.erase(pending_out_.begin(), pending_out_.end() - 4096);
  }
}

void PtyFakeBoard::Unplug() {
  board_.Unplug();
  ClosePty();
  if (!link_path_.empty()) {
    std::error_code ignored;
    std::filesystem::remove(link_path_, ignored);
  }
}

void PtyFakeBoard::Replug(bool reset_board) {
  if (master_fd_ < 0) OpenPty();
  board_.Replug(reset_board);
}

}  // namespace slamo::platform
