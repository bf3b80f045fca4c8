// Online extrinsic calibration in Singer-LIO end to end on a short simulated sequence (medium
// regime, tuning index 100, 16 beams, every 4th firing): from a nominal extrinsic 3° and 10 cm
// off the truth, the estimate moves towards the truth and its marginal σ shrinks from the prior's;
// the extrinsic is a static state that stays in the window (kept by the marginal prior) and is
// read by every lidar residual. Off, no extrinsic state exists.
#include <ceres/covariance.h>
#include <gtest/gtest.h>

#include <cmath>

#include "common/sim_lio.h"
#include "ctlio/sim/extrinsic_error.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "ctlio/solvers/lio/state_keys.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

// The clock right: the extrinsic alone starts wrong.
sim::SimConfig Sequence(double duration_s) {
  return testing::WrongCalibrationSequence(sim::Regime::kMedium, duration_s, 0.0);
}

OdometryConfig Config(bool estimate) {
  OdometryConfig c = testing::SimLioConfig();
  c.calibration.estimate_extrinsic = estimate;
  return c;
}

// Runs the sequence through LioOdometry; returns the odometry for its window.
std::unique_ptr<LioOdometry> RunSequence(const sim::SimConfig& sim_config, OdometryConfig config,
                                         std::vector<ScanResult>* results) {
  sim::SimulatedSource source(sim_config);
  config.T_imu_lidar = source.ImuFromLidar();
  config.gravity = *source.Gravity();
  auto odometry = MakeLioOdometry(config);
  io::ScanFrame f;
  while (source.Next(&f)) {
    for (const io::ImuSample& x : f.imu) odometry->AddImu(x);
    results->push_back(odometry->AddScan(lioapp::TakeLidarScan(&f)));
  }
  return odometry;
}

TEST(ExtrinsicCalibration, ConvergesFromAWrongStartAndSigmaShrinks) {
  const sim::SimConfig c = Sequence(4.0);
  std::vector<ScanResult> results;
  const auto odometry = RunSequence(c, Config(true), &results);
  ASSERT_FALSE(results.empty());
  const ScanResult& last = results.back();
  ASSERT_NE(last.status, ScanStatus::kFailed) << last.message;
  ASSERT_TRUE(last.calibration.has_extrinsic);
  const sim::ExtrinsicErrorSize start =
      sim::MeasureExtrinsicError(*c.nominal_imu_from_lidar, c.imu_from_lidar);
  const sim::ExtrinsicErrorSize end =
      sim::MeasureExtrinsicError(last.calibration.T_imu_lidar, c.imu_from_lidar);
  EXPECT_NEAR(start.rotation_deg, 3.0, 1e-9);
  // Measured on this sequence: 0.07° and 1.0 cm after 4 s, σ ≤ 0.21° and ≤ 4.1 cm per axis.
  EXPECT_LT(end.rotation_deg, 0.5);
  EXPECT_LT(end.translation_m, 0.03);
  // The prior's σ is 5° and 0.2 m per axis; the marginal σ must have shrunk well below it, and
  // cover the error (3σ per axis).
  const Vec6& s = last.calibration.extrinsic_sigma;
  EXPECT_GT(s.minCoeff(), 0.0);
  EXPECT_LT(s.head<3>().maxCoeff(), 0.08);
  EXPECT_LT(s.tail<3>().maxCoeff(), 0.5 * M_PI / 180.0);
  const sim::SigmaCoverage covered =
      sim::CoveredBySigma(last.calibration.T_imu_lidar, c.imu_from_lidar, s);
  EXPECT_TRUE(covered.rotation);
  EXPECT_TRUE(covered.translation);
  // A static state: every marginalisation keeps it, and the lidar residuals read it: with the
  // default residual_blocks ("square_root") one batch per knot interval of the newest scan
  // besides the marginal prior (ContinuousLidarTerm::batched).
  EXPECT_GT(odometry->num_marginalizations(), 10);
  const std::vector<StateId>& kept = odometry->last_marginalization().kept;
  EXPECT_NE(std::find(kept.begin(), kept.end(), kExtrinsicKey), kept.end());
  EXPECT_GE(odometry->window().ResidualBlocksOf(kExtrinsicKey).size(), 2u);
}

// The reported marginal σ of the calibration states (the Schur complement of the whole window's
// information onto them, LioOdometry::ReportCalibrationCovariance) is the window's pseudo-inverse
// as Ceres computes it (ceres::Covariance, dense SVD of the Jacobian, null space dropped: C_mi
// is refined with the extrinsic and its yaw about gravity is free), with both calibrations.
TEST(ExtrinsicCalibration, ReportedSigmaIsTheWindowsPseudoInverse) {
  sim::SimConfig c = Sequence(1.0);
  c.imu.stamp_offset_s = 0.02;
  OdometryConfig config = Config(true);
  config.calibration.estimate_time_offset = true;
  std::vector<ScanResult> results;
  const auto odometry = RunSequence(c, config, &results);
  const ScanResult& last = results.back();
  ASSERT_NE(last.status, ScanStatus::kFailed) << last.message;
  ASSERT_EQ(last.calibration.time_offset_sigma_s.size(), 1u);
  SlidingWindow& window = odometry->window();
  const double* offset = window.State(TimeOffsetKey(0));
  const double* extrinsic = window.State(kExtrinsicKey);
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.null_space_rank = -1;
  ceres::Covariance covariance(options);
  ASSERT_TRUE(covariance.Compute({{offset, offset}, {extrinsic, extrinsic}}, &window.problem()));
  double var = 0.0;
  ASSERT_TRUE(covariance.GetCovarianceBlockInTangentSpace(offset, offset, &var));
  EXPECT_NEAR(last.calibration.time_offset_sigma_s[0], std::sqrt(var), 1e-6 * std::sqrt(var));
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> block;
  ASSERT_TRUE(covariance.GetCovarianceBlockInTangentSpace(extrinsic, extrinsic, block.data()));
  const Vec6 reference = block.diagonal().cwiseSqrt();
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(last.calibration.extrinsic_sigma[i], reference[i], 1e-6 * reference[i]) << i;
  }
  // And well below the priors' (30 ms; 0.2 m, 5°): the measurements are in it.
  EXPECT_LT(last.calibration.time_offset_sigma_s[0], 0.003);
  EXPECT_LT(last.calibration.extrinsic_sigma.tail<3>().maxCoeff(), 2.0 * M_PI / 180.0);
}

TEST(ExtrinsicCalibration, OffThereIsNoExtrinsicState) {
  std::vector<ScanResult> results;
  const auto odometry = RunSequence(Sequence(0.5), Config(false), &results);
  EXPECT_FALSE(odometry->window().HasState(kExtrinsicKey));
  for (const ScanResult& r : results) EXPECT_FALSE(r.calibration.has_extrinsic);
}

}  // namespace
}  // namespace ctlio::lio
