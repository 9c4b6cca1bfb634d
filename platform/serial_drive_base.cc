#include "platform/serial_drive_base.h"

#include <poll.h>
#include <sys/ioctl.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <utility>
#include <variant>

#include <mrpt/comms/CSerialPort.h>

namespace slamo::platform {
namespace {

// CSerialPort keeps its descriptor protected; polling needs it.
class PolledSerialPort : public mrpt::comms::CSerialPort {
 public:
  int fd() const { return hCOM; }
};

class MrptSerialTransport : public SerialTransport {
 public:
  MrptSerialTransport(std::string device, int baud) : device_(std::move(device)), baud_(baud) {}

  bool Open() override {
    Close();
    try {
      auto port = std::make_unique<PolledSerialPort>();
      port->setSerialPortName(device_);
      port->open();
      port->setConfig(baud_, 0, 8, 1, false);
      port_ = std::move(port);
      return true;
    } catch (const std::exception& e) {
      last_error_ = e.what();
      return false;
    }
  }

  void Close() override {
    if (!port_) return;
    try {
      port_->close();
    } catch (const std::exception& e) {
      last_error_ = e.what();
    }
    port_.reset();
  }

  bool IsOpen() const override { return port_ && port_->isOpen(); }

  bool Read(std::vector<uint8_t>* out) override {
    if (!IsOpen()) return false;
    pollfd p{port_->fd(), POLLIN, 0};
    if (::poll(&p, 1, 0) < 0) return Gone(std::strerror(errno));
    int waiting = 0;
    if ((p.revents & POLLIN) && ::ioctl(port_->fd(), FIONREAD, &waiting) < 0) {
      return Gone(std::strerror(errno));
    }
    if (waiting > 0) {
      const size_t before = out->size();
      out->resize(before + static_cast<size_t>(waiting));
      try {
        const size_t got = port_->Read(out->data() + before, static_cast<size_t>(waiting));
        out->resize(before + got);
      } catch (const std::exception& e) {
        out->resize(before);
        return Gone(e.what());
      }
      if (!port_->isOpen()) return Gone("device disconnected (EIO)");
    }
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) return Gone("hang-up on " + device_);
    return true;
  }

  bool Write(const std::vector<uint8_t>& bytes) override {
    if (!IsOpen()) return false;
    pollfd p{port_->fd(), POLLOUT, 0};
    if (::poll(&p, 1, 0) < 0) return Gone(std::strerror(errno));
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) return Gone("hang-up on " + device_);
    if (!(p.revents & POLLOUT)) {
      last_error_ = "output would block; frame dropped";
      return false;
    }
    try {
      errno = 0;  // CSerialPort::Write retries while errno is 0 or EAGAIN
      port_->Write(bytes.data(), bytes.size());
    } catch (const std::exception& e) {
      return Gone(e.what());
    }
    return true;
  }

  std::string last_error() const override { return last_error_; }

 private:
  bool Gone(const std::string& why) {
    last_error_ = why;
    Close();
    return false;
  }

  std::string device_;
  int baud_;
  std::unique_ptr<PolledSerialPort> port_;
  std::string last_error_;
};

}  // namespace

std::unique_ptr<SerialTransport> MakeMrptSerialTransport(const std::string& device, int baud) {
  return std::make_unique<MrptSerialTransport>(device, baud);
}

const char* LinkStateName(LinkState state) {
  switch (state) {
    case LinkState::kClosed:
      return "closed";
    case LinkState::kWaiting:
      return "waiting";
    case LinkState::kUp:
      return "up";
  }
  return "?";
}

SerialDriveBase::SerialDriveBase(std::unique_ptr<SerialTransport> transport, const Clock& clock,
                                 const SerialDriveOptions& options)
    : transport_(std::move(transport)), clock_(clock), options_(options) {
  const double now_s = clock_.NowS();
  next_open_attempt_s_ = now_s;
  TryOpen(now_s);
}

void SerialDriveBase::SetSpeedTargets(double left_mps, double right_mps) {
  Poll();
  command_ = serial::SetSpeedFromMps(left_mps, right_mps);
  Send(*command_);
  next_refresh_s_ = clock_.NowS() + options_.command_refresh_s;
}

void SerialDriveBase::SetPwm(int left, int right) {
  Poll();
  const auto clamp = [](int v) { return static_cast<uint8_t>(std::clamp(v, 0, 255)); };
  command_ = serial::SetPwm{clamp(left), clamp(right)};
  Send(*command_);
  next_refresh_s_ = clock_.NowS() + options_.command_refresh_s;
}

void SerialDriveBase::Stop() {
  Poll();
  command_ = serial::Stop{};
  Send(*command_);
  next_refresh_s_ = clock_.NowS() + options_.stop_refresh_s;
}

EncoderTicks SerialDriveBase::ReadEncoders() {
  Poll();
  if (!have_ticks_) return {clock_.NowS(), left_total_, right_total_};
  return last_ticks_;
}

void SerialDriveBase::SetPidGains(const field::PidGains& gains) {
  options_.pid = gains;
  Send(serial::SetPidFromGains(gains));
}

void SerialDriveBase::TryOpen(double now_s) {
  next_open_attempt_s_ = now_s + options_.reconnect_period_s;
  if (!transport_->Open()) return;
  ++stats_.port_opens;
  state_ = LinkState::kWaiting;
  opened_s_ = now_s;
  last_rx_s_ = now_s;
  rebase_ = true;
  parser_ = serial::Parser();
  heartbeat_outstanding_ = false;
  next_heartbeat_s_ = now_s;  // say hello at once
}

void SerialDriveBase::ClosePort(double now_s) {
  if (state_ == LinkState::kUp) LoseLink(now_s);
  transport_->Close();
  ++stats_.port_closes;
  state_ = LinkState::kClosed;
  next_open_attempt_s_ = now_s + options_.reconnect_period_s;
}

void SerialDriveBase::LoseLink(double now_s) {
  ++stats_.link_losses;
  state_ = transport_->IsOpen() ? LinkState::kWaiting : LinkState::kClosed;
  // The board's watchdog stops the motors only if the host falls silent, and the heartbeats go
  // on: the stop is resent every stop_refresh_s, link up or not, until the next command (on a
  // link dropping a fifth of its frames this stop and the one before it were once both lost,
  // and the motors ran on).
  command_ = serial::Stop{};
  Send(*command_);
  next_refresh_s_ = now_s + options_.stop_refresh_s;
  rebase_ = true;
  heartbeat_outstanding_ = false;
  opened_s_ = now_s;  // the silence before reopening counts from here
}

void SerialDriveBase::Poll() {
  const double now_s = clock_.NowS();
  if (!transport_->IsOpen()) {
    if (state_ != LinkState::kClosed) ClosePort(now_s);
    if (now_s >= next_open_attempt_s_) TryOpen(now_s);
    if (!transport_->IsOpen()) return;
  }

  std::vector<uint8_t> bytes;
  const bool alive = transport_->Read(&bytes);
  for (const serial::Frame& frame : parser_.Feed(bytes)) HandleFrame(frame, now_s);
  stats_.parser = parser_.stats();
  if (!alive) {
    ClosePort(now_s);
    return;
  }

  if (state_ == LinkState::kUp && now_s - last_rx_s_ > options_.link_timeout_s) LoseLink(now_s);
  if (state_ == LinkState::kWaiting &&
      now_s - std::max(last_rx_s_, opened_s_) > options_.reopen_after_silence_s) {
    ClosePort(now_s);
    TryOpen(now_s);
    if (!transport_->IsOpen()) return;
  }

  if (now_s >= next_heartbeat_s_) {
    ++heartbeat_token_;
    if (Send(serial::HostHeartbeat{heartbeat_token_})) {
      heartbeat_sent_s_ = now_s;
      heartbeat_sent_token_ = heartbeat_token_;
      heartbeat_outstanding_ = true;
    }
    next_heartbeat_s_ = std::max(next_heartbeat_s_ + options_.heartbeat_period_s, now_s);
  }
  const bool stopping = command_ && std::holds_alternative<serial::Stop>(*command_);
  if ((state_ == LinkState::kUp || stopping) && command_ && now_s >= next_refresh_s_) {
    Send(*command_);
    next_refresh_s_ = now_s + (stopping ? options_.stop_refresh_s : options_.command_refresh_s);
  }
}

bool SerialDriveBase::Send(const serial::Message& message) {
  if (!transport_->IsOpen()) return false;
  if (!transport_->Write(serial::Encode(message, seq_++))) {
    ++stats_.writes_failed;
    return false;
  }
  ++stats_.frames_sent;
  return true;
}

void SerialDriveBase::HandleFrame(const serial::Frame& frame, double now_s) {
  const std::optional<serial::Message> message = serial::Decode(frame);
  if (!message) {
    ++stats_.unknown_frames;
    return;
  }
  // Any valid board frame proves the link.
  last_rx_s_ = now_s;
  if (state_ != LinkState::kUp) {
    state_ = LinkState::kUp;
    ++stats_.link_ups;
    if (options_.pid) Send(serial::SetPidFromGains(*options_.pid));
  }
  if (const auto* m = std::get_if<serial::Encoders>(&*message)) {
    HandleEncoders(*m, now_s);
  } else if (const auto* m = std::get_if<serial::BoardHeartbeat>(&*message)) {
    ++stats_.board_heartbeats;
    stats_.board_rx_errors = m->rx_errors;
    stats_.board_watchdog_trips = m->watchdog_trips;
    if (heartbeat_outstanding_ && m->token == heartbeat_sent_token_) {
      const double rtt_s = now_s - heartbeat_sent_s_;
      stats_.last_rtt_s = rtt_s;
      stats_.max_rtt_s = std::max(stats_.max_rtt_s, rtt_s);
      stats_.sum_rtt_s += rtt_s;
      ++stats_.rtt_samples;
      heartbeat_outstanding_ = false;
    }
  } else if (std::holds_alternative<serial::Ack>(*message)) {
    ++stats_.acks;
  } else if (std::holds_alternative<serial::Error>(*message)) {
    ++stats_.errors;
  } else {
    ++stats_.unknown_frames;  // a host -> board type coming back: ignore
  }
}

void SerialDriveBase::HandleEncoders(const serial::Encoders& m, double now_s) {
  if (!rebase_ && last_raw_ && m.t_us == last_raw_->t_us) {
    ++stats_.duplicate_encoder_frames;
    return;
  }
  ++stats_.encoder_frames;
  if (rebase_ || !last_raw_) {
    board_time_us_ = 0;
    clock_offset_s_.reset();
  } else {
    // Wrap-safe differences of the 32-bit board counters.
    left_total_ += static_cast<int32_t>(static_cast<uint32_t>(m.left_ticks) -
                                        static_cast<uint32_t>(last_raw_->left_ticks));
    right_total_ += static_cast<int32_t>(static_cast<uint32_t>(m.right_ticks) -
                                         static_cast<uint32_t>(last_raw_->right_ticks));
    board_time_us_ += static_cast<uint32_t>(m.t_us - last_raw_->t_us);
  }
  rebase_ = false;
  last_raw_ = m;
  const double board_s = 1e-6 * static_cast<double>(board_time_us_);
  const double offset_s = now_s - board_s;
  if (!clock_offset_s_ || offset_s < *clock_offset_s_) clock_offset_s_ = offset_s;
  double t_s = board_s + *clock_offset_s_;
  if (have_ticks_) t_s = std::max(t_s, last_ticks_.t_s);
  last_ticks_ = {t_s, left_total_, right_total_};
  have_ticks_ = true;
}

}  // namespace slamo::platform
