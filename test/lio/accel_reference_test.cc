// The accelerometer against a lidar + gyro reference (apps/lio/accel_reference.h):
//   * the rule on given fits: a relabelling that explains the reference's accelerations clearly
//     better than the axes as read, and about as well as a free map, is warned about and named;
//     a gain below the threshold, or a relabelling far worse than the free map (a reference that
//     is poor in a way no relabelling describes), is not;
//   * end to end on the short simulated sequence (fixed seed), both methods: the clean run is not
//     warned about and its estimate is the same with the reference as without, bit for bit; an
//     x↔z-swapped accelerometer is warned about and read back as (+z, +y, +x) — for the baseline
//     also where the frame check of its own trajectory (frame_consistency.h) stays below its
//     threshold (the fused trajectory follows the swapped accelerometer part of the way).
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
      if (name == "clean") {
        EXPECT_EQ(run.accel_relabelling, "");
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

}  // namespace
}  // namespace ctlio::lio
