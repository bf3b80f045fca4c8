// The perturbed nominal extrinsic of calibration experiments (sim/extrinsic_error.h): the text
// syntax and its errors, the nominal extrinsic off the truth by exactly the requested angle and
// distance (given or per-sequence drawn directions), and the simulated source handing out the
// nominal extrinsic while the lidar keeps moving with the truth.
#include "ctlio/sim/extrinsic_error.h"

#include <gtest/gtest.h>

#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {
namespace {

TEST(ExtrinsicError, ParsesAngleDistanceAndDirections) {
  const ExtrinsicError e = ParseExtrinsicError("3deg,0.10m");
  EXPECT_DOUBLE_EQ(e.rotation_deg, 3.0);
  EXPECT_DOUBLE_EQ(e.translation_m, 0.10);
  EXPECT_FALSE(e.rotation_axis.has_value());
  EXPECT_FALSE(e.translation_direction.has_value());
  const ExtrinsicError g = ParseExtrinsicError("0.1m@0:2:0,2deg@0:0:-1");
  EXPECT_DOUBLE_EQ(g.rotation_deg, 2.0);
  ASSERT_TRUE(g.rotation_axis && g.translation_direction);
  EXPECT_LT((*g.rotation_axis - Vec3(0, 0, -1)).norm(), 1e-15);
  EXPECT_LT((*g.translation_direction - Vec3(0, 1, 0)).norm(), 1e-15);
  EXPECT_TRUE(ParseExtrinsicError("").IsZero());
  EXPECT_TRUE(ParseExtrinsicError("0deg,0m").IsZero());
}

TEST(ExtrinsicError, MalformedTextThrowsQuotingIt) {
  for (const char* bad : {"3", "3rad", "-1deg", "3deg@0:0:0", "3deg@1:0", "xdeg", "1m,2m,3deg",
                          "nandeg", "0.1m@a:b:c"}) {
    try {
      ParseExtrinsicError(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(ExtrinsicError, NominalIsOffByExactlyTheRequestedAmounts) {
  const SE3 truth(so3::Exp(Vec3(0.1, -0.2, 0.3)), Vec3(0.05, -0.02, 0.1));
  const ExtrinsicError e = ParseExtrinsicError("3deg,0.10m");
  const SE3 a = NominalExtrinsic(truth, e, kExperimentSeed, 0);
  const ExtrinsicErrorSize s = MeasureExtrinsicError(a, truth);
  EXPECT_NEAR(s.rotation_deg, 3.0, 1e-9);
  EXPECT_NEAR(s.translation_m, 0.10, 1e-12);
  // Deterministic per sequence, different between sequences.
  const SE3 again = NominalExtrinsic(truth, e, kExperimentSeed, 0);
  EXPECT_EQ((again.Matrix() - a.Matrix()).norm(), 0.0);
  const SE3 other = NominalExtrinsic(truth, e, kExperimentSeed, 1);
  EXPECT_GT((other.Matrix() - a.Matrix()).norm(), 1e-3);
  // A given axis: the error rotation is about it.
  const SE3 z = NominalExtrinsic(truth, ParseExtrinsicError("2deg@0:0:1,0m"), kExperimentSeed, 0);
  const Vec3 phi = so3::Log(z.rotation() * truth.rotation().transpose());
  EXPECT_LT((phi - Vec3(0, 0, 2.0 * M_PI / 180.0)).norm(), 1e-12);
  EXPECT_EQ((z.translation() - truth.translation()).norm(), 0.0);
  EXPECT_EQ((NominalExtrinsic(truth, ExtrinsicError{}, 1, 2).Matrix() - truth.Matrix()).norm(),
            0.0);
}

TEST(ExtrinsicError, SigmaCoverageComparesEachAxisWithItsSigma) {
  const SE3 truth(so3::Exp(Vec3(0.1, 0.0, 0.0)), Vec3(0.1, 0.0, 0.0));
  const SE3 estimate = SE3::Exp((Vec6() << 0.01, 0, 0, 0, 0.002, 0).finished()) * truth;
  Vec6 sigma = Vec6::Constant(0.001);
  SigmaCoverage c = CoveredBySigma(estimate, truth, sigma);
  EXPECT_FALSE(c.translation);  // 1 cm error, 3σ = 3 mm
  EXPECT_TRUE(c.rotation);      // 2 mrad within 3 mrad
  sigma[0] = 0.004;
  sigma[4] = 0.0005;
  c = CoveredBySigma(estimate, truth, sigma);
  EXPECT_TRUE(c.translation);
  EXPECT_FALSE(c.rotation);
}

TEST(ExtrinsicError, SourceHandsOutTheNominalAndKeepsTheTruth) {
  SimConfig c = ExperimentConfig(Regime::kMedium, 0);
  c.duration_s = 0.3;
  c.lidar.beams = 4;
  SimulatedSource plain(c);
  c.nominal_imu_from_lidar =
      NominalExtrinsic(c.imu_from_lidar, ParseExtrinsicError("3deg,0.1m"), kExperimentSeed, 0);
  SimulatedSource perturbed(c);
  EXPECT_EQ((perturbed.ImuFromLidar().Matrix() - c.nominal_imu_from_lidar->Matrix()).norm(), 0.0);
  ASSERT_TRUE(perturbed.TrueImuFromLidar().has_value());
  EXPECT_EQ((perturbed.TrueImuFromLidar()->Matrix() - c.imu_from_lidar.Matrix()).norm(), 0.0);
  // The data are those of the true extrinsic: identical scans with and without the error.
  io::ScanFrame a, b;
  ASSERT_TRUE(plain.Next(&a));
  ASSERT_TRUE(perturbed.Next(&b));
  ASSERT_EQ(a.cloud.points.size(), b.cloud.points.size());
  for (size_t i = 0; i < a.cloud.points.size(); ++i) {
    EXPECT_EQ(a.cloud.points[i], b.cloud.points[i]);
  }
}

}  // namespace
}  // namespace ctlio::sim
