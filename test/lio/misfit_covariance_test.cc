// window.pose_covariance_misfit (solvers/lio/misfit_covariance.h): where the newest interval's
// IMU χ² rejects the motion model, the covariance gains what that model's information was worth.
#include "ctlio/solvers/lio/misfit_covariance.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

// The test at the 0.999 quantiles of the IMU terms' dof: the baseline's preintegrated factor (9:
// 27.877), Singer-LIO's 20 samples of one sensor (60: 99.607) and of both (120: 173.617).
TEST(MisfitCovariance, TheFactorNeedsBothTheTestAndAReducedChiSquareAboveOne) {
  EXPECT_EQ(MisfitFactor(27.8, 9), 1.0);
  EXPECT_DOUBLE_EQ(MisfitFactor(27.95, 9), 27.95 / 9.0);
  EXPECT_EQ(MisfitFactor(173.5, 120), 1.0);
  EXPECT_DOUBLE_EQ(MisfitFactor(173.75, 120), 173.75 / 120.0);
  // χ²/dof > 1 but within the test: no misfit (a 9-dof χ² exceeds 9 in 44 % of fits).
  EXPECT_EQ(MisfitFactor(20.0, 9), 1.0);
  EXPECT_DOUBLE_EQ(MisfitFactor(60.0, 9), 60.0 / 9.0);
  EXPECT_DOUBLE_EQ(MisfitFactor(99720.0, 60), 1662.0);
  EXPECT_EQ(MisfitFactor(2.4, 60), 1.0);  // Singer-LIO's usual level (σ 5× the device's)
  EXPECT_EQ(MisfitFactor(std::numeric_limits<double>::quiet_NaN(), 9), 1.0);
  EXPECT_EQ(MisfitFactor(100.0, 0), 1.0);
}

double MinEigenvalue(const Mat6& A) {
  return Eigen::SelfAdjointEigenSolver<Mat6>(0.5 * (A + A.transpose())).eigenvalues()[0];
}

// A short run twice, without and with the key. Singer-LIO's configured IMU variances are a
// sixteenth of the file's (the estimate is the same in both runs), so that the test rejects the
// motion model at the motion's start and passes it elsewhere. The estimate is the same bit for
// bit; the covariance is the same where the scan's IMU χ² (ScanResult, at the same estimate)
// passes each sensor's test, and larger (positive semi-definite difference, a trace more than 1 %
// larger) where one does not.
TEST(MisfitCovariance, SameEstimateLargerCovarianceExactlyWhereTheImuRejectsTheModel) {
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput}) {
    const sim::SimConfig c = testing::ShortSparseSequence();
    // The method's resolved configuration (data/sim_lio.yaml's per_method), changed below.
    OdometryConfig config = testing::SimLioConfig().ForMethod(m);
    config.per_method.clear();
    config.pose_covariance = true;
    config.pose_covariance_misfit = false;  // data/sim_lio.yaml turns it on
    if (m == LioMethod::kSingerLio) {
      config.accel_variance /= 16.0;
      config.gyro_variance /= 16.0;
    }
    sim::SimulatedSource a_source(c), b_source(c);
    const lioapp::RunSummary a = lioapp::RunOdometry(a_source, config, lioapp::RunOptions{});
    config.pose_covariance_misfit = true;
    const lioapp::RunSummary b = lioapp::RunOdometry(b_source, config, lioapp::RunOptions{});
    ASSERT_EQ(a.scans.size(), b.scans.size());
    int rejected = 0, passed = 0;
    for (size_t k = 0; k < a.scans.size(); ++k) {
      const ScanResult &x = a.scans[k], &y = b.scans[k];
      EXPECT_EQ(x.T_mr.Matrix(), y.T_mr.Matrix()) << LioMethodName(m) << k;
      ASSERT_EQ(x.has_pose_covariance, y.has_pose_covariance);
      if (!x.has_pose_covariance) continue;
      const Mat6 added = y.pose_covariance - x.pose_covariance;
      const double tol = 1e-8 * y.pose_covariance.norm();
      const double f =
          std::max(MisfitFactor(x.accel_chi2, x.accel_dof), MisfitFactor(x.gyro_chi2, x.gyro_dof));
      if (f == 1.0) {
        EXPECT_LT(added.norm(), tol) << LioMethodName(m) << " scan " << k;
        ++passed;
      } else {
        EXPECT_GE(MinEigenvalue(added), -tol) << LioMethodName(m) << " scan " << k;
        EXPECT_GT(added.trace(), 0.01 * x.pose_covariance.trace()) << LioMethodName(m) << k;
        ++rejected;
      }
    }
    if (m == LioMethod::kSingerLio) {
      EXPECT_GE(rejected, 1);  // the motion's start (χ²/dof in the thousands)
    } else {
      // The preintegrated factor's 9 residuals are matched by the newest state's velocity and
      // pose (χ²/dof ~1e-7 here, ≤ 0.014 on the VLP-16 box): its test never rejects.
      EXPECT_EQ(rejected, 0);
    }
    EXPECT_GE(passed, 1) << LioMethodName(m);
  }
}

}  // namespace
}  // namespace ctlio::lio
