// Everything one match runs on, behind the operations the executive needs: the robot (through
// RobotIo: the simulated field and its camera in a dry run, the board and a camera on match
// day), SLAM-O (EKF over pose and surveyed markers, the object
// tracker, the OctoMap object map), the planner on that map and the travel times the strategy
// asks for. Each operation advances the match clock and stops at the deadline; the robot is
// only ever steered from SLAM-O's estimate, never from the simulator's truth (the truth, when
// there is one, is recorded for the report).
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "autonomy/loop/robot_io.h"
#include "field_configs/robot_config.h"
#include "field_configs/season_config.h"
#include "mapping/frame_selection.h"
#include "mapping/slam_o.h"
#include "planning/planner.h"
#include "platform/clock.h"
#include "platform/drive_script.h"
#include "strategy/strategy.h"
#include "strategy/travel_field.h"

namespace slamo::autonomy {

// Where the simulator puts the objects of a match. Nominal: each fixed-position floor object
// moved up to MatchSetup::placement_jitter_m (today's layouts). Disturbed: each moved 0.3-0.8 m
// from its spot in a random direction, as after contact with an opponent (preloads, raised
// objects and stacks' upper objects stay with what they rest on). The robot is told the season
// file either way.
enum class Scenario { kNominal, kDisturbed };
const char* ScenarioName(Scenario scenario);
// "nominal" or "disturbed"; throws std::invalid_argument naming the choices.
Scenario ParseScenario(const std::string& name);
inline constexpr double kDisturbMin_m = 0.3, kDisturbMax_m = 0.8;

struct MatchSetup {
  std::string strategy = "planner";  // strategy::StrategyNames()
  strategy::StrategyOptions strategy_options;
  mapping::FrameSelectionOptions frames;  // the rule for every observation (cap: the action's)
  field::Alliance alliance = field::Alliance::kRed;
  int start_index = 0;               // among the alliance's starting tiles
  double placement_jitter_m = 0.15;  // fixed-position objects moved up to this per seed
  Scenario scenario = Scenario::kNominal;
  std::string planner = "rrtconnect";
  double plan_budget_s = 0.05;
  // Planner iterations per attempt instead of a time budget, so that a match depends only on
  // its seed, not on how busy the machine is (PlanRequest::max_iterations; 0: the budget).
  int plan_iterations = 10000;
  double snapshot_period_s = 0.25;  // match time between replay snapshots (0: none)
  double drive_speed_mps = 0.0;     // 0: the robot's drive.match_speed_mps
  // How the executive drives with SLAM-O (perceiving strategies): a quick look of
  // correction_frames every check_spacing_m of path (0: none; negative: DefaultCheckSpacing);
  // on arrival up to arrival_fixes rounds of look-and-correct until within
  // arrival_tolerance_m; objects narrower than pushable_fraction of the robot's width are
  // pushed aside, not planned round.
  double check_spacing_m = -1.0;
  int correction_frames = 5;
  int arrival_fixes = 2;
  double arrival_tolerance_m = 0.04;
  // After an arrival's look, an error up to this is left to the next action, which aims from
  // the estimate itself (a pick, a release, a push, each driving its own straight approach
  // from the stage): no correcting drive for it. Negative: half the strategy's
  // approach_margin_m, the straight run the next action has to absorb it in.
  double arrival_slack_m = -1.0;
  double pushable_fraction = 1.0;
  // Path legs behind the robot up to this long are driven backwards instead of turning round
  // twice (0: always forwards).
  double reverse_max_m = 0.6;
  // Two interior path corners closer than this become one (where the legs before and after
  // meet, else their midpoint, else either corner) when the legs to and from it are clear: a
  // few-centimetre leg between two turns is two stops for one bend (0: never).
  double corner_merge_m = 0.15;
  bool gyro =
      true;  // the turn of every motion from a yaw gyro, not the encoders (VEX robots carry one)
  bool adaptive_filter = false;  // the EKF's adaptive noise (mapping::AdaptiveOptions)
  // The drive controller turns and holds heading on the gyro instead of the encoders (robot
  // files with an `imu`, with `gyro` on). Off: on the V5 robot it lifts the blind scripted
  // route more than the planner (README, #15: "Then: turns cut at the wheels' measured
  // speed").
  bool gyro_turns = false;
  // Frames taken while driving past objects (#15 item 5), one every moving_frame_period_s of a
  // straight drive (0: only at stops), each its own stop of one frame, when the body turned by
  // at most moving_frame_max_turn_dps over the last control period (a frame taken mid-turn
  // smears, and the heading the update pairs it at moves fastest then). On the robot such a
  // frame is taken only when the camera has one ready (RobotIo::CaptureReady): its processing
  // (the detector's 4-11 ms, README) runs inside the drive controller's period, whose motor
  // command stands meanwhile. Not yet tried on a robot.
  double moving_frame_period_s = 0.2;
  double moving_frame_max_turn_dps = 20.0;
  // Each frame while driving re-aims the path leg under way from SLAM-O's estimate: heading
  // and distance to the leg's end (corrections up to steer_max_deg; none in the leg's last
  // steer_min_remaining_m).
  bool steer_on_estimate = true;
  double steer_max_deg = 20.0;
  double steer_min_remaining_m = 0.1;
};

// The quick looks' spacing for `setup` when it leaves it to the executive: 2.4 m of path when
// legs are steered from frames while driving, 1.2 m otherwise (each the better of the two for
// its case: README, #15, "Then: steering a leg from the estimate").
double DefaultCheckSpacing(const MatchSetup& setup);

// What the camera saw on the last frame whose objects were detected (the first and the last
// frame of every look), downscaled, with those detections: the replay's camera panel. One is
// made per such frame, only when snapshots are recorded, and shared by the snapshots showing it.
struct CameraView {
  double t_s = 0.0;  // when the frame was taken
  cv::Mat image;     // BGR (CV_8UC3), the colour frame downscaled to kCameraViewWidth
  struct Seen {
    cv::Rect2d box;  // in `image`'s pixels
    std::string kind, colour;
    double range_m = -1.0;  // < 0: no range
    mapping::DetectionUse use = mapping::DetectionUse::kTracked;
  };
  std::vector<Seen> seen;
};
inline constexpr int kCameraViewWidth = 256;
// The view of `frame` (its colour image) with `objects`, the detections made on it.
CameraView MakeCameraView(const platform::RgbdFrame& frame, const mapping::ObjectFrame& objects,
                          double t_s, int width = kCameraViewWidth);

// A moment of the match for the replay and the map picture.
struct Snapshot {
  double t_s = 0.0;
  bool truth_known = true;  // false on hardware: truth and truth_objects are empty
  platform::Pose2D truth;
  Eigen::Vector3d estimate = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  struct Object {
    Eigen::Vector2d position_m;
    std::string colour;
    double radius_m = 0.0;
  };
  std::vector<Object> truth_objects;  // on the floor, in the simulator
  std::vector<strategy::ObjectBelief> tracked;
  std::string action;
  int points = 0;
  std::shared_ptr<const CameraView> camera;  // the last frame seen; null before the first
};

// Estimate against truth at the same instant (every filter update), for ATE and the TUM file.
struct PoseSample {
  double t_s = 0.0;
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();
  Eigen::Vector3d estimate = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  bool truth_known = true;  // false on hardware (truth is then zero)
};

// The pose ATE over the samples whose truth is known: the RMS position error at the same
// instants, without alignment (mapping::PairedTrajectoryError); NaN when none is.
double PoseAte(const std::vector<PoseSample>& samples);

// The filter against the truth at every update: the pose NEES (3 dof) against one update's
// 95 % band. Below the band the filter is conservative, above it overconfident.
struct PoseConsistency {
  int updates = 0;  // samples whose truth is known
  int in_band = 0, below = 0, above = 0;
  double band_low = 0.0, band_high = 0.0;
  // In the band or conservative, over the updates (NaN: none).
  double HonestFraction() const;
};
PoseConsistency PoseConsistencyOf(const std::vector<PoseSample>& samples);

class MatchWorld {
 public:
  // On `io` (the robot), the season's objects where its file puts them; `seed` seeds the
  // planners. Calls io->Start().
  MatchWorld(std::unique_ptr<RobotIo> io, const field::SeasonConfig& season,
             const field::RobotConfig& robot, const MatchSetup& setup, uint64_t seed,
             bool perceive);

  double now_s() const { return io_->clock().NowS(); }
  double deadline_s() const { return deadline_s_; }
  double time_left_s() const { return deadline_s_ - now_s(); }

  strategy::Belief Belief() const;
  const strategy::StrategyContext& Context() const { return context_; }

  // Observes up to max_frames (the frame rule may stop earlier), landmarks every frame and
  // objects on the last; the map and the planner follow. Returns the frames taken.
  int Observe(int max_frames);
  // Turns in place to a field heading.
  bool TurnTo(double heading_rad);
  // Plans from the estimated pose to `target` and follows the path turn-then-drive, each
  // segment aimed from the latest estimate; observes frames_per_stop at stops every
  // stop_spacing_m; replans when an observation puts an obstacle on the rest of the path.
  // Gives up (false) when it has taken budget_s (<= 0: no limit).
  bool Navigate(const Eigen::Vector3d& target, double stop_spacing_m, int frames_per_stop,
                double budget_s = 0.0);
  // A knock: straight from where the robot stands to target.xy, whatever the map holds (the
  // object to knock off lies on the way, and the planner would go round it), and straight back
  // as far (pressed against the structure the robot could not turn; the way it came is clear);
  // true when the robot got within 0.12 m of target.xy. back_m >= 0: back out only that far
  // (an object pushed along the floor leaves the robot free to turn).
  bool Push(const Eigen::Vector3d& target, double back_m = -1.0);
  // Final approach to an object believed at target.xy and the intake; true when the intake
  // took an object of the target's kind and colour (another one is held, but the pick
  // failed).
  bool Pick(const strategy::Action& action);
  // Whether the last Pick gave up before its approach: the look on arrival did not find the
  // target (StrategyOptions::pick_in_view).
  bool pick_skipped() const { return pick_skipped_; }
  // Final approach to the goal and the release; true when the object landed where intended.
  bool Score(const strategy::Action& action);
  // Turns to action.target's heading and releases the held object there, on the floor;
  // true when it left the intake.
  bool Drop(const strategy::Action& action);
  // Stands still until the deadline.
  void IdleToDeadline();

  // The alliance's points now, when known (the simulator).
  std::optional<int> Points() const { return io_->Points(); }
  const field::SeasonConfig& field() const { return field_; }
  RobotIo& io() { return *io_; }
  const RobotIo& io() const { return *io_; }
  // SLAM-O: the EKF, the object tracker and the maps.
  const mapping::SlamO& slam() const { return slam_; }
  const std::vector<PoseSample>& samples() const { return samples_; }
  const std::vector<Snapshot>& snapshots() const { return snapshots_; }
  const std::vector<std::vector<Eigen::Vector2d>>& paths() const { return paths_; }
  // The surveyed marker centres (what SLAM-O is given, and on the simulated field the truth).
  const std::vector<Eigen::Vector2d>& landmark_truth() const { return markers_; }
  double overrun_s() const { return overrun_s_; }
  int frames() const { return frames_; }
  int moving_frames() const { return moving_frames_; }  // of frames(): taken while driving
  int replans() const { return replans_; }
  int relocalisations() const { return slam_.relocalisations(); }
  int rejected_frames() const { return slam_.gated_frames(); }
  double odometry_scale() const { return odometry_scale_; }
  double last_motion_s() const { return last_motion_s_; }
  void set_action_label(const std::string& label) { action_label_ = label; }

 private:
  // With `leg_end` (a path leg's end, driven backwards when `reverse`) and frames while
  // driving, each such frame steers the leg's straight drive from SLAM-O's estimate
  // (MatchSetup::steer_on_estimate).
  bool Drive(const std::vector<platform::DriveStep>& steps,
             const std::optional<Eigen::Vector2d>& leg_end = std::nullopt, bool reverse = false);
  void Wait(double seconds);
  void Advance(double dt_s);
  // The encoders' (and gyro's) motion since the last prediction into SLAM-O: up to now, or up
  // to `odometry` and the gyro's `gyro` (nothing: the encoders' turn, without setup_.gyro).
  void PredictFromOdometry();
  void PredictTo(const platform::Pose2D& odometry, const std::optional<double>& gyro);
  struct OdometryReading {
    double t_s = 0.0;
    platform::Pose2D odometry;
    std::optional<double> gyro;
  };
  // One frame taken on the move: its markers and objects, a stop of its own, paired with the
  // odometry of its exposure (camera.latency_s before now) from `recent`. False: no frame.
  bool ObserveMoving(const std::deque<OdometryReading>& recent);
  void RecordSample();
  void MaybeSnapshot(bool force = false);
  // Keeps `frame` and its detections for the replay, when snapshots are recorded.
  void KeepView(const platform::RgbdFrame& frame, const mapping::ObjectFrame& objects);
  void UpdateMaps();
  void Init(uint64_t seed);
  bool PathClear(const std::vector<Eigen::Vector2d>& path) const;
  // setup_.corner_merge_m on a path's corners (its ends stay).
  void MergeCloseCorners(std::vector<Eigen::Vector2d>* corners) const;
  double ObjectRadius(const std::string& kind) const;

  field::SeasonConfig field_;  // the season with this match's object placement
  field::RobotConfig robot_;
  MatchSetup setup_;
  bool perceive_;
  double deadline_s_;
  std::unique_ptr<RobotIo> io_;
  mapping::SlamO slam_;  // the EKF, the object tracker, the object and obstacle maps
  std::vector<Eigen::Vector2d> markers_;
  std::unique_ptr<planning::Planner> planner_;
  double gyro_heading_ = 0.0;  // the gyro's reading at the last prediction
  strategy::TravelField travel_;
  strategy::StrategyContext context_;
  platform::DriveControllerOptions drive_options_;
  platform::Pose2D odometry_;    // the encoders' pose at the last prediction
  double odometry_scale_ = 1.0;  // true distance per encoder distance, calibrated
  std::optional<strategy::ObjectBelief> held_;
  std::vector<int> picked_ids_;  // tracker ids of objects taken off the field
  // Frames taken since the robot last moved: a pick or score right after a look at the same
  // standstill does not look again (the same view, and the same per-stop bias counted twice).
  int frames_at_rest_ = 0;
  double look_start_s_ = -1.0;  // when the first look since the robot last moved began
  bool pick_skipped_ = false;
  std::vector<PoseSample> samples_;
  std::vector<Snapshot> snapshots_;
  std::shared_ptr<const CameraView> camera_view_;  // the last frame seen, for the snapshots
  std::vector<std::vector<Eigen::Vector2d>> paths_;
  std::string action_label_;
  double next_snapshot_s_ = 0.0;
  double overrun_s_ = 0.0;
  double last_motion_s_ = 0.0;
  int frames_ = 0;
  int moving_frames_ = 0;
  int replans_ = 0;
};

// SLAM-O as a match runs it: from `start`, known to a centimetre and a degree, over the
// season's surveyed markers, known to a millimetre and all there is (no new landmarks); with
// `relocalise`, a belief that left the truth is widened and paired again; with `adaptive`, the
// EKF checks its noise against what it observes (mapping::AdaptiveOptions).
mapping::SlamO SurveyedSlam(const field::SeasonConfig& field, const field::RobotConfig& robot,
                            const platform::Pose2D& start, bool relocalise, bool adaptive = false);

}  // namespace slamo::autonomy
