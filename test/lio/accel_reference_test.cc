// The accelerometer against a lidar + gyro reference (apps/lio/accel_reference.h):
//   * the rule on given fits: a relabelling that explains the reference's accelerations clearly
//     better than the axes as read, and about as well as a free map, is warned about and named;
//     a gain below the threshold, or a relabelling far worse than the free map (a reference that
//     is poor in a way no relabelling describes), is not;
//   * end to end on the short simulated sequence (fixed seed), both methods: the clean run is not
//     warned about and its estimate is the same with the reference as without, bit for bit; an
//     x↔z-swapped accelerometer is warned about and read back as (+z, +y, +x) — for the baseline
//     also where the frame check of its own trajectory (frame_consistency.h) stays below its
//     threshold (the fused trajectory follows the swapped accelerometer part of the way);
//   * the disagreement with the reference: the rule on given values (above the threshold fraction
//     of the path warns, below it or over a short path does not), and end to end: the clean runs
//     stay below it, a sign-flipped accelerometer with the baseline (the kind of run that no
//     relabelling in a poor reference explains) is warned.
#include "lio/accel_reference.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "common/mutated_source.h"
#include "common/sim_lio.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

lioapp::FrameConsistency Fit(double identity, double best, double free) {
  lioapp::FrameConsistency r;
  r.windows = 40;
  r.identity_rms = identity;
  r.best_relabelling_rms = best;
  r.free_rms = free;
  r.best_relabelling = "(+y, +x, +z)";
  return r;
}

TEST(AccelReference, ARelabellingThatExplainsTheReferenceIsNamed) {
  const std::string w = lioapp::RelabellingWarning(Fit(0.24, 0.013, 0.010), 80);
  EXPECT_NE(w.find("accelerometer axes look swapped/flipped: best relabelling true (x, y, z) = "
                   "reading (+y, +x, +z)"),
            std::string::npos)
      << w;
  // Gain below the threshold: a walk where a relabelling barely changes the fit.
  EXPECT_EQ(lioapp::RelabellingWarning(Fit(0.29, 0.29, 0.28), 80), "");
  // A relabelling that fits better than I but far worse than a free map: the reference itself is
  // off (a clean slow run's lidar + gyro trajectory, measured 0.38 / 0.17 / 0.010).
  EXPECT_EQ(lioapp::RelabellingWarning(Fit(0.38, 0.17, 0.010), 80), "");
  EXPECT_EQ(lioapp::RelabellingWarning(lioapp::FrameConsistency(), 80), "");
}

// The medium test sequence, 4.5 s, every IMU sample's specific force passed through `mutate`.
testing::MutatedSource Mutated(std::function<Vec3(const Vec3&)> mutate) {
  sim::SimConfig c = testing::ShortMediumSequence();
  c.duration_s = 4.5;
  return testing::AccelMutatedSource(c, std::move(mutate));
}

lioapp::RunOptions WithReference() {
  lioapp::RunOptions o;
  o.accel_reference_scans = 100;
  o.accel_reference_config = testing::SimLioConfig().ForMethod(LioMethod::kLidarGyro);
  return o;
}

TEST(AccelReference, ASwappedAccelerometerIsWarnedCleanIsNotAndTheEstimateIsUnchanged) {
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput}) {
    for (const auto& [name, mutate] : testing::AccelerometerFaults()) {
      if (name == "sign flipped") continue;  // the frame check's own case
      SCOPED_TRACE(name + " " + LioMethodName(m));
      const OdometryConfig config = testing::SimLioConfig().ForMethod(m);
      testing::MutatedSource source = Mutated(mutate);
      const lioapp::RunSummary run = lioapp::RunOdometry(source, config, WithReference());
      const lioapp::FrameConsistency& ref = run.accel_reference;
      std::printf(
          "%s, %s: reference over %d scans: residual as read %.3g, best relabelling %s %.3g, "
          "free %.3g; own frame residual %.3g; ATE %.4f\n",
          LioMethodName(m).c_str(), name.c_str(), run.accel_reference_scans, ref.identity_rms,
          ref.best_relabelling.c_str(), ref.best_relabelling_rms, ref.free_rms,
          run.frames.identity_rms, run.ate ? run.ate->rmse : -1.0);
      EXPECT_GE(ref.windows, 15);
      std::printf(
          "  reference disagreement %.4g m RMS (max %.4g) over %.3g m, %d poses; extent %.3g m "
          "(estimate %.3g m)\n",
          run.reference_rms_m, run.reference_max_m, run.reference_path_m, run.reference_pairs,
          run.reference_extent_m, run.estimate_extent_m);
      EXPECT_GE(run.reference_pairs, 20);
      EXPECT_EQ(run.reference_ran_off, "");
      if (name == "clean") {
        EXPECT_EQ(run.accel_relabelling, "");
        EXPECT_EQ(run.reference_disagreement, "");
        testing::MutatedSource again = Mutated(mutate);
        const lioapp::RunSummary plain = lioapp::RunOdometry(again, config);
        EXPECT_EQ(plain.accel_reference_scans, 0);
        ASSERT_EQ(plain.trajectory.size(), run.trajectory.size());
        for (size_t i = 0; i < run.trajectory.size(); ++i) {
          EXPECT_EQ(plain.trajectory[i].pose.Matrix(), run.trajectory[i].pose.Matrix()) << i;
        }
      } else {
        EXPECT_NE(run.accel_relabelling.find("reading (+z, +y, +x)"), std::string::npos)
            << run.accel_relabelling;
        if (m == LioMethod::kImuInput) {
          // Without the reference this run is not warned: the frame check of the baseline's own
          // trajectory stays below its threshold.
          EXPECT_EQ(run.frames.warning, "");
        }
      }
    }
  }
}

TEST(AccelReference, ADepartureFromTheReferenceIsWarnedAboveItsFractionOfThePath) {
  lioapp::ReferenceDisagreement d;
  d.pairs = 80;
  d.path_m = 10.0;
  d.rms_m = 2.0;
  d.max_m = 4.5;
  const std::string w = lioapp::DisagreementWarning(d, 80);
  EXPECT_NE(w.find("the estimate departs from a lidar + gyro reference (no accelerometer in it) by "
                   "2 m RMS (max 4.5 m) over the first 80 scans (20.0 % of its 10 m path; "
                   "threshold 15.0 %)"),
            std::string::npos)
      << w;
  d.rms_m = 0.72;  // 7.2 %: the largest clean run measured (a baseline town run, bad-input.md)
  EXPECT_EQ(lioapp::DisagreementWarning(d, 80), "");
  d.rms_m = 2.0;
  d.path_m = 0.5;  // hardly moved: the fraction is not judged
  EXPECT_EQ(lioapp::DisagreementWarning(d, 80), "");
  EXPECT_EQ(lioapp::DisagreementWarning(lioapp::ReferenceDisagreement(), 80), "");
}

// A reference that went further from its start than the estimate ran off on its own: not judged.
TEST(AccelReference, AReferenceThatWentFurtherThanTheEstimateIsNotJudged) {
  lioapp::ReferenceDisagreement d;
  d.pairs = 100;
  d.extent_m = 40.0;
  d.estimate_extent_m = 8.0;
  const std::string note = lioapp::ReferenceRanOff(d);
  EXPECT_NE(note.find("the lidar + gyro reference went 40 m from its start where the estimate "
                      "went 8 m (5.00x; more than 1.50x)"),
            std::string::npos)
      << note;
  // A method that follows a defective accelerometer goes further than the reference: judged.
  d.extent_m = 7.0;
  d.estimate_extent_m = 14.9;
  EXPECT_EQ(lioapp::ReferenceRanOff(d), "");
  // Within the ratio, or hardly moved: judged / not judged either way, no note.
  d.extent_m = 8.8;
  EXPECT_EQ(lioapp::ReferenceRanOff(d), "");
  d.extent_m = 0.9;
  d.estimate_extent_m = 0.1;
  EXPECT_EQ(lioapp::ReferenceRanOff(d), "");
  EXPECT_EQ(lioapp::ReferenceRanOff(lioapp::ReferenceDisagreement()), "");
}

// The medium box sequence at 32 beams over 8 s: a reference good to 1-2 cm, so that a baseline run
// that follows a flipped accelerometer away (ATE ~5 m) departs from it by more than the path.
TEST(AccelReference, AFlippedAccelerometerThatTheBaselineFollowsDepartsFromTheReference) {
  for (const auto& [name, mutate] : testing::AccelerometerFaults()) {
    if (name == "x and z swapped") continue;  // the relabelling's case, 0.4 % of the path here
    SCOPED_TRACE(name);
    sim::SimConfig c = testing::ShortMediumSequence();
    c.duration_s = 8.0;
    c.lidar.beams = 32;
    c.lidar.firing_decimation = 2;
    testing::MutatedSource source = testing::AccelMutatedSource(c, mutate);
    const lioapp::RunSummary run = lioapp::RunOdometry(
        source, testing::SimLioConfig().ForMethod(LioMethod::kImuInput), WithReference());
    std::printf(
        "imu_input, %s: %.4g m RMS (max %.4g) over %.3g m (estimate %.3g m); extent %.3g m "
        "(estimate %.3g m); ATE %.4f\n",
        name.c_str(), run.reference_rms_m, run.reference_max_m, run.reference_path_m,
        run.reference_estimate_path_m, run.reference_extent_m, run.estimate_extent_m,
        run.ate ? run.ate->rmse : -1.0);
    EXPECT_GE(run.reference_path_m, 5.0);
    EXPECT_EQ(run.reference_ran_off, "");
    if (name == "clean") {
      // Measured 0.014 m over 7.35 m (0.19 %).
      EXPECT_LT(run.reference_rms_m, 0.02 * run.reference_path_m);
      EXPECT_EQ(run.reference_disagreement, "");
    } else {
      // Measured 8.5 m over 7.35 m (116 %).
      EXPECT_NE(
          run.reference_disagreement.find("the estimate departs from a lidar + gyro reference"),
          std::string::npos)
          << run.reference_disagreement;
    }
  }
}

}  // namespace
}  // namespace ctlio::lio
