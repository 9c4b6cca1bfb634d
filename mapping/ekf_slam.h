// EKF SLAM over the robot pose and point landmarks (thesis ch. 4, corrected): state
// X = [x, y, theta, l1x, l1y, ...], prediction from encoder odometry with noise that grows
// with distance and turn, range-bearing updates r = hypot(dx, dy), phi = atan2(dy, dx) - theta
// in Joseph form, augmentation with the inverse observation model and its cross-covariances,
// and data association by known id or by Mahalanobis nearest neighbour with one gate to
// associate and a stricter one to create a landmark.
//
// Game objects are not in this state: they move (robots push them), and a moved object in the
// joint state would drag the robot's pose. They are tracked apart, conditioned on the pose
// (object_tracker.h).
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "field_configs/robot_config.h"

namespace slamo::mapping {

// Odometry increment in the robot frame at the start of the step.
struct OdometryStep {
  OdometryStep(double dx = 0.0, double dy = 0.0, double dtheta = 0.0,
               std::optional<Eigen::Matrix3d> step_covariance = std::nullopt)
      : dx_m(dx), dy_m(dy), dtheta_rad(dtheta), covariance(std::move(step_covariance)) {}
  double dx_m = 0.0;  // forward
  double dy_m = 0.0;  // left
  double dtheta_rad = 0.0;
  // The increment's own covariance (dx, dy, dtheta), when the source gives one (an MRPT
  // rawlog's CActionRobotMovement2D, a text log's odom line with sigmas); without it the
  // filter's MotionNoise model stands in.
  std::optional<Eigen::Matrix3d> covariance;
};

// Defaults: the thesis robot as simulated, measured over 300 seeds of `forward 0.3` and
// `turn 90` (odometry error rms: 0.052 m forward, 0.002 m sideways and 0.029 rad per 0.3 m;
// 0.071 m in x and y and 0.038 rad per 90 deg turn). The forward figure is mostly a bias
// (wheels slip; encoders over-read by ~17 %) that the filter can only treat as noise.
struct MotionNoise {
  double sigma_per_m = 0.175;            // forward distance sigma per metre travelled
  double lateral_sigma_per_m = 0.01;     // sideways sigma per metre travelled
  double forward_sigma_per_rad = 0.045;  // forward sigma per radian turned (turn slip)
  double lateral_sigma_per_rad = 0.045;  // sideways sigma per radian turned (turn slip)
  double heading_sigma_per_rad = 0.025;  // heading sigma per radian turned
  double heading_sigma_per_m = 0.10;     // heading sigma per metre travelled
  double floor_m = 1e-4;                 // keeps Q positive definite when standing still
  double floor_rad = 1e-4;
};

// The motion model of the robot file's odometry_noise (the numerical floor stays the default).
MotionNoise MotionNoiseFor(const field::OdometryNoiseConfig& odometry);

// The covariance of the increment `u` (dx, dy, dtheta) under the motion model `noise`: sigmas
// growing with the distance travelled and the angle turned.
Eigen::Matrix3d MotionModelCovariance(const MotionNoise& noise, const OdometryStep& u);

// One range-bearing measurement from the robot centre, with its covariance (vision's).
struct RangeBearing {
  double range_m = 0.0;
  double bearing_rad = 0.0;
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity() * 1e-4;
  int id = -1;            // known landmark id (>= 0) or -1 when it must be associated
  std::string signature;  // e.g. the marker's colour: only same-signature landmarks match
};

struct AssociationOptions {
  double gate_chi2 = 9.21;  // associate within this Mahalanobis distance^2 (99 %, 2 dof)
  double new_chi2 = 25.0;   // create a landmark only beyond this from every landmark
};

// The filter checking itself against what it observes. The normalised innovation squared
// (NIS, e^T S^-1 e, 2 dof) of every measurement that updates the filter is kept over a
// sliding window (a measurement outside the gate is an outlier to it: a misdetected marker
// fails at every frame). Covariance matching (Mehra 1972; the scaled-Q form of Sage and Husa's
// adaptive filter): when the window's mean NIS lies above the 97.5 % bound of its chi-square
// band the process noise is scaled up by `growth`, and scaled back towards 1 by the same
// factor when the mean falls below its expectation (2). Lost and found: after `lost_after`
// known-id measurements in a row fail the gate, of two or more landmarks (one landmark that
// keeps failing while nothing else is seen may be a misdetection), the pose is widened (its
// rows and columns of P scaled so that the failing innovation would sit inside the gate) and
// the measurement tried again; a pairing then ends the lost state (re-acquired).
// Which noise is wrong: a large innovation says the prediction and the measurement disagree,
// not whether the motion or the sensor noise was understated. The measurements of one step
// tell them apart: a pose error is common to all of them, sensor noise is not. So at the end
// of each step (the next Predict), when two or more known landmarks were measured, the pose is
// fitted to those measurements alone, the prior ignored (the snapshot least-squares residual
// test of GPS integrity monitoring, RAIM: Parkinson and Axelrad 1988), each landmark once (the
// step's first measurement of it: repeated frames at a stop share their error), and only when
// the fit has a unique answer. A misdetected marker would pass for noisy measurements: among
// three or more, a measurement the gate refused whose leaving out brings the residual inside
// its 97.5 % band is excluded (RAIM fault detection and exclusion, Brown 1992, limited to what
// the prediction already doubts; excluding any measurement raised the filter's NEES where the
// motion noise is 10x the told). Its residual
// chi-square (2m - 3 degrees of freedom) does not depend on the motion noise; the predicted
// pose against the fitted one (3 degrees of freedom) tests the motion. Over `sensor_window`
// such steps, or at once when a bound passed by chance once in a million checks is passed:
//   - a residual above its 97.5 % band scales the measurement noise by the residual-to-
//     expected ratio (covariance matching of R; Mohamed and Schwarz 1999) and the whole
//     covariance by as much (it was built from measurements trusted too much); the sensor's
//     noise is a property of the sensor, so the scale is never lowered again (a sensor told
//     noisier than it is only makes the filter conservative);
//   - otherwise the pose test raises or lowers the process noise as the NIS window does.
// With step checks the NIS window no longer decides the process noise.
struct AdaptiveOptions {
  bool enabled = false;
  int window = 20;         // measurements per NIS window
  double growth = 2.0;     // process-noise scale factor per window outside the band
  double max_scale = 1e3;  // the process noise is never scaled beyond this
  int lost_after = 3;      // known-id gate failures in a row, of >= 2 landmarks, before the
                           // pose is widened
  double nis_cap = 100.0;  // one measurement's NIS counts at most this much in the window
  int sensor_window = 10;  // steps (with >= 2 known landmarks seen) per sensor-noise window
};

// What the filter did, over its life.
struct FilterCounters {
  int updated = 0;
  int added = 0;
  int ambiguous = 0;
  int rejected = 0;
  int reacquired = 0;         // updates that ended a lost state after the pose was widened
  int adaptive_episodes = 0;  // times the process noise was raised from its nominal level
  int sensor_episodes = 0;    // times the measurement noise was raised
  int excluded = 0;           // step checks that left a refused, inconsistent measurement out
  double nis_sum = 0.0;       // NIS of the measurements that updated the filter
  int nis_count = 0;
  double MeanNis() const { return nis_count ? nis_sum / nis_count : 0.0; }
};

struct EkfOptions {
  MotionNoise motion;
  AdaptiveOptions adaptive;
  AssociationOptions association;
  double max_range_m = 4.5;  // measurements beyond this are ignored
  // false: the map is surveyed and complete; a measurement that pairs with no landmark is
  // dropped instead of starting a new one (UpdateFrame reports it kRejected).
  bool add_landmarks = true;
  // First-estimates Jacobians (FEJ-EKF: Huang, Mourikis and Roumeliotis, "Observability-based
  // rules for designing consistent EKF SLAM estimators", IJRR 2010). The standard EKF evaluates
  // each Jacobian at the latest estimate: a landmark's at every update after it moved, and the
  // pose's after each measurement of a step moved it. The linearised system then seems to
  // observe the map's global position and heading, which nothing measures, and the filter
  // grows overconfident in them and weighs the next measurements wrongly. With this option
  // the measurement Jacobians use the pose as predicted for the step (before any of its
  // measurements) and each landmark's first estimate (where it was initialised, or surveyed),
  // and the prediction's Jacobian the difference of two successive predicted poses: the
  // unobservable directions stay unobservable. Innovations are still taken at the latest
  // estimate. Off by default (the matches); `slamo replay` and the robustness experiment
  // turn it on.
  bool first_estimates = false;
};

// What an update did with each measurement.
enum class UpdateOutcome { kUpdated, kAdded, kAmbiguous, kRejected };

class EkfSlam {
 public:
  EkfSlam(const Eigen::Vector3d& start_pose, const Eigen::Matrix3d& start_covariance,
          const EkfOptions& options = {});

  // Prediction: X- = f(X+, u), P- = F P F^T + G Q G^T, Q the step's own covariance when it
  // has one, else the MotionNoise model; scaled by the adaptive process-noise factor.
  void Predict(const OdometryStep& u);
  // Update with one measurement (associating it, or adding a landmark).
  UpdateOutcome Update(const RangeBearing& z);
  // Update with one frame's measurements together: those without an id are associated by
  // joint compatibility branch and bound (JCBB: the largest set of pairings whose joint
  // innovation passes the chi-square gate, ties to the smallest joint Mahalanobis distance),
  // which resolves what nearest neighbour cannot when same-coloured markers are close in
  // view. Unpaired measurements beyond the creation gate become landmarks.
  std::vector<UpdateOutcome> UpdateFrame(const std::vector<RangeBearing>& frame);
  // The JCBB pairing of measurements (without ids) to landmark indices, -1 for none.
  std::vector<int> JointCompatibility(const std::vector<RangeBearing>& frame) const;

  const Eigen::VectorXd& state() const { return x_; }
  const Eigen::MatrixXd& covariance() const { return p_; }
  Eigen::Vector3d pose() const { return x_.head<3>(); }
  Eigen::Matrix3d pose_covariance() const { return p_.topLeftCorner<3, 3>(); }
  const FilterCounters& counters() const { return counters_; }
  const EkfOptions& options() const { return options_; }
  // The process-noise scale now (1: nominal) and whether known markers keep failing the gate.
  double process_noise_scale() const { return q_scale_; }
  // The measurement-noise scale now (1: the measurements' own covariance).
  double measurement_noise_scale() const { return r_scale_; }
  bool lost() const { return lost_; }
  int landmark_count() const { return static_cast<int>(ids_.size()); }
  Eigen::Vector2d landmark(int index) const { return x_.segment<2>(3 + 2 * index); }
  Eigen::Matrix2d landmark_covariance(int index) const {
    return p_.block<2, 2>(3 + 2 * index, 3 + 2 * index);
  }
  int landmark_id(int index) const { return ids_[index]; }
  const std::string& landmark_signature(int index) const { return signatures_[index]; }
  // Inserts a landmark known in advance (a surveyed field), with its covariance.
  // Adds `extra` to the pose covariance: the belief widened when measurements show it has
  // left the truth (relocalisation by the next update).
  void InflatePoseCovariance(const Eigen::Matrix3d& extra) { p_.topLeftCorner<3, 3>() += extra; }
  void AddKnownLandmark(const Eigen::Vector2d& position, const Eigen::Matrix2d& covariance, int id,
                        const std::string& signature);

  // The measurement model and its Jacobians (public for tests).
  static Eigen::Vector2d Observe(const Eigen::Vector3d& pose, const Eigen::Vector2d& landmark);
  // d h / d pose (2x3) and d h / d landmark (2x2).
  static void ObserveJacobians(const Eigen::Vector3d& pose, const Eigen::Vector2d& landmark,
                               Eigen::Matrix<double, 2, 3>* h_pose, Eigen::Matrix2d* h_landmark);
  // Inverse model: landmark from pose and measurement, with d g / d pose and d g / d z.
  static Eigen::Vector2d InverseObserve(const Eigen::Vector3d& pose, double range_m,
                                        double bearing_rad, Eigen::Matrix<double, 2, 3>* g_pose,
                                        Eigen::Matrix2d* g_z);
  // Motion model with d f / d pose (3x3) and d f / d u (3x3).
  static Eigen::Vector3d Move(const Eigen::Vector3d& pose, const OdometryStep& u,
                              Eigen::Matrix3d* f_pose, Eigen::Matrix3d* f_u);
  Eigen::Matrix3d MotionCovariance(const OdometryStep& u) const;

  // Mahalanobis distance^2 of a measurement to landmark `index` (innovation covariance S).
  double Mahalanobis2(const RangeBearing& z, int index) const;

 private:
  // The innovation of `z` against landmark `index` at the latest estimate, with the
  // measurement Jacobians at the linearisation point (EkfOptions::first_estimates).
  Eigen::Vector2d Innovation(const RangeBearing& z, int index, Eigen::Matrix<double, 2, 3>* h_pose,
                             Eigen::Matrix2d* h_landmark) const;
  // Update without counting the outcome (Update and UpdateFrame count).
  UpdateOutcome Associate(const RangeBearing& z);
  // Returns the measurement's NIS against the prediction.
  double ApplyUpdate(const RangeBearing& z, int index);
  int AddLandmark(const RangeBearing& z);
  // The adaptive scheme's bookkeeping for one measurement's NIS (AdaptiveOptions).
  void RecordNis(double nis);
  // The covariance the filter uses for a measurement: its own, times the adaptive scale.
  Eigen::Matrix2d NoiseOf(const RangeBearing& z) const {
    return r_scale_ == 1.0 ? z.covariance : Eigen::Matrix2d(z.covariance * r_scale_);
  }
  // The sensor-noise check of the step that just ended (AdaptiveOptions), then a new step.
  void CheckStep();
  // The process-noise scale one step up (`raise`) or back towards 1 (`lower`), episodes counted.
  void StepProcessNoise(bool raise, bool lower);
  // Widens the pose by `factor` (its rows and columns of P by sqrt(factor)).
  void WidenPose(double factor);
  UpdateOutcome Count(UpdateOutcome outcome);

  EkfOptions options_;
  Eigen::VectorXd x_;
  Eigen::MatrixXd p_;
  Eigen::Matrix<double, Eigen::Dynamic, 2> pht_, gain_, gain_s_;  // update scratch, kept sized
  std::vector<int> ids_;
  std::vector<std::string> signatures_;
  // First estimates (EkfOptions::first_estimates): the pose as predicted for this step, and
  // each landmark where it was first placed.
  Eigen::Vector3d step_prior_;
  std::vector<Eigen::Vector2d> first_landmarks_;
  FilterCounters counters_;
  std::deque<double> nis_window_;
  double q_scale_ = 1.0;
  bool in_episode_ = false;
  // Sensor-noise check: this step's known-landmark measurements, the window's sums.
  // A known landmark seen in this step, as the filter knew it before the measurement.
  struct Seen {
    RangeBearing z;
    Eigen::Vector2d landmark;
    Eigen::Matrix2d covariance;
    bool refused = false;  // outside the gate against the prediction
  };
  std::vector<Seen> step_seen_;
  // The pose that best explains `seen` alone but for `skip` (-1: none), by Gauss-Newton from
  // the estimate, with its
  // information and residual chi-square; nullopt when the fit has no unique answer (two landmarks
  // in line with the robot) or does not settle.
  struct SnapshotFit {
    Eigen::Vector3d pose;
    Eigen::Matrix3d information;
    double chi2 = 0.0;
  };
  std::optional<SnapshotFit> FitSnapshot(const std::vector<Seen>& seen, int skip) const;
  struct Prior {
    Eigen::Vector3d pose;
    Eigen::Matrix3d covariance;
  };
  std::optional<Prior> prior_;  // the step's predicted pose
  struct StepWindow {
    double residual_chi2 = 0.0, pose_chi2 = 0.0;
    int residual_dof = 0, pose_dof = 0, steps = 0;
  };
  StepWindow window_;
  bool step_checks_ = false;  // steps with >= 2 known landmarks seen: they decide Q, not NIS
  double r_scale_ = 1.0;
  bool sensor_suspect_ = false;
  int known_failures_ = 0;        // known-id gate failures in a row
  std::vector<int> failing_ids_;  // the landmarks among them
  bool lost_ = false;
};

// Pose NEES (x - x_hat)^T P^-1 (x - x_hat), heading error wrapped.
double PoseNees(const Eigen::Vector3d& truth, const Eigen::Vector3d& estimate,
                const Eigen::Matrix3d& covariance);

// Two-sided 95 % band of the average NEES of `runs` runs of a `dof`-dimensional state:
// [chi2_{0.025}(dof * runs), chi2_{0.975}(dof * runs)] / runs.
std::pair<double, double> NeesBand(int dof, int runs);

// Repeated frames of a static scene share an error that does not average away (a per-stop
// bias): with white variance w and bias variance b per component, the k-th frame's update
// uses R_k = (w + k b)(w + (k - 1) b) / w, so that k sequential updates carry exactly the
// information of their average, 1 / (w / k + b).
Eigen::Matrix2d IteratedFrameCovariance(const Eigen::Matrix2d& white, const Eigen::Matrix2d& bias,
                                        int frame_index /* 1-based */);

}  // namespace slamo::mapping
