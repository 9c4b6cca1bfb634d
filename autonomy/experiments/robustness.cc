#include "autonomy/experiments/robustness.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "autonomy/experiments/peer_bench.h"
#include "mapping/ekf_slam.h"
#include "mapping/metrics.h"
#include "mapping/replay_log.h"
#include "platform/drive_base.h"

namespace slamo::autonomy {
namespace {

namespace fs = std::filesystem;
using platform::kPi;

// simul-landmarks' ini for one run.
void WriteIni(const std::string& path, const RobustnessOptions& o, const RobustnessCase& c,
              uint64_t seed) {
  std::ofstream out(path);
  out << "[Params]\nrandom_seed = " << seed << "\nnSteps = " << o.steps
      << "\ncircularPath = 0\nsquarePathLength = 50\nloadLandmarksFromFile =\n"
      << "odometryNoiseXY_std = " << o.odometry_xy_sigma_m * c.motion_factor
      << "\nodometryNoisePhi_std_deg = " << o.odometry_heading_sigma_deg * c.motion_factor
      << "\nminSensorDistance = 0\nmaxSensorDistance = " << o.max_range_m
      << "\nfieldOfView_deg = " << o.field_of_view_deg
      << "\nstdRange = " << o.range_sigma_m * c.sensor_factor
      << "\nstdYaw_deg = " << o.bearing_sigma_deg * c.sensor_factor
      << "\nstdPitch_deg = 0\noutFile = gen.rawlog\noutDir = OUT\nshow_in_3d = false\n\n"
      << "[RANDOMSET_1]\nnLandmarks = " << o.landmarks
      << "\nmin_x = -4\nmax_x = 12\nmin_y = -3\nmax_y = 12\nmin_z = 0\nmax_z = 0\n";
  if (!out) throw std::runtime_error(path + ": cannot write");
}

// The rows of one of simul-landmarks' text files (`%` comments skipped).
std::vector<std::vector<double>> ReadColumns(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open (did simul-landmarks run?)");
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '%') continue;
    std::istringstream fields(line);
    std::vector<double> row;
    double v;
    while (fields >> v) row.push_back(v);
    if (!row.empty()) rows.push_back(row);
  }
  return rows;
}

// The generated run as a peer scenario: step 0 holds what is seen before the first move, step
// k the k-th odometry increment and what is seen after it, with the truth after it (line k
// of the path file); both filters are told the options' noise, whatever the truth was.
PeerScenario ScenarioFrom(const std::string& dir, const PeerBenchOptions& told) {
  const mapping::ReplayLog log = mapping::ReadRawlog(dir + "/OUT/gen.rawlog");
  const std::vector<std::vector<double>> path =
      ReadColumns(dir + "/OUT/gen.rawlog_ground_truth_robot_path.txt");
  const Eigen::Matrix3d q = PeerStepCovariance(told);
  const Eigen::Matrix2d r = Eigen::Vector2d(told.sigma_range_m * told.sigma_range_m,
                                            told.sigma_bearing_rad * told.sigma_bearing_rad)
                                .asDiagonal();
  PeerScenario scenario;
  scenario.steps.emplace_back();
  for (const mapping::LogEvent& e : log.events) {
    if (e.is_odometry()) {
      PeerStep step;
      step.odometry = e.odometry();
      step.odometry.covariance = q;
      scenario.steps.push_back(step);
    } else {
      mapping::RangeBearing z = e.measurement();
      z.covariance = r;
      scenario.steps.back().measurements.push_back(z);
    }
  }
  if (path.size() < 2) throw std::runtime_error(dir + ": simul-landmarks wrote no robot path");
  if (scenario.steps.size() > path.size()) scenario.steps.resize(path.size());
  for (size_t k = 0; k < scenario.steps.size(); ++k) {
    if (path[k].size() < 4) throw std::runtime_error(dir + ": a robot path line without a yaw");
    scenario.steps[k].truth = Eigen::Vector3d(path[k][0], path[k][1], path[k][3]);
  }
  return scenario;
}

RobustnessScore Score(const PeerScenario& scenario, const PeerTrack& track,
                      const std::vector<mapping::LandmarkPoint>& landmarks, int measurements) {
  std::vector<Eigen::Vector2d> truth, estimate;
  double nees = 0.0;
  int nees_steps = 0;
  for (size_t k = 0; k < scenario.steps.size() && k < track.poses.size(); ++k) {
    truth.push_back(scenario.steps[k].truth.head<2>());
    const mapping::TimedPose& p = track.poses[k];
    estimate.emplace_back(p.x_m, p.y_m);
    if (k == 0 || track.covariances[k].determinant() <= 0.0) continue;
    nees += mapping::PoseNees(scenario.steps[k].truth, Eigen::Vector3d(p.x_m, p.y_m, p.theta_rad),
                              track.covariances[k]);
    ++nees_steps;
  }
  const mapping::AteResult ate = mapping::PairedTrajectoryError(truth, estimate, true);
  RobustnessScore s;
  s.ate_m = ate.rmse_m;
  s.landmark_rmse_m = mapping::LandmarkRmse(landmarks, track.landmarks, ate.alignment).rmse_m;
  s.mean_nees = nees_steps ? nees / nees_steps : 0.0;
  s.rejected_fraction = measurements ? static_cast<double>(track.rejected) / measurements : 0.0;
  s.ms_per_step = 1000.0 * track.filter_s / static_cast<double>(scenario.steps.size());
  return s;
}

void Accumulate(const RobustnessScore& s, int runs, RobustnessScore* sum) {
  sum->landmark_rmse_m += s.landmark_rmse_m / runs;
  sum->ate_m += s.ate_m / runs;
  sum->mean_nees += s.mean_nees / runs;
  sum->rejected_fraction += s.rejected_fraction / runs;
  sum->ms_per_step += s.ms_per_step / runs;
}

}  // namespace

std::vector<RobustnessCase> DefaultRobustnessCases() {
  std::vector<RobustnessCase> cases;
  for (double m : {0.5, 1.0, 2.0, 5.0, 10.0}) cases.push_back({m, 1.0});
  for (double s : {0.5, 2.0, 5.0, 10.0}) cases.push_back({1.0, s});
  return cases;
}

std::vector<RobustnessRow> RunRobustness(const RobustnessOptions& options,
                                         const std::vector<RobustnessCase>& cases, int runs,
                                         uint64_t seed, const std::string& work_dir,
                                         const std::function<void(int, int)>& progress) {
  if (runs < 1) throw std::invalid_argument("robustness: runs must be at least 1");
  if (std::system("command -v simul-landmarks > /dev/null 2>&1") != 0) {
    throw std::runtime_error(
        "simul-landmarks not found: it is MRPT's, in Debian's mrpt-apps "
        "(apt-get install mrpt-apps; ./slamo installs it)");
  }
  PeerBenchOptions told;
  told.sigma_step_xy_m = options.odometry_xy_sigma_m;
  told.sigma_step_heading_rad = options.odometry_heading_sigma_deg * kPi / 180.0;
  told.sigma_range_m = options.range_sigma_m;
  told.sigma_bearing_rad = options.bearing_sigma_deg * kPi / 180.0;
  told.max_range_m = options.max_range_m;
  told.adaptive = true;  // as `slamo replay` runs it
  told.first_estimates = true;
  std::vector<RobustnessRow> rows;
  int done = 0;
  const int total = static_cast<int>(cases.size()) * runs;
  for (size_t c = 0; c < cases.size(); ++c) {
    RobustnessRow row;
    row.noise = cases[c];
    row.slamo.rejected_fraction = row.mrpt.rejected_fraction = 0.0;
    for (int r = 0; r < runs; ++r) {
      const std::string dir = work_dir + "/case" + std::to_string(c) + "_run" + std::to_string(r);
      fs::create_directories(dir);
      WriteIni(dir + "/gen.ini", options, cases[c], seed + static_cast<uint64_t>(r));
      const std::string command =
          "cd '" + dir + "' && simul-landmarks gen.ini > simul-landmarks.log 2>&1";
      if (std::system(command.c_str()) != 0) {
        throw std::runtime_error("simul-landmarks failed in " + dir +
                                 " (see simul-landmarks.log there)");
      }
      const PeerScenario scenario = ScenarioFrom(dir, told);
      std::vector<mapping::LandmarkPoint> landmarks;
      for (const std::vector<double>& l : ReadColumns(dir + "/OUT/gen.rawlog_ground_truth.txt")) {
        if (l.size() >= 7) landmarks.push_back({static_cast<int>(l[6]), l[0], l[1]});
      }
      int measurements = 0;
      for (const PeerStep& s : scenario.steps)
        measurements += static_cast<int>(s.measurements.size());
      Accumulate(Score(scenario, RunSlamoFilter(scenario, told), landmarks, measurements), runs,
                 &row.slamo);
      PeerTrack mrpt = RunMrptFilter(scenario, told);
      RobustnessScore m = Score(scenario, mrpt, landmarks, measurements);
      m.rejected_fraction = 0.0;  // MRPT's filter does not report refusals
      Accumulate(m, runs, &row.mrpt);
      if (progress) progress(++done, total);
    }
    row.mrpt.rejected_fraction = -1.0;
    rows.push_back(row);
  }
  return rows;
}

}  // namespace slamo::autonomy
