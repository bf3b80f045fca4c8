// The calibration states' part on its own (calibration_states.h): which window blocks are the
// calibration, the hold priors from a mask and their release, on a window of a clock offset and
// an extrinsic with nothing else in it.
#include "ctlio/solvers/lio/calibration_states.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ctlio/factors/priors/euclidean_prior.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/solvers/lio/state_keys.h"

namespace ctlio::lio {
namespace {

CalibrationOptions BothEstimated() {
  CalibrationOptions options;
  options.estimate_time_offset = true;
  options.estimate_extrinsic = true;
  return options;
}

// δ_0 = 10 ms and T_imu_lidar = (0.1, 0, 0) m, each with a weak prior pulling it elsewhere
// (δ towards 40 ms with the prior's σ; the extrinsic 5 cm along y), so that a solve moves every
// coordinate unless it is held.
class CalibrationStatesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    window_.AddVectorState(TimeOffsetKey(0), Eigen::VectorXd::Constant(1, 0.010));
    window_.AddPoseState(kExtrinsicKey, T0_);
    const CalibrationOptions o = BothEstimated();
    window_.AddResidualBlock(
        new EuclideanPrior<1>(Eigen::Matrix<double, 1, 1>(0.040),
                              Eigen::Matrix<double, 1, 1>(1.0 / o.time_offset_prior_sigma_s)),
        nullptr, {TimeOffsetKey(0)});
    Mat6 sqrt_information = Mat6::Identity();
    sqrt_information.topLeftCorner<3, 3>() /= o.extrinsic_prior_sigma_m;
    sqrt_information.bottomRightCorner<3, 3>() /= o.extrinsic_prior_sigma_deg * M_PI / 180.0;
    window_.AddResidualBlock(new PosePrior(Pull() * T0_, sqrt_information), nullptr,
                             {kExtrinsicKey});
  }

  // The extrinsic pull in calibration.csv's chart T = Exp([ρ; φ])·T0: 5 cm along y, 0.02 rad
  // about z.
  static SE3 Pull() { return SE3::Exp((Vec6() << 0.0, 0.05, 0.0, 0.0, 0.0, 0.02).finished()); }
  // The extrinsic's estimate in that chart.
  Vec6 Chart() const { return (window_.Pose(kExtrinsicKey) * T0_.Inverse()).Log(); }

  const SE3 T0_ = SE3(Mat3::Identity(), Vec3(0.1, 0.0, 0.0));
  SlidingWindow window_;
};

TEST_F(CalibrationStatesTest, IdsAreTheOffsetsThenTheExtrinsic) {
  const CalibrationStates states(BothEstimated(), 2);
  EXPECT_EQ(states.Ids(window_), (std::vector<StateId>{TimeOffsetKey(0), kExtrinsicKey}));
  window_.AddVectorState(TimeOffsetKey(1), Eigen::VectorXd::Zero(1));
  EXPECT_EQ(states.Ids(window_),
            (std::vector<StateId>{TimeOffsetKey(0), TimeOffsetKey(1), kExtrinsicKey}));
  SlidingWindow empty;
  EXPECT_TRUE(states.Ids(empty).empty());
}

// Within HoldUntil's span the masked coordinates do not move in a solve and the others do; the
// priors go with Release, and after the span nothing is held.
TEST_F(CalibrationStatesTest, HoldsTheMaskedCoordinatesWithinTheSpanAndReleasesThem) {
  CalibrationStates states(BothEstimated(), 1);
  // δ_0 and ρ_y held; ρ_x, ρ_z and φ free.
  const std::vector<bool> mask = {true, false, true, false, false, false, false};
  states.HoldUntil(1.0, mask);
  const int blocks = window_.num_residual_blocks();
  ScanResult result;
  states.Hold(0.5, &window_, &result);
  EXPECT_EQ(result.calibration.held, mask);
  EXPECT_EQ(window_.num_residual_blocks(), blocks + 2);  // one on δ_0, one on the extrinsic
  window_.Solve();
  // σ_hold = σ_prior / 1e4: 3 µs and 20 µm against pulls of 30 ms and 5 cm.
  EXPECT_NEAR(window_.State(TimeOffsetKey(0))[0], 0.010, 1e-5);
  EXPECT_NEAR(Chart()[1], 0.0, 1e-4);
  EXPECT_NEAR(Chart()[5], 0.02, 1e-3);  // φ_z free: at the pull
  states.Release(&window_);
  EXPECT_EQ(window_.num_residual_blocks(), blocks);
  window_.Solve();
  // Released: the pulls win.
  EXPECT_NEAR(window_.State(TimeOffsetKey(0))[0], 0.040, 1e-6);
  EXPECT_NEAR(Chart()[1], 0.05, 1e-4);
  // After the span (and hold_unobservable off) nothing is held.
  ScanResult later;
  states.Hold(1.5, &window_, &later);
  EXPECT_TRUE(later.calibration.held.empty());
  EXPECT_EQ(window_.num_residual_blocks(), blocks);
}

TEST_F(CalibrationStatesTest, AnEmptyMaskHoldsEverything) {
  CalibrationStates states(BothEstimated(), 1);
  states.HoldUntil(1.0, {});
  ScanResult result;
  states.Hold(1.0, &window_, &result);
  EXPECT_EQ(result.calibration.held, std::vector<bool>(7, true));
  window_.Solve();
  states.Release(&window_);
  EXPECT_NEAR(window_.State(TimeOffsetKey(0))[0], 0.010, 1e-5);
  EXPECT_LT(Chart().norm(), 1e-4);
}

// With hold_unobservable and no assessment yet every coordinate counts as unobservable: held.
TEST_F(CalibrationStatesTest, HoldUnobservableHoldsEverythingBeforeTheFirstAssessment) {
  CalibrationOptions options = BothEstimated();
  options.hold_unobservable = true;
  CalibrationStates states(options, 1);
  EXPECT_EQ(states.observability(), nullptr);
  ScanResult result;
  states.Hold(0.1, &window_, &result);
  EXPECT_EQ(result.calibration.held, std::vector<bool>(7, true));
  ASSERT_NE(states.observability(), nullptr);
  EXPECT_EQ(states.observability()->dimension(), 7);
  states.Release(&window_);
}

// Without an estimated calibration the part does nothing, whatever HoldUntil says.
TEST_F(CalibrationStatesTest, NothingWithoutAnEstimatedCalibration) {
  CalibrationStates states(CalibrationOptions{}, 1);
  states.HoldUntil(1.0, {});
  const int blocks = window_.num_residual_blocks();
  ScanResult result;
  states.Hold(0.5, &window_, &result);
  states.Report({}, &window_, &result);
  EXPECT_TRUE(result.calibration.held.empty());
  EXPECT_TRUE(result.calibration.time_offset_sigma_s.empty());
  EXPECT_EQ(window_.num_residual_blocks(), blocks);
}

// The covariance report: the two priors are all the information, so at their means σ is theirs.
TEST_F(CalibrationStatesTest, ReportsTheMarginalSigmaOfTheWindow) {
  CalibrationOptions options = BothEstimated();
  options.observability_horizon_scans = 0;  // no assessment: the σ only
  CalibrationStates states(options, 1);
  window_.Solve();
  ScanResult result;
  states.Report({}, &window_, &result);
  ASSERT_EQ(result.calibration.time_offset_sigma_s.size(), 1u);
  EXPECT_NEAR(result.calibration.time_offset_sigma_s[0], options.time_offset_prior_sigma_s, 1e-9);
  EXPECT_NEAR(result.calibration.extrinsic_sigma[1], options.extrinsic_prior_sigma_m, 1e-6);
  EXPECT_NEAR(result.calibration.extrinsic_sigma[5], options.extrinsic_prior_sigma_deg * M_PI / 180,
              1e-6);
  EXPECT_TRUE(result.calibration.observability.empty());
}

}  // namespace
}  // namespace ctlio::lio
