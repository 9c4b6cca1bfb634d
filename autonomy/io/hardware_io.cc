#include "autonomy/io/hardware_io.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "field_configs/summary.h"

namespace slamo::autonomy {

using platform::Pose2D;

RecordedStreamCamera::RecordedStreamCamera(std::unique_ptr<platform::RecordingReader> reader,
                                           const platform::Clock& match_clock, bool loop)
    : reader_(std::move(reader)), clock_(match_clock), loop_(loop) {}

bool RecordedStreamCamera::ReadNext() {
  next_ = reader_->Grab();
  if (!next_ && loop_ && have_first_ && shown_ >= 0) {
    // Start again: the next pass follows the last frame by one mean frame period.
    const size_t n = std::max<size_t>(reader_->frame_count(), 1);
    const double span_s = last_t_s_ - first_t_s_;
    const double period_s = n > 1 ? span_s / static_cast<double>(n - 1) : 1.0 / 30.0;
    loop_offset_s_ += span_s + period_s;
    ++loops_;
    reader_ = platform::OpenRecording(reader_->path());
    next_ = reader_->Grab();
  }
  if (!next_) return false;
  if (!have_first_) {
    have_first_ = true;
    first_t_s_ = next_->t_s;
  }
  last_t_s_ = next_->t_s;
  next_->t_s = next_->t_s - first_t_s_ + loop_offset_s_;  // on the match clock
  return true;
}

std::optional<platform::RgbdFrame> RecordedStreamCamera::Grab() {
  if (!have_first_ && !ReadNext()) return std::nullopt;
  const double now_s = clock_.NowS();
  std::optional<platform::RgbdFrame> latest;
  while (next_ && next_->t_s <= now_s + 1e-9) {
    latest = std::move(next_);
    next_.reset();
    ++shown_;
    ReadNext();
  }
  if (latest) latest->index = shown_;
  return latest;
}

FakeBoardCamera::FakeBoardCamera(const field::SeasonConfig& season, const field::RobotConfig& robot,
                                 const platform::FakeBoard& board, const Pose2D& start,
                                 const platform::Clock& clock, uint64_t seed)
    : world_(platform::CreateWorld(season, seed)),
      renderer_(season, robot.camera, platform::RenderOptions{}, seed),
      board_(board),
      start_(start),
      clock_(clock),
      period_s_(1.0 / robot.camera.frame_rate_hz) {}

Pose2D FakeBoardCamera::Truth() const {
  const Pose2D& m = board_.motors().true_pose();
  const double c = std::cos(start_.theta_rad), s = std::sin(start_.theta_rad);
  return {start_.x_m + c * m.x_m - s * m.y_m, start_.y_m + s * m.x_m + c * m.y_m,
          platform::WrapAngleRad(start_.theta_rad + m.theta_rad)};
}

std::optional<platform::RgbdFrame> FakeBoardCamera::Grab() {
  if (clock_.NowS() + 1e-9 < next_s_) return std::nullopt;
  next_s_ = clock_.NowS() + period_s_;
  return renderer_.Render(world_, Truth(), clock_.NowS(), nullptr);
}

HardwareIo::HardwareIo(platform::SerialDriveBase* board, platform::RgbdCamera* camera,
                       const platform::Clock& base_clock, std::function<void(double)> pace,
                       const HardwareIoOptions& options)
    : board_(board),
      camera_(camera),
      base_clock_(base_clock),
      pace_(std::move(pace)),
      options_(options),
      match_clock_(base_clock) {}

bool HardwareIo::Connect() {
  const double give_up_s = base_clock_.NowS() + options_.connect_timeout_s;
  board_->Poll();
  while (!board_->link_up() && base_clock_.NowS() < give_up_s) {
    pace_(0.001);
    board_->Poll();
  }
  return board_->link_up();
}

void HardwareIo::Start(const field::SeasonConfig& field, const field::RobotConfig& robot,
                       const Pose2D& start) {
  robot_ = robot;
  match_clock_.StartNow();
  link_losses_at_start_ = board_->stats().link_losses;
  odometry_.emplace(
      platform::kPi * robot.drive.wheel_diameter_m / robot.drive.encoder_ticks_per_rev,
      robot.drive.track_width_m, board_->ReadEncoders(), start);
  // The preload, as loaded by hand: the season's object of the alliance's colour under the
  // robot's footprint nearest its centre (the simulator's rule, platform/sim/sim_field.h).
  const double c = std::cos(start.theta_rad), s = std::sin(start.theta_rad);
  double best = std::numeric_limits<double>::infinity();
  for (const field::ObjectPlacement& p : field.objects) {
    if (!p.position_m || p.z_m > 0.0 || !field::ScoresFor(field, p.colour, options_.alliance))
      continue;
    const double dx = p.position_m->x - start.x_m, dy = p.position_m->y - start.y_m;
    const double ahead = c * dx + s * dy, side = -s * dx + c * dy;
    if (std::abs(ahead) > robot.length_m / 2.0 || std::abs(side) > robot.width_m / 2.0) continue;
    if (std::hypot(dx, dy) < best) {
      best = std::hypot(dx, dy);
      preload_ = IntakeItem{p.type, p.colour, true};
    }
  }
  held_ = preload_.has_value();
  started_ = true;
}

void HardwareIo::Advance(double dt_s) {
  const double target_s = base_clock_.NowS() + dt_s;
  for (double left_s = dt_s; left_s > 1e-9; left_s = target_s - base_clock_.NowS()) {
    pace_(std::min(0.001, left_s));
    board_->Poll();
  }
  if (!odometry_) return;
  const platform::EncoderTicks ticks = board_->ReadEncoders();
  odometry_->Update(ticks);
  if (options_.recorder && started_) {
    const double t_s = match_clock_.NowS();
    options_.recorder->AddEncoders({t_s, ticks.left, ticks.right});
    if (const std::optional<Pose2D> truth = TruePose())
      options_.recorder->AddGroundTruth({t_s, *truth});
  }
}

Pose2D HardwareIo::OdometryPose() const { return odometry_ ? odometry_->pose() : Pose2D{}; }

bool HardwareIo::MotorsDriven() const {
  // As the board last reported them (a lost link keeps the last report; the board's own
  // watchdog stops the motors 50 ms after the link is lost).
  const std::optional<platform::serial::Encoders>& e = board_->last_encoder_frame();
  return e && (e->left_pwm != robot_.drive.pwm.stop || e->right_pwm != robot_.drive.pwm.stop);
}

std::optional<platform::RgbdFrame> HardwareIo::Capture() {
  const double give_up_s = base_clock_.NowS() + options_.frame_wait_s;
  while (true) {
    if (std::optional<platform::RgbdFrame> frame = GrabOnce()) return frame;
    if (base_clock_.NowS() >= give_up_s) break;
    Advance(0.005);
  }
  ++frames_missed_;
  return std::nullopt;
}

// None ready is not a miss: the drive goes on, and the next period asks again.
std::optional<platform::RgbdFrame> HardwareIo::CaptureReady() { return GrabOnce(); }

std::optional<platform::RgbdFrame> HardwareIo::GrabOnce() {
  std::optional<platform::RgbdFrame> frame = camera_->Grab();
  if (!frame) return std::nullopt;
  ++frames_;
  if (options_.recorder && started_ && match_clock_.NowS() > last_frame_s_ + 1e-6) {
    platform::RgbdFrame stamped = *frame;
    stamped.t_s = last_frame_s_ = match_clock_.NowS();
    options_.recorder->AddFrame(stamped);
  }
  return frame;
}

std::optional<IntakeItem> HardwareIo::Pick(const strategy::ObjectBelief& target) {
  if (held_) return std::nullopt;  // the intake holds one already
  held_ = true;
  ++picks_assumed_;
  return IntakeItem{target.kind, target.colour, true};
}

std::optional<ReleaseOutcome> HardwareIo::Release(int intended_goal) {
  if (!held_) return std::nullopt;
  held_ = false;
  ++releases_assumed_;
  // Taken on trust: where it was aimed (the floor, for a drop).
  return ReleaseOutcome{intended_goal >= 0 ? std::optional<int>(intended_goal) : std::nullopt,
                        true};
}

std::string HardwareIo::Describe() const {
  return "board " + options_.board_name + ", camera " + options_.camera_name;
}

std::map<std::string, double> HardwareIo::Status() const {
  const platform::SerialDriveStats& s = board_->stats();
  return {
      {"link_losses", static_cast<double>(s.link_losses - link_losses_at_start_)},
      {"link_ups", static_cast<double>(s.link_ups)},
      {"port_opens", static_cast<double>(s.port_opens)},
      {"encoder_frames", static_cast<double>(s.encoder_frames)},
      {"frames_sent", static_cast<double>(s.frames_sent)},
      {"crc_errors", static_cast<double>(s.parser.crc_errors)},
      {"bytes_skipped", static_cast<double>(s.parser.bytes_skipped)},
      {"board_errors", static_cast<double>(s.errors)},
      {"board_rx_errors", static_cast<double>(s.board_rx_errors)},
      {"board_watchdog_trips", static_cast<double>(s.board_watchdog_trips)},
      {"max_rtt_ms", s.max_rtt_s * 1e3},
      {"camera_frames", static_cast<double>(frames_)},
      {"camera_frames_missed", static_cast<double>(frames_missed_)},
      {"picks_assumed", static_cast<double>(picks_assumed_)},
      {"releases_assumed", static_cast<double>(releases_assumed_)},
  };
}

}  // namespace slamo::autonomy
