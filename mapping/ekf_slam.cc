#include "mapping/ekf_slam.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>

#include <Eigen/Dense>

#include "platform/drive_base.h"

namespace slamo::mapping {
namespace {

using platform::kPi;

double Wrap(double a) {
  const double w = std::remainder(a, 2.0 * kPi);
  return w <= -kPi ? w + 2.0 * kPi : w;
}

// Keeps P symmetric after every operation (round-off breaks it slowly otherwise).
// Averages P with its transpose, in place (`P = 0.5 (P + P^T)` would read entries it has already
// written: Eigen does not guard that alias).
void Symmetrise(Eigen::MatrixXd* p) {
  Eigen::MatrixXd& m = *p;
  for (Eigen::Index c = 1; c < m.cols(); ++c) {
    for (Eigen::Index r = 0; r < c; ++r) m(r, c) = m(c, r) = 0.5 * (m(r, c) + m(c, r));
  }
}

// The regularised lower incomplete gamma function P(a, x) (series below a + 1, continued
// fraction above; Numerical Recipes 6.2), the chi-square CDF being P(dof / 2, x / 2).
double RegularisedGammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefix = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 1000 && std::abs(term) > 1e-15 * std::abs(sum); ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return sum * std::exp(log_prefix);
  }
  double b = x + 1.0 - a, c = 1e300, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return 1.0 - std::exp(log_prefix) * h;
}

// The p-quantile of chi-square with `dof` degrees of freedom, by bisection on its CDF;
// remembered, since the adaptive checks ask for the same few at every step.
double Chi2Quantile(double p, int dof) {
  thread_local std::map<std::pair<double, int>, double> known;
  const auto it = known.find({p, dof});
  if (it != known.end()) return it->second;
  double lo = 0.0, hi = std::max(10.0, 5.0 * dof);
  while (RegularisedGammaP(dof / 2.0, hi / 2.0) < p) hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (RegularisedGammaP(dof / 2.0, mid / 2.0) < p ? lo : hi) = mid;
  }
  return known[{p, dof}] = 0.5 * (lo + hi);
}

}  // namespace

EkfSlam::EkfSlam(const Eigen::Vector3d& start_pose, const Eigen::Matrix3d& start_covariance,
                 const EkfOptions& options)
    : options_(options), x_(start_pose), p_(start_covariance), step_prior_(start_pose) {}

Eigen::Vector3d EkfSlam::Move(const Eigen::Vector3d& pose, const OdometryStep& u,
                              Eigen::Matrix3d* f_pose, Eigen::Matrix3d* f_u) {
  const double c = std::cos(pose.z()), s = std::sin(pose.z());
  const Eigen::Vector3d next(pose.x() + c * u.dx_m - s * u.dy_m, pose.y() + s * u.dx_m + c * u.dy_m,
                             Wrap(pose.z() + u.dtheta_rad));
  if (f_pose) {
    *f_pose << 1, 0, -s * u.dx_m - c * u.dy_m,  //
        0, 1, c * u.dx_m - s * u.dy_m,          //
        0, 0, 1;
  }
  if (f_u) {
    *f_u << c, -s, 0,  //
        s, c, 0,       //
        0, 0, 1;
  }
  return next;
}

Eigen::Matrix3d EkfSlam::MotionCovariance(const OdometryStep& u) const {
  return MotionModelCovariance(options_.motion, u);
}

MotionNoise MotionNoiseFor(const field::OdometryNoiseConfig& odometry) {
  MotionNoise m;
  m.sigma_per_m = odometry.forward_sigma_per_m;
  m.lateral_sigma_per_m = odometry.lateral_sigma_per_m;
  m.forward_sigma_per_rad = odometry.forward_sigma_per_rad;
  m.lateral_sigma_per_rad = odometry.lateral_sigma_per_rad;
  m.heading_sigma_per_rad = odometry.heading_sigma_per_rad;
  m.heading_sigma_per_m = odometry.heading_sigma_per_m;
  return m;
}

Eigen::Matrix3d MotionModelCovariance(const MotionNoise& m, const OdometryStep& u) {
  const double distance = std::hypot(u.dx_m, u.dy_m);
  const double turn = std::abs(u.dtheta_rad);
  const double sx = m.sigma_per_m * distance + m.forward_sigma_per_rad * turn + m.floor_m;
  const double sy = m.lateral_sigma_per_m * distance + m.lateral_sigma_per_rad * turn + m.floor_m;
  const double st = m.heading_sigma_per_rad * turn + m.heading_sigma_per_m * distance + m.floor_rad;
  return Eigen::Vector3d(sx * sx, sy * sy, st * st).asDiagonal();
}

void EkfSlam::Predict(const OdometryStep& u) {
  if (options_.adaptive.enabled) CheckStep();
  Eigen::Matrix3d f_pose, f_u;
  x_.head<3>() = Move(x_.head<3>(), u, &f_pose, &f_u);
  if (options_.first_estimates) {
    // The heading column from the two predicted poses, not the updated one and the increment.
    f_pose(0, 2) = -(x_(1) - step_prior_.y());
    f_pose(1, 2) = x_(0) - step_prior_.x();
  }
  step_prior_ = x_.head<3>();
  // P = F P F^T + G Q G^T, touching only the pose rows and columns.
  const int n = static_cast<int>(x_.size());
  const Eigen::Matrix3d q = u.covariance ? *u.covariance : MotionCovariance(u);
  p_.topLeftCorner<3, 3>() = f_pose * p_.topLeftCorner<3, 3>() * f_pose.transpose() +
                             f_u * (q_scale_ == 1.0 ? q : q * q_scale_) * f_u.transpose();
  if (n > 3) {
    p_.topRightCorner(3, n - 3) = f_pose * p_.topRightCorner(3, n - 3);
    p_.bottomLeftCorner(n - 3, 3) = p_.topRightCorner(3, n - 3).transpose();
  }
  Symmetrise(&p_);
  if (options_.adaptive.enabled) prior_ = Prior{x_.head<3>(), p_.topLeftCorner<3, 3>()};
}

Eigen::Vector2d EkfSlam::Observe(const Eigen::Vector3d& pose, const Eigen::Vector2d& landmark) {
  const Eigen::Vector2d d = landmark - pose.head<2>();
  return Eigen::Vector2d(d.norm(), Wrap(std::atan2(d.y(), d.x()) - pose.z()));
}

void EkfSlam::ObserveJacobians(const Eigen::Vector3d& pose, const Eigen::Vector2d& landmark,
                               Eigen::Matrix<double, 2, 3>* h_pose, Eigen::Matrix2d* h_landmark) {
  const Eigen::Vector2d d = landmark - pose.head<2>();
  const double q = d.squaredNorm();
  const double r = std::sqrt(q);
  *h_landmark << d.x() / r, d.y() / r,  //
      -d.y() / q, d.x() / q;
  h_pose->leftCols<2>() = -*h_landmark;
  h_pose->col(2) = Eigen::Vector2d(0.0, -1.0);
}

Eigen::Vector2d EkfSlam::InverseObserve(const Eigen::Vector3d& pose, double range_m,
                                        double bearing_rad, Eigen::Matrix<double, 2, 3>* g_pose,
                                        Eigen::Matrix2d* g_z) {
  const double a = pose.z() + bearing_rad;
  const double c = std::cos(a), s = std::sin(a);
  if (g_pose) {
    *g_pose << 1, 0, -range_m * s,  //
        0, 1, range_m * c;
  }
  if (g_z) {
    *g_z << c, -range_m * s,  //
        s, range_m * c;
  }
  return Eigen::Vector2d(pose.x() + range_m * c, pose.y() + range_m * s);
}

Eigen::Vector2d EkfSlam::Innovation(const RangeBearing& z, int index,
                                    Eigen::Matrix<double, 2, 3>* h_pose,
                                    Eigen::Matrix2d* h_landmark) const {
  const Eigen::Vector3d pose = x_.head<3>();
  const Eigen::Vector2d l = landmark(index);
  if (options_.first_estimates) {
    ObserveJacobians(step_prior_, first_landmarks_[index], h_pose, h_landmark);
  } else {
    ObserveJacobians(pose, l, h_pose, h_landmark);
  }
  Eigen::Vector2d e = Eigen::Vector2d(z.range_m, z.bearing_rad) - Observe(pose, l);
  e.y() = Wrap(e.y());
  return e;
}

double EkfSlam::Mahalanobis2(const RangeBearing& z, int index) const {
  Eigen::Matrix<double, 2, 3> h_pose;
  Eigen::Matrix2d h_l;
  const Eigen::Vector2d e = Innovation(z, index, &h_pose, &h_l);
  const int j = 3 + 2 * index;
  const Eigen::Matrix2d s = h_pose * p_.topLeftCorner<3, 3>() * h_pose.transpose() +
                            h_pose * p_.block<3, 2>(0, j) * h_l.transpose() +
                            h_l * p_.block<2, 3>(j, 0) * h_pose.transpose() +
                            h_l * p_.block<2, 2>(j, j) * h_l.transpose() + NoiseOf(z);
  return e.dot(s.ldlt().solve(e));
}

double EkfSlam::ApplyUpdate(const RangeBearing& z, int index) {
  const int j = 3 + 2 * index;
  Eigen::Matrix<double, 2, 3> h_pose;
  Eigen::Matrix2d h_l;
  const Eigen::Vector2d e = Innovation(z, index, &h_pose, &h_l);
  // Only the pose and this landmark's columns of H are non-zero: P H^T from those.
  pht_.noalias() = p_.leftCols<3>() * h_pose.transpose();
  pht_.noalias() += p_.middleCols<2>(j) * h_l.transpose();
  const Eigen::Matrix2d s = h_pose * pht_.topRows<3>() + h_l * pht_.middleRows<2>(j) + NoiseOf(z);
  gain_.noalias() = pht_ * s.inverse();
  x_.noalias() += gain_ * e;
  x_(2) = Wrap(x_(2));
  // Joseph form (I - K H) P (I - K H)^T + K R K^T, multiplied out so that no n x n x n product
  // is formed: P - K (H P) - (H P)^T K^T + K S K^T, with H P = (P H^T)^T. Each term is an outer
  // product of n x 2 factors (O(n^2)); the sum keeps the Joseph form's tolerance of a gain that
  // is not exactly optimal. One pass over the upper triangle, mirrored: P stays exactly symmetric.
  gain_s_.noalias() = gain_ * s;
  for (Eigen::Index c = 0; c < p_.cols(); ++c) {
    for (Eigen::Index r = 0; r <= c; ++r) {
      p_(r, c) = p_(c, r) = p_(r, c) - gain_.row(r).dot(pht_.row(c)) -
                            pht_.row(r).dot(gain_.row(c)) + gain_s_.row(r).dot(gain_.row(c));
    }
  }
  const double nis = e.dot(s.ldlt().solve(e));
  counters_.nis_sum += nis;
  ++counters_.nis_count;
  RecordNis(nis);
  return nis;
}

void EkfSlam::RecordNis(double nis) {
  const AdaptiveOptions& a = options_.adaptive;
  if (!a.enabled || step_checks_) return;  // the step checks decide (CheckStep)
  nis_window_.push_back(std::min(nis, a.nis_cap));
  if (static_cast<int>(nis_window_.size()) < a.window) return;
  double mean = 0.0;
  for (double v : nis_window_) mean += v;
  mean /= static_cast<double>(nis_window_.size());
  const double upper = Chi2Quantile(0.975, 2 * a.window) / a.window;
  // Innovations persistently larger than predicted: more process noise; smaller than
  // expected: back towards the nominal noise.
  StepProcessNoise(mean > upper, mean < 2.0);
  nis_window_.clear();
}

std::optional<EkfSlam::SnapshotFit> EkfSlam::FitSnapshot(const std::vector<Seen>& seen,
                                                         int skip) const {
  SnapshotFit fit{x_.head<3>(), Eigen::Matrix3d::Zero(), 0.0};
  for (int iteration = 0; iteration < 10; ++iteration) {
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    fit.information.setZero();
    fit.chi2 = 0.0;
    for (int j = 0; j < static_cast<int>(seen.size()); ++j) {
      if (j == skip) continue;
      const Seen& s = seen[j];
      Eigen::Matrix<double, 2, 3> h_pose;
      Eigen::Matrix2d h_l;
      ObserveJacobians(fit.pose, s.landmark, &h_pose, &h_l);
      const Eigen::Matrix2d w = (NoiseOf(s.z) + h_l * s.covariance * h_l.transpose()).inverse();
      Eigen::Vector2d e =
          Eigen::Vector2d(s.z.range_m, s.z.bearing_rad) - Observe(fit.pose, s.landmark);
      e.y() = Wrap(e.y());
      fit.information += h_pose.transpose() * w * h_pose;
      b += h_pose.transpose() * w * e;
      fit.chi2 += e.dot(w * e);
    }
    const Eigen::Vector3d eigen =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(fit.information).eigenvalues();
    const Eigen::Vector3d delta = fit.information.ldlt().solve(b);
    if (!(eigen(0) > 1e-9 * eigen(2)) || !delta.allFinite()) return std::nullopt;
    fit.pose += delta;
    fit.pose.z() = Wrap(fit.pose.z());
    if (delta.head<2>().norm() < 1e-5 && std::abs(delta.z()) < 1e-5) return fit;
  }
  return std::nullopt;
}

void EkfSlam::CheckStep() {
  const AdaptiveOptions& a = options_.adaptive;
  const std::vector<Seen> seen_list = std::move(step_seen_);
  step_seen_.clear();
  const int m = static_cast<int>(seen_list.size());
  if (m < 2) return;
  // The pose that best explains this step's measurements alone, against the landmarks as they
  // were before these measurements updated them (so that the residual is not shrunk by its
  // own update); each measurement weighted by its noise and its landmark's uncertainty.
  std::optional<SnapshotFit> fit = FitSnapshot(seen_list, -1);
  if (!fit) return;
  int m_used = m;
  if (m >= 3 && fit->chi2 > Chi2Quantile(1.0 - 1e-6, 2 * m - 3)) {
    std::optional<SnapshotFit> best;
    for (int j = 0; j < m; ++j) {
      if (!seen_list[j].refused) continue;
      std::optional<SnapshotFit> without = FitSnapshot(seen_list, j);
      if (without && (!best || without->chi2 < best->chi2)) best = without;
    }
    if (best && best->chi2 <= Chi2Quantile(0.975, 2 * (m - 1) - 3)) {
      fit = best;
      m_used = m - 1;
      ++counters_.excluded;
    }
  }
  const Eigen::Vector3d pose = fit->pose;
  const Eigen::Matrix3d information = fit->information;
  const double chi2 = fit->chi2;
  step_checks_ = true;
  // The sensor: the fit's residual, 2m - 3 degrees of freedom.
  const int dof = 2 * m_used - 3;
  window_.residual_chi2 += std::min(chi2, 0.5 * a.nis_cap * dof);  // outliers count at most this
  window_.residual_dof += dof;
  // The motion: the step's predicted pose against the fit, 3 degrees of freedom.
  if (prior_) {
    Eigen::Vector3d d = pose - prior_->pose;
    d.z() = Wrap(d.z());
    const Eigen::Matrix3d c = prior_->covariance + information.inverse();
    window_.pose_chi2 += std::min(d.dot(c.ldlt().solve(d)), 1.5 * a.nis_cap);
    window_.pose_dof += 3;
  }
  ++window_.steps;
  // Decide at the window's end, or at once on overwhelming evidence: a bound passed by chance
  // once in a million checks (each step checks, so a lower bound would raise false alarms).
  const double kOverwhelming = 1.0 - 1e-6;
  const bool sensor_overwhelming =
      window_.residual_chi2 > Chi2Quantile(kOverwhelming, window_.residual_dof);
  const bool motion_overwhelming =
      window_.pose_dof > 0 && window_.pose_chi2 > Chi2Quantile(kOverwhelming, window_.pose_dof);
  if (window_.steps < a.sensor_window && !sensor_overwhelming && !motion_overwhelming) return;
  const StepWindow w = window_;
  window_ = StepWindow{};
  const double ratio = w.residual_chi2 / w.residual_dof;
  sensor_suspect_ = ratio > Chi2Quantile(0.975, w.residual_dof) / w.residual_dof;
  if (sensor_suspect_) {
    ++counters_.sensor_episodes;
    const double growth = std::min(a.max_scale / r_scale_, ratio);
    r_scale_ *= growth;
    // What the filter believes came from measurements whose noise was understated by
    // `growth`: widen the whole belief by as much (conservative where motion dominated it).
    p_ *= growth;
    return;  // the pose test used the understated noise too: no verdict on the motion
  }
  if (w.pose_dof == 0) return;
  // The prediction keeps missing what the measurements say: more process noise.
  const double pose_ratio = w.pose_chi2 / w.pose_dof;
  StepProcessNoise(pose_ratio > Chi2Quantile(0.975, w.pose_dof) / w.pose_dof, pose_ratio < 1.0);
}

void EkfSlam::StepProcessNoise(bool raise, bool lower) {
  const AdaptiveOptions& a = options_.adaptive;
  if (raise) {
    if (!in_episode_) ++counters_.adaptive_episodes;
    in_episode_ = true;
    q_scale_ = std::min(a.max_scale, q_scale_ * a.growth);
  } else if (lower && q_scale_ > 1.0) {
    q_scale_ = std::max(1.0, q_scale_ / a.growth);
    if (q_scale_ == 1.0) in_episode_ = false;
  }
}

void EkfSlam::WidenPose(double factor) {
  const double f = std::sqrt(factor);
  p_.topRows<3>() *= f;
  p_.leftCols<3>() *= f;
  Symmetrise(&p_);
}

UpdateOutcome EkfSlam::Count(UpdateOutcome outcome) {
  switch (outcome) {
    case UpdateOutcome::kUpdated:
      ++counters_.updated;
      break;
    case UpdateOutcome::kAdded:
      ++counters_.added;
      break;
    case UpdateOutcome::kAmbiguous:
      ++counters_.ambiguous;
      break;
    case UpdateOutcome::kRejected:
      ++counters_.rejected;
      break;
  }
  return outcome;
}

int EkfSlam::AddLandmark(const RangeBearing& z) {
  const int n = static_cast<int>(x_.size());
  Eigen::Matrix<double, 2, 3> g_pose;
  Eigen::Matrix2d g_z;
  const Eigen::Vector2d l = InverseObserve(x_.head<3>(), z.range_m, z.bearing_rad, &g_pose, &g_z);
  x_.conservativeResize(n + 2);
  x_.tail<2>() = l;
  Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(n + 2, n + 2);
  grown.topLeftCorner(n, n) = p_;
  // Cross-covariances with everything the pose is correlated with.
  grown.block(n, 0, 2, n) = g_pose * p_.topRows<3>();
  grown.block(0, n, n, 2) = grown.block(n, 0, 2, n).transpose();
  grown.block<2, 2>(n, n) =
      g_pose * p_.topLeftCorner<3, 3>() * g_pose.transpose() + g_z * NoiseOf(z) * g_z.transpose();
  p_ = std::move(grown);
  Symmetrise(&p_);
  ids_.push_back(z.id);
  signatures_.push_back(z.signature);
  first_landmarks_.push_back(l);
  return static_cast<int>(ids_.size()) - 1;
}

void EkfSlam::AddKnownLandmark(const Eigen::Vector2d& position, const Eigen::Matrix2d& covariance,
                               int id, const std::string& signature) {
  const int n = static_cast<int>(x_.size());
  x_.conservativeResize(n + 2);
  x_.tail<2>() = position;
  Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(n + 2, n + 2);
  grown.topLeftCorner(n, n) = p_;
  grown.block<2, 2>(n, n) = covariance;
  p_ = std::move(grown);
  ids_.push_back(id);
  signatures_.push_back(signature);
  first_landmarks_.push_back(position);
}

UpdateOutcome EkfSlam::Update(const RangeBearing& z) { return Count(Associate(z)); }

UpdateOutcome EkfSlam::Associate(const RangeBearing& z) {
  if (!(z.range_m > 0.0) || z.range_m > options_.max_range_m || !std::isfinite(z.bearing_rad)) {
    return UpdateOutcome::kRejected;
  }
  // Known id: that landmark, or a new one with that id.
  if (z.id >= 0) {
    for (int i = 0; i < landmark_count(); ++i) {
      if (ids_[i] != z.id) continue;
      const double d2 = Mahalanobis2(z, i);
      // The step's snapshot (CheckStep) takes each landmark once: repeated frames of one marker
      // at a stop share its bias and add no geometry. The first frame's is the one kept.
      if (options_.adaptive.enabled &&
          std::none_of(step_seen_.begin(), step_seen_.end(),
                       [&](const Seen& seen) { return seen.z.id == z.id; })) {
        step_seen_.push_back(
            {z, landmark(i), landmark_covariance(i), d2 > options_.association.new_chi2});
      }
      if (d2 <= options_.association.new_chi2) {
        ApplyUpdate(z, i);
        if (lost_) ++counters_.reacquired;
        lost_ = false;
        known_failures_ = 0;
        failing_ids_.clear();
        return UpdateOutcome::kUpdated;
      }
      // A known landmark outside the gate: the belief is too narrow, or the measurement is
      // wrong (a misdetected marker keeps failing at every frame). It is an outlier to the
      // noise adaptation (covariance matching takes the innovations it updates with); the
      // belief is taken for lost only when two or more landmarks fail with none pairing.
      if (!options_.adaptive.enabled) return UpdateOutcome::kRejected;
      ++known_failures_;
      if (std::find(failing_ids_.begin(), failing_ids_.end(), z.id) == failing_ids_.end())
        failing_ids_.push_back(z.id);
      if (known_failures_ < options_.adaptive.lost_after || failing_ids_.size() < 2)
        return UpdateOutcome::kRejected;
      // Lost: widen the pose so that this innovation sits inside the gate, and pair again.
      lost_ = true;
      WidenPose(std::min(1e6, 2.0 * d2 / options_.association.gate_chi2));
      if (Mahalanobis2(z, i) > options_.association.new_chi2) return UpdateOutcome::kRejected;
      ApplyUpdate(z, i);
      ++counters_.reacquired;
      lost_ = false;
      known_failures_ = 0;
      failing_ids_.clear();
      return UpdateOutcome::kUpdated;
    }
    AddLandmark(z);
    return UpdateOutcome::kAdded;
  }
  // Nearest neighbour by Mahalanobis distance among same-signature landmarks.
  int best = -1, candidates = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < landmark_count(); ++i) {
    if (signatures_[i] != z.signature) continue;
    const double d2 = Mahalanobis2(z, i);
    if (d2 < options_.association.gate_chi2) ++candidates;
    if (d2 < best_d2) best_d2 = d2, best = i;
  }
  if (best >= 0 && best_d2 < options_.association.gate_chi2) {
    if (candidates > 1) return UpdateOutcome::kAmbiguous;  // two within the gate: no guess
    ApplyUpdate(z, best);
    return UpdateOutcome::kUpdated;
  }
  if (best < 0 || best_d2 > options_.association.new_chi2) {
    AddLandmark(z);
    return UpdateOutcome::kAdded;
  }
  return UpdateOutcome::kRejected;  // between the gates: neither matched nor surely new
}

std::vector<int> EkfSlam::JointCompatibility(const std::vector<RangeBearing>& frame) const {
  const int m = static_cast<int>(frame.size());
  const int n = landmark_count();
  // Individually compatible candidates per measurement (same signature, inside the gate).
  std::vector<std::vector<int>> candidates(m);
  for (int i = 0; i < m; ++i) {
    if (frame[i].id >= 0) continue;
    for (int j = 0; j < n; ++j) {
      if (signatures_[j] == frame[i].signature &&
          Mahalanobis2(frame[i], j) < options_.association.gate_chi2) {
        candidates[i].push_back(j);
      }
    }
  }
  // Joint Mahalanobis distance of a hypothesis (pairs measurement -> landmark).
  // S = H P H^T + R over the pose and the paired landmarks only (H is zero elsewhere).
  const auto joint_d2 = [&](const std::vector<std::pair<int, int>>& pairs) {
    const int k = static_cast<int>(pairs.size());
    const int size = 3 + 2 * k;
    std::vector<int> rows = {0, 1, 2};
    for (const auto& pair : pairs)
      rows.insert(rows.end(), {3 + 2 * pair.second, 4 + 2 * pair.second});
    Eigen::MatrixXd p_sub(size, size);
    for (int a = 0; a < size; ++a)
      for (int b = 0; b < size; ++b) p_sub(a, b) = p_(rows[a], rows[b]);
    Eigen::VectorXd e(2 * k);
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(2 * k, size);
    Eigen::MatrixXd r = Eigen::MatrixXd::Zero(2 * k, 2 * k);
    for (int p = 0; p < k; ++p) {
      const auto [i, j] = pairs[p];
      Eigen::Matrix<double, 2, 3> h_pose;
      Eigen::Matrix2d h_l;
      e.segment<2>(2 * p) = Innovation(frame[i], j, &h_pose, &h_l);
      h.block<2, 3>(2 * p, 0) = h_pose;
      h.block<2, 2>(2 * p, 3 + 2 * p) = h_l;
      r.block<2, 2>(2 * p, 2 * p) = NoiseOf(frame[i]);
    }
    const Eigen::MatrixXd s = h * p_sub * h.transpose() + r;
    return e.dot(s.ldlt().solve(e));
  };
  // Depth-first branch and bound over the measurements.
  std::vector<int> best(m, -1), current(m, -1);
  int best_pairs = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  std::vector<std::pair<int, int>> pairs;
  std::vector<bool> used(n, false);
  const std::function<void(int)> search = [&](int i) {
    if (i == m) {
      const int k = static_cast<int>(pairs.size());
      const double d2 = k ? joint_d2(pairs) : 0.0;
      if (k > best_pairs || (k == best_pairs && d2 < best_d2))
        best_pairs = k, best_d2 = d2, best = current;
      return;
    }
    // Bound: even pairing every remaining measurement cannot beat the best.
    int remaining = 0;
    for (int r = i; r < m; ++r) remaining += !candidates[r].empty();
    if (static_cast<int>(pairs.size()) + remaining < best_pairs) return;
    for (int j : candidates[i]) {
      if (used[j]) continue;
      pairs.emplace_back(i, j);
      // Joint compatibility at 99 % for 2k degrees of freedom.
      if (joint_d2(pairs) < Chi2Quantile(0.99, 2 * static_cast<int>(pairs.size()))) {
        used[j] = true;
        current[i] = j;
        search(i + 1);
        current[i] = -1;
        used[j] = false;
      }
      pairs.pop_back();
    }
    search(i + 1);  // this measurement unpaired
  };
  search(0);
  return best;
}

std::vector<UpdateOutcome> EkfSlam::UpdateFrame(const std::vector<RangeBearing>& frame) {
  std::vector<UpdateOutcome> out(frame.size(), UpdateOutcome::kRejected);
  const std::vector<int> pairing = JointCompatibility(frame);
  // Remember the landmarks before any update: indices stay valid (landmarks are appended).
  std::vector<bool> add(frame.size(), false);
  for (size_t i = 0; i < frame.size(); ++i) {
    const RangeBearing& z = frame[i];
    if (!(z.range_m > 0.0) || z.range_m > options_.max_range_m || !std::isfinite(z.bearing_rad))
      continue;
    if (z.id >= 0) {
      out[i] = Associate(z);
    } else if (pairing[i] >= 0) {
      ApplyUpdate(z, pairing[i]);
      out[i] = UpdateOutcome::kUpdated;
    } else {
      add[i] = true;
    }
  }
  // Unpaired measurements: a new landmark only when far from every same-signature one.
  for (size_t i = 0; i < frame.size(); ++i) {
    if (!add[i] || !options_.add_landmarks) continue;
    double nearest = std::numeric_limits<double>::infinity();
    for (int j = 0; j < landmark_count(); ++j) {
      if (signatures_[j] == frame[i].signature)
        nearest = std::min(nearest, Mahalanobis2(frame[i], j));
    }
    if (nearest > options_.association.new_chi2) {
      AddLandmark(frame[i]);
      out[i] = UpdateOutcome::kAdded;
    }
  }
  for (UpdateOutcome o : out) Count(o);
  return out;
}

double PoseNees(const Eigen::Vector3d& truth, const Eigen::Vector3d& estimate,
                const Eigen::Matrix3d& covariance) {
  Eigen::Vector3d e = truth - estimate;
  e.z() = Wrap(e.z());
  return e.dot(covariance.ldlt().solve(e));
}

std::pair<double, double> NeesBand(int dof, int runs) {
  const int k = dof * runs;
  return {Chi2Quantile(0.025, k) / runs, Chi2Quantile(0.975, k) / runs};
}

Eigen::Matrix2d IteratedFrameCovariance(const Eigen::Matrix2d& white, const Eigen::Matrix2d& bias,
                                        int frame_index) {
  Eigen::Matrix2d r = Eigen::Matrix2d::Zero();
  for (int c = 0; c < 2; ++c) {
    const double w = white(c, c), b = bias(c, c);
    const int k = std::max(1, frame_index);
    r(c, c) = w > 0.0 ? (w + k * b) * (w + (k - 1) * b) / w : w + b;
  }
  return r;
}

}  // namespace slamo::mapping
