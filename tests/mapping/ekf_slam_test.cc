#include "mapping/ekf_slam.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace slamo::mapping {
namespace {

constexpr double kStep = 1e-6;

TEST(EkfSlamJacobianTest, ObservationMatchesNumericalDerivatives) {
  const Eigen::Vector3d pose(0.3, -0.2, 0.7);
  const Eigen::Vector2d l(1.4, 0.9);
  Eigen::Matrix<double, 2, 3> h_pose;
  Eigen::Matrix2d h_l;
  EkfSlam::ObserveJacobians(pose, l, &h_pose, &h_l);
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d plus = pose, minus = pose;
    plus(k) += kStep, minus(k) -= kStep;
    const Eigen::Vector2d numeric =
        (EkfSlam::Observe(plus, l) - EkfSlam::Observe(minus, l)) / (2 * kStep);
    EXPECT_NEAR((numeric - h_pose.col(k)).norm(), 0.0, 1e-6) << "pose column " << k;
  }
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector2d plus = l, minus = l;
    plus(k) += kStep, minus(k) -= kStep;
    const Eigen::Vector2d numeric =
        (EkfSlam::Observe(pose, plus) - EkfSlam::Observe(pose, minus)) / (2 * kStep);
    EXPECT_NEAR((numeric - h_l.col(k)).norm(), 0.0, 1e-6) << "landmark column " << k;
  }
}

TEST(EkfSlamJacobianTest, InverseObservationAndMotionMatchNumericalDerivatives) {
  const Eigen::Vector3d pose(0.3, -0.2, 0.7);
  const double r = 1.7, b = -0.4;
  Eigen::Matrix<double, 2, 3> g_pose;
  Eigen::Matrix2d g_z;
  const Eigen::Vector2d l = EkfSlam::InverseObserve(pose, r, b, &g_pose, &g_z);
  // The inverse model inverts the model.
  const Eigen::Vector2d z = EkfSlam::Observe(pose, l);
  EXPECT_NEAR(z.x(), r, 1e-12);
  EXPECT_NEAR(z.y(), b, 1e-12);
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d plus = pose, minus = pose;
    plus(k) += kStep, minus(k) -= kStep;
    const Eigen::Vector2d numeric = (EkfSlam::InverseObserve(plus, r, b, nullptr, nullptr) -
                                     EkfSlam::InverseObserve(minus, r, b, nullptr, nullptr)) /
                                    (2 * kStep);
    EXPECT_NEAR((numeric - g_pose.col(k)).norm(), 0.0, 1e-6);
  }
  const Eigen::Vector2d dr = (EkfSlam::InverseObserve(pose, r + kStep, b, nullptr, nullptr) -
                              EkfSlam::InverseObserve(pose, r - kStep, b, nullptr, nullptr)) /
                             (2 * kStep);
  const Eigen::Vector2d db = (EkfSlam::InverseObserve(pose, r, b + kStep, nullptr, nullptr) -
                              EkfSlam::InverseObserve(pose, r, b - kStep, nullptr, nullptr)) /
                             (2 * kStep);
  EXPECT_NEAR((dr - g_z.col(0)).norm(), 0.0, 1e-6);
  EXPECT_NEAR((db - g_z.col(1)).norm(), 0.0, 1e-6);

  const OdometryStep u{0.3, 0.02, 0.4};
  Eigen::Matrix3d f_pose, f_u;
  EkfSlam::Move(pose, u, &f_pose, &f_u);
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d plus = pose, minus = pose;
    plus(k) += kStep, minus(k) -= kStep;
    const Eigen::Vector3d numeric =
        (EkfSlam::Move(plus, u, nullptr, nullptr) - EkfSlam::Move(minus, u, nullptr, nullptr)) /
        (2 * kStep);
    EXPECT_NEAR((numeric - f_pose.col(k)).norm(), 0.0, 1e-6);
  }
}

// A world of landmarks, odometry drawn from the filter's own noise model and measurements
// from their stated covariance: the filter should be consistent.
struct Simulation {
  Simulation() {
    // A mildly nonlinear regime (heading noise 0.6 deg per step): the test checks the
    // filter's algebra; large heading noise makes any EKF overconfident by linearisation.
    options.motion.heading_sigma_per_m = 0.035;
  }
  std::vector<Eigen::Vector2d> landmarks{{2.0, 1.0}, {2.5, -1.0}, {0.5, 2.0}, {-1.0, -1.5}};
  EkfOptions options;
  Eigen::Matrix2d r = Eigen::Vector2d(0.01 * 0.01, 0.01 * 0.01).asDiagonal();

  // Drives a square-ish loop; returns the per-step pose NEES.
  std::vector<double> Run(uint64_t seed, bool known_ids) const {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n01(0.0, 1.0);
    Eigen::Vector3d truth(0, 0, 0);
    EkfSlam ekf(truth, Eigen::Matrix3d::Identity() * 1e-8, options);
    std::vector<double> nees;
    for (int step = 0; step < 40; ++step) {
      const OdometryStep u =
          step % 10 == 9 ? OdometryStep{0.0, 0.0, M_PI / 2} : OdometryStep{0.3, 0.0, 0.0};
      // The true motion: the commanded step plus noise drawn from the model.
      const Eigen::Matrix3d q = ekf.MotionCovariance(u);
      const OdometryStep noisy{u.dx_m + std::sqrt(q(0, 0)) * n01(rng),
                               u.dy_m + std::sqrt(q(1, 1)) * n01(rng),
                               u.dtheta_rad + std::sqrt(q(2, 2)) * n01(rng)};
      truth = EkfSlam::Move(truth, noisy, nullptr, nullptr);
      ekf.Predict(u);
      for (size_t i = 0; i < landmarks.size(); ++i) {
        Eigen::Vector2d z = EkfSlam::Observe(truth, landmarks[i]);
        if (z.x() > 4.0) continue;
        z += Eigen::Vector2d(0.01 * n01(rng), 0.01 * n01(rng));
        RangeBearing m{z.x(), z.y(), r, known_ids ? static_cast<int>(i) : -1, "marker"};
        ekf.Update(m);
      }
      nees.push_back(PoseNees(truth, ekf.pose(), ekf.pose_covariance()));
      // The covariance stays symmetric positive definite.
      const Eigen::MatrixXd& p = ekf.covariance();
      EXPECT_LT((p - p.transpose()).norm(), 1e-12);
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(p).eigenvalues().minCoeff(), 0.0);
    }
    return nees;
  }
};

TEST(EkfSlamTest, NeesInsideTheBandOverSeeds) {
  Simulation sim;
  const int runs = 50;
  std::vector<double> average(40, 0.0);
  for (int run = 0; run < runs; ++run) {
    const std::vector<double> nees = sim.Run(100 + run, true);
    for (size_t s = 0; s < nees.size(); ++s) average[s] += nees[s] / runs;
  }
  const auto [lo, hi] = NeesBand(3, runs);
  int inside = 0;
  double mean = 0.0;
  for (double a : average) inside += a >= lo && a <= hi, mean += a / average.size();
  // Loose: most steps inside the 95 % band, the overall mean near 3.
  EXPECT_GE(inside, 30) << "band [" << lo << ", " << hi << "], mean " << mean;
  EXPECT_GT(mean, 2.0);
  EXPECT_LT(mean, 4.5);
}

// The update multiplies the Joseph form out to stay O(n^2): it must equal the textbook
// (I - K H) P (I - K H)^T + K R K^T on a map whose landmarks are correlated with the pose.
TEST(EkfSlamTest, UpdateEqualsTheFullJosephForm) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  EkfSlam ekf(Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Matrix3d::Identity() * 1e-2);
  const Eigen::Matrix2d r = Eigen::Vector2d(4e-4, 3e-4).asDiagonal();
  for (int id = 0; id < 10; ++id) {
    ekf.Update({1.0 + 0.2 * id, -1.2 + 0.25 * id, r, id, "marker"});
    ekf.Predict(OdometryStep{0.05, 0.01, 0.02});
  }
  for (int trial = 0; trial < 20; ++trial) {
    const int index = trial % ekf.landmark_count();
    const Eigen::MatrixXd p = ekf.covariance();
    const Eigen::VectorXd x = ekf.state();
    const Eigen::Vector2d z = EkfSlam::Observe(x.head<3>(), ekf.landmark(index)) +
                              Eigen::Vector2d(0.01 * n01(rng), 0.01 * n01(rng));
    // The textbook update, with dense matrices.
    Eigen::Matrix<double, 2, 3> h_pose;
    Eigen::Matrix2d h_l;
    EkfSlam::ObserveJacobians(x.head<3>(), ekf.landmark(index), &h_pose, &h_l);
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(2, x.size());
    h.leftCols<3>() = h_pose;
    h.block<2, 2>(0, 3 + 2 * index) = h_l;
    const Eigen::MatrixXd k = p * h.transpose() * (h * p * h.transpose() + r).inverse();
    const Eigen::MatrixXd ikh = Eigen::MatrixXd::Identity(x.size(), x.size()) - k * h;
    const Eigen::MatrixXd expected = ikh * p * ikh.transpose() + k * r * k.transpose();

    ASSERT_EQ(ekf.Update({z.x(), z.y(), r, ekf.landmark_id(index), "marker"}),
              UpdateOutcome::kUpdated);
    const Eigen::MatrixXd& got = ekf.covariance();
    EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-12 * p.cwiseAbs().maxCoeff())
        << "trial " << trial;
    EXPECT_EQ((got - got.transpose()).cwiseAbs().maxCoeff(), 0.0);  // exactly symmetric
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(got).eigenvalues().minCoeff(), 0.0);
  }
}

TEST(EkfSlamTest, FirstEstimatesUpdateIsTheJosephFormAtThePredictedPoseAndFirstLandmark) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  EkfOptions options;
  options.first_estimates = true;
  EkfSlam ekf(Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Matrix3d::Identity() * 1e-2, options);
  const Eigen::Matrix2d r = Eigen::Vector2d(4e-4, 3e-4).asDiagonal();
  std::vector<Eigen::Vector2d> first;  // each landmark where it was placed
  for (int id = 0; id < 10; ++id) {
    ekf.Update({1.0 + 0.2 * id, -1.2 + 0.25 * id, r, id, "marker"});
    first.push_back(ekf.landmark(id));
    ekf.Predict(OdometryStep{0.05, 0.01, 0.02});
  }
  const Eigen::Vector3d predicted = ekf.pose();  // this step's prior: every update below uses it
  for (int trial = 0; trial < 20; ++trial) {
    const int index = trial % ekf.landmark_count();
    const Eigen::MatrixXd p = ekf.covariance();
    const Eigen::VectorXd x = ekf.state();
    const Eigen::Vector2d z = EkfSlam::Observe(x.head<3>(), ekf.landmark(index)) +
                              Eigen::Vector2d(0.01 * n01(rng), 0.01 * n01(rng));
    if (trial > 0) {
      ASSERT_GT((x.head<3>() - predicted).norm(), 0.0) << "moved since predicted";
    }
    Eigen::Matrix<double, 2, 3> h_pose;
    Eigen::Matrix2d h_l;
    EkfSlam::ObserveJacobians(predicted, first[index], &h_pose, &h_l);
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(2, x.size());
    h.leftCols<3>() = h_pose;
    h.block<2, 2>(0, 3 + 2 * index) = h_l;
    const Eigen::MatrixXd k = p * h.transpose() * (h * p * h.transpose() + r).inverse();
    const Eigen::MatrixXd ikh = Eigen::MatrixXd::Identity(x.size(), x.size()) - k * h;
    const Eigen::MatrixXd expected = ikh * p * ikh.transpose() + k * r * k.transpose();
    // The innovation is still taken at the latest estimate.
    Eigen::Vector2d e = z - EkfSlam::Observe(x.head<3>(), ekf.landmark(index));
    e.y() = std::remainder(e.y(), 2.0 * M_PI);
    const Eigen::VectorXd expected_x = x + k * e;

    ASSERT_EQ(ekf.Update({z.x(), z.y(), r, ekf.landmark_id(index), "marker"}),
              UpdateOutcome::kUpdated);
    EXPECT_LT((ekf.covariance() - expected).cwiseAbs().maxCoeff(), 1e-12 * p.cwiseAbs().maxCoeff())
        << "trial " << trial;
    Eigen::VectorXd dx = ekf.state() - expected_x;
    dx(2) = std::remainder(dx(2), 2.0 * M_PI);
    EXPECT_LT(dx.cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
  }
}

TEST(EkfSlamTest, NearestNeighbourAssociationMakesNoDuplicates) {
  Simulation sim;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  const Eigen::Vector3d truth(0, 0, 0);
  EkfSlam ekf(truth, Eigen::Matrix3d::Identity() * 1e-6, sim.options);
  for (int frame = 0; frame < 100; ++frame) {
    for (const Eigen::Vector2d& l : sim.landmarks) {
      Eigen::Vector2d z =
          EkfSlam::Observe(truth, l) + Eigen::Vector2d(0.01 * n01(rng), 0.01 * n01(rng));
      ekf.Update({z.x(), z.y(), sim.r, -1, "marker"});
    }
  }
  ASSERT_EQ(ekf.landmark_count(), 4);
  // Static scene: each landmark converges to the truth within its (shrunk) covariance.
  for (int i = 0; i < 4; ++i) {
    double best = 1e9;
    for (const Eigen::Vector2d& l : sim.landmarks)
      best = std::min(best, (ekf.landmark(i) - l).norm());
    EXPECT_LT(best, 0.01);
    EXPECT_LT(ekf.landmark_covariance(i).trace(), 1e-4);
  }
}

TEST(EkfSlamTest, SignaturesKeepColoursApartAndGatesRejectOutliers) {
  EkfSlam ekf(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 1e-6);
  const Eigen::Matrix2d r = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
  EXPECT_EQ(ekf.Update({2.0, 0.0, r, -1, "green"}), UpdateOutcome::kAdded);
  EXPECT_EQ(ekf.Update({2.0, 0.0, r, -1, "yellow"}), UpdateOutcome::kAdded);  // other colour
  EXPECT_EQ(ekf.Update({2.005, 0.002, r, -1, "green"}), UpdateOutcome::kUpdated);
  // Between the gates (a few sigma off): neither matched nor added.
  EXPECT_EQ(ekf.Update({2.04, 0.0, r, -1, "green"}), UpdateOutcome::kRejected);
  EXPECT_EQ(ekf.landmark_count(), 2);
  EXPECT_EQ(ekf.Update({9.0, 0.0, r, -1, "green"}), UpdateOutcome::kRejected);  // beyond range
}

// k sequential updates with R_k carry the information of the average of k frames.
TEST(IteratedFrameCovarianceTest, SequentialUpdatesEqualTheAverage) {
  const Eigen::Matrix2d white = Eigen::Vector2d(4e-4, 1e-4).asDiagonal();
  const Eigen::Matrix2d bias = Eigen::Vector2d(1e-4, 2e-5).asDiagonal();
  for (int k = 1; k <= 30; ++k) {
    double information = 0.0;
    for (int i = 1; i <= k; ++i) information += 1.0 / IteratedFrameCovariance(white, bias, i)(0, 0);
    EXPECT_NEAR(1.0 / information, white(0, 0) / k + bias(0, 0), 1e-12) << k;
  }
  EXPECT_DOUBLE_EQ(IteratedFrameCovariance(white, Eigen::Matrix2d::Zero(), 5)(1, 1), 1e-4);
}

TEST(NeesBandTest, MatchesChiSquareTables) {
  // chi2(3): 0.216 and 9.348; 50 runs: chi2(150) quantiles 117.98 and 185.80.
  const auto one = NeesBand(3, 1);
  EXPECT_NEAR(one.first, 0.216, 0.02);
  EXPECT_NEAR(one.second, 9.348, 0.05);
  const auto fifty = NeesBand(3, 50);
  EXPECT_NEAR(fifty.first, 117.98 / 50, 0.01);
  EXPECT_NEAR(fifty.second, 185.80 / 50, 0.01);
}

}  // namespace
}  // namespace slamo::mapping

namespace slamo::mapping {
namespace {

// Two same-coloured markers 0.3 m apart and a robot unsure where it is: each measurement
// alone fits both markers, so nearest neighbour refuses; jointly only one pairing fits.
TEST(JcbbTest, ResolvesWhatNearestNeighbourCannot) {
  const Eigen::Vector2d a(2.0, 0.15), b(2.0, -0.15);
  const Eigen::Vector3d truth(0.0, 0.0, 0.0);
  // The filter believes the robot 0.1 m to the left, with a wide covariance.
  const Eigen::Vector3d belief(0.0, 0.1, 0.0);
  const Eigen::Matrix3d belief_cov = Eigen::Vector3d(0.01, 0.04, 0.0025).asDiagonal();
  const Eigen::Matrix2d r = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
  const auto make_filter = [&] {
    EkfSlam ekf(belief, belief_cov);
    ekf.AddKnownLandmark(a, Eigen::Matrix2d::Identity() * 1e-6, -1, "green");
    ekf.AddKnownLandmark(b, Eigen::Matrix2d::Identity() * 1e-6, -1, "green");
    return ekf;
  };
  std::vector<RangeBearing> frame;
  for (const Eigen::Vector2d& l : {a, b}) {
    const Eigen::Vector2d z = EkfSlam::Observe(truth, l);
    frame.push_back({z.x(), z.y(), r, -1, "green"});
  }
  EkfSlam nn = make_filter();
  EXPECT_EQ(nn.Update(frame[0]), UpdateOutcome::kAmbiguous);

  EkfSlam jcbb = make_filter();
  EXPECT_EQ(jcbb.JointCompatibility(frame), (std::vector<int>{0, 1}));
  const std::vector<UpdateOutcome> outcomes = jcbb.UpdateFrame(frame);
  EXPECT_EQ(outcomes,
            (std::vector<UpdateOutcome>{UpdateOutcome::kUpdated, UpdateOutcome::kUpdated}));
  EXPECT_EQ(jcbb.landmark_count(), 2);
  EXPECT_LT((jcbb.pose().head<2>() - truth.head<2>()).norm(), 0.02);  // the belief is corrected
}

TEST(JcbbTest, UnpairedFarMeasurementsBecomeLandmarks) {
  EkfSlam ekf(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 1e-6);
  const Eigen::Matrix2d r = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
  const auto outcomes = ekf.UpdateFrame({{2.0, 0.3, r, -1, "green"}, {2.0, -0.3, r, -1, "green"}});
  EXPECT_EQ(outcomes, (std::vector<UpdateOutcome>{UpdateOutcome::kAdded, UpdateOutcome::kAdded}));
  // The same frame again pairs with them.
  const auto again = ekf.UpdateFrame({{2.001, 0.3, r, -1, "green"}, {1.999, -0.3, r, -1, "green"}});
  EXPECT_EQ(again, (std::vector<UpdateOutcome>{UpdateOutcome::kUpdated, UpdateOutcome::kUpdated}));
  EXPECT_EQ(ekf.landmark_count(), 2);
}

}  // namespace
}  // namespace slamo::mapping
