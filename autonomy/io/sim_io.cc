#include "autonomy/io/sim_io.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <optional>
#include <random>
#include <vector>

#include "platform/field_geometry.h"

#include "platform/sim/sim_drive_script.h"
#include "platform/sim/sim_field.h"
#include "platform/sim/sim_gyro.h"
#include "platform/sim/sim_renderer.h"

namespace slamo::autonomy {
namespace {

using platform::Pose2D;

// What a team measures before it trusts its encoders: drive 1 m straight a few times on an
// empty floor and compare the true distance (a tape measure) with what the encoders say. The
// mean ratio scales every commanded distance and every odometry increment; SLAM-O is left the
// random part of the slip.
double CalibrateOdometryScale(const field::RobotConfig& robot) {
  double ratio = 0.0;
  const int runs = 5;
  for (int i = 0; i < runs; ++i) {
    const std::vector<platform::DriveStepResult> r = platform::SimulateDriveScript(
        "forward 1.0", robot, platform::SimDriveOptionsFor(robot.drive), 1000 + i);
    const double truth = std::hypot(r.back().true_pose.x_m, r.back().true_pose.y_m);
    const double encoders = std::hypot(r.back().odometry_pose.x_m, r.back().odometry_pose.y_m);
    ratio += truth / encoders;
  }
  return ratio / runs;
}

class SimIo : public RobotIo {
 public:
  SimIo(field::Alliance alliance, uint64_t seed, double jitter_m, Scenario scenario)
      : alliance_(alliance), seed_(seed), jitter_m_(jitter_m), scenario_(scenario), gyro_(seed) {}

  void Start(const field::SeasonConfig& season, const field::RobotConfig& robot,
             const Pose2D& start) override {
    // The simulator and its renderer keep references to the field: it lives here.
    field_ = PlaceObjects(season, jitter_m_, seed_, scenario_);
    const field::SeasonConfig& field = field_;
    robot_ = robot;
    platform::SimFieldOptions options;
    options.preload = true;
    sim_ = std::make_unique<platform::SimField>(field, robot, alliance_, seed_, start,
                                                platform::SimDriveOptionsFor(robot.drive), options);
    if (robot.imu) gyro_ = platform::SimGyro(seed_, platform::SimGyroOptionsFor(*robot.imu));
    renderer_ = std::make_unique<platform::SimRenderer>(field, robot.camera,
                                                        platform::RenderOptions{}, seed_);
  }
  const platform::Clock& clock() const override { return clock_; }
  platform::DriveBase& drive() override { return sim_->drive(); }
  void Advance(double dt_s) override {
    sim_->Step(dt_s);
    clock_.Advance(dt_s);
    if (robot_.camera.latency_s > 0.0) {
      // The poses a frame with the camera's latency may show.
      history_.push_back({clock_.NowS(), sim_->robot_pose()});
      while (history_.size() > 2 && history_[1].first < clock_.NowS() - robot_.camera.latency_s) {
        history_.pop_front();
      }
    }
  }
  Pose2D OdometryPose() const override { return sim_->drive().odometry_pose(); }
  bool MotorsDriven() const override {
    const platform::SimDriveBase& d = sim_->drive();
    return d.left_pwm() != robot_.drive.pwm.stop || d.right_pwm() != robot_.drive.pwm.stop;
  }
  std::optional<double> GyroHeadingRad() override {
    return gyro_.Read(sim_->robot_pose().theta_rad, clock_.NowS());
  }
  // The frame exposed camera.latency_s ago: where the robot was then (between the two
  // controller periods about it), stamped with that time.
  std::optional<platform::RgbdFrame> Capture() override {
    const double t_s = clock_.NowS() - robot_.camera.latency_s;
    return renderer_->Render(sim_->world(), PoseAt(t_s), t_s, nullptr);
  }
  std::optional<IntakeItem> Pick(const strategy::ObjectBelief&) override {
    const std::optional<int> picked = sim_->Pick();
    if (!picked) return std::nullopt;
    return Item(*picked);  // the intake knows what it took (its own colour sensor)
  }
  std::optional<ReleaseOutcome> Release(int) override {
    const std::optional<platform::ReleaseResult> released = sim_->Release();
    if (!released) return std::nullopt;
    return ReleaseOutcome{released->goal_index, false};
  }
  std::optional<IntakeItem> Preload() const override {
    if (sim_->held().empty()) return std::nullopt;
    return Item(sim_->held().front());
  }
  double OdometryScale() override { return CalibrateOdometryScale(robot_); }
  std::optional<Pose2D> TruePose() const override { return sim_->robot_pose(); }
  std::optional<int> Points() const override { return sim_->Score(alliance_); }
  std::optional<std::vector<TrueObject>> TrueObjects() const override {
    std::vector<TrueObject> out;
    out.reserve(sim_->world().objects.size());
    for (const platform::SimObject& o : sim_->world().objects) {
      out.push_back(
          {o.id, o.type->name, o.colour, o.center_m, o.type->size_m / 2.0, o.held, o.in_goal});
    }
    return out;
  }
  std::string Describe() const override { return "simulated field"; }

 private:
  Pose2D PoseAt(double t_s) const {
    if (history_.empty() || t_s >= history_.back().first) return sim_->robot_pose();
    if (t_s <= history_.front().first) return history_.front().second;
    size_t k = 1;
    while (history_[k].first < t_s) ++k;
    const auto& [t0, a] = history_[k - 1];
    const auto& [t1, b] = history_[k];
    const double f = (t_s - t0) / (t1 - t0);
    return Pose2D{a.x_m + f * (b.x_m - a.x_m), a.y_m + f * (b.y_m - a.y_m),
                  a.theta_rad + f * platform::WrapAngleRad(b.theta_rad - a.theta_rad)};
  }
  std::optional<IntakeItem> Item(int id) const {
    for (const platform::SimObject& o : sim_->world().objects) {
      if (o.id == id) return IntakeItem{o.type->name, o.colour, false};
    }
    return std::nullopt;
  }

  field::Alliance alliance_;
  uint64_t seed_;
  double jitter_m_;
  Scenario scenario_;
  field::SeasonConfig field_;  // as placed
  field::RobotConfig robot_;
  platform::SimClock clock_;
  std::unique_ptr<platform::SimField> sim_;
  std::unique_ptr<platform::SimRenderer> renderer_;
  platform::SimGyro gyro_;
  std::deque<std::pair<double, Pose2D>> history_;  // (time, true pose), camera.latency_s back
};

}  // namespace

std::unique_ptr<RobotIo> MakeSimIo(field::Alliance alliance, uint64_t seed,
                                   double placement_jitter_m, Scenario scenario) {
  return std::make_unique<SimIo>(alliance, seed, placement_jitter_m, scenario);
}

field::SeasonConfig PlaceObjects(const field::SeasonConfig& season, double jitter_m, uint64_t seed,
                                 Scenario scenario) {
  field::SeasonConfig out = season;
  const bool disturbed = scenario == Scenario::kDisturbed;
  if (!disturbed && jitter_m <= 0.0) return out;
  // Its own stream for the disturbed layout, so that a seed's nominal layout stays as it was.
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + (disturbed ? 29 : 17));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> distance(kDisturbMin_m, kDisturbMax_m);
  std::uniform_real_distribution<double> direction(-platform::kPi, platform::kPi);
  const auto move = [&](const Eigen::Vector2d& nominal) -> Eigen::Vector2d {
    if (!disturbed) return nominal + jitter_m * Eigen::Vector2d(unit(rng), unit(rng));
    const double d = distance(rng), a = direction(rng);
    return nominal + d * Eigen::Vector2d(std::cos(a), std::sin(a));
  };
  std::optional<field::Vec2> stack_bottom;  // where the bottom of the current stack went
  for (field::ObjectPlacement& p : out.objects) {
    // A stack moves as one: its upper objects follow its bottom one.
    if (p.position_m && p.stack_level > 0) {
      if (stack_bottom) p.position_m = stack_bottom;
      continue;
    }
    stack_bottom.reset();
    if (!p.position_m || p.z_m > 0.0) continue;
    const Eigen::Vector2d nominal(p.position_m->x, p.position_m->y);
    const bool preload =
        std::any_of(season.starts.begin(), season.starts.end(), [&](const field::StartTile& s) {
          return (nominal - Eigen::Vector2d(s.center_m.x, s.center_m.y)).norm() < 0.3;
        });
    if (preload) continue;
    const field::ObjectType* type = season.FindObjectType(p.type);
    const double r = type ? type->size_m / 2.0 : 0.1;
    // Held in a structure (a Push Back loader's column): it stays where the structure holds it,
    // whatever the layout.
    if (platform::PointBlocksObject(season, nominal, r, type ? type->height_m : 0.0)) continue;
    for (int attempt = 0; attempt < 30; ++attempt) {
      const Eigen::Vector2d c = move(nominal);
      const double limit = season.HalfSize() - r;
      if (std::abs(c.x()) > limit || std::abs(c.y()) > limit) continue;
      if (platform::PointBlocksObject(season, c, r, type ? type->height_m : 0.0)) continue;
      p.position_m = field::Vec2{c.x(), c.y()};
      break;
    }
    if (p.stack_size > 1) stack_bottom = p.position_m;
  }
  // A goal standing on an object (a mobile goal's stake) goes where that object went.
  for (field::Goal& g : out.goals) {
    if (g.on_object.empty()) continue;
    for (size_t i = 0; i < season.objects.size(); ++i) {
      const field::ObjectPlacement& p = season.objects[i];
      if (p.type != g.on_object || !p.position_m) continue;
      if (std::hypot(p.position_m->x - g.center_m.x, p.position_m->y - g.center_m.y) > 0.01)
        continue;
      g.center_m = *out.objects[i].position_m;
      break;
    }
  }
  return out;
}

MatchResult RunMatch(const field::SeasonConfig& season, const field::RobotConfig& robot,
                     const MatchSetup& setup, uint64_t seed, const std::string& out_dir,
                     const std::function<void(const TimelineEntry&)>& progress) {
  return RunMatchWith(strategy::MakeStrategy(setup.strategy, setup.strategy_options), season, robot,
                      setup, seed, out_dir, progress);
}

MatchResult RunMatchWith(std::unique_ptr<strategy::Strategy> strategy,
                         const field::SeasonConfig& season, const field::RobotConfig& robot,
                         const MatchSetup& setup, uint64_t seed, const std::string& out_dir,
                         const std::function<void(const TimelineEntry&)>& progress) {
  return RunMatchOn(MakeSimIo(setup.alliance, seed, setup.placement_jitter_m, setup.scenario),
                    std::move(strategy), season, robot, setup, seed, out_dir, progress);
}

}  // namespace slamo::autonomy
