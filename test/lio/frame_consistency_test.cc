// The lidar–IMU frame consistency check (apps/lio/frame_consistency.h):
//   * on an analytic trajectory with exact IMU samples: the clean stream fits (residual near 0, no
//     warning); a flipped or axes-swapped accelerometer is warned about and its map read back as
//     the signed permutation; a pose frame rotated 5° from the IMU's is found as a 5° rotation
//     along excited axes; a platform that does not rotate excites no axis (no rotation verdict);
//     samples stamped on a clock offset from the lidar's fit once the offset is configured;
//   * end to end on a short simulated sequence (fixed seed), both methods: the clean run is not
//     warned about, the sign-flipped and the x↔z-swapped accelerometer are — the swapped one passed
//     the IMU χ² check (imu_consistency_run_test.cc) — except the baseline's swapped run, seen at
//     20× its clean residual but below the threshold; under --strict the warning is an error.
#include "lio/frame_consistency.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/mutated_source.h"
#include "common/sim_lio.h"
#include "ctlio/io/warning_limiter.h"
#include "ctlio/manifolds/so3.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

const Vec3 kGravity(0.0, 0.0, -9.81);

// An analytic motion: position and attitude of the IMU in the map frame.
struct Motion {
  double rotation = 1.0;  // scale of the attitude's swing (0: no rotation)
  Vec3 Position(double t) const {
    return Vec3(1.5 * std::sin(1.3 * t), 1.0 * std::sin(0.9 * t + 0.4), 0.3 * std::sin(2.1 * t));
  }
  Vec3 Acceleration(double t) const {
    return Vec3(-1.5 * 1.69 * std::sin(1.3 * t), -1.0 * 0.81 * std::sin(0.9 * t + 0.4),
                -0.3 * 4.41 * std::sin(2.1 * t));
  }
  Mat3 Attitude(double t) const {
    return so3::Exp(rotation * Vec3(0.4 * std::sin(1.1 * t), 0.3 * std::sin(0.7 * t + 1.0),
                                    0.8 * std::sin(0.5 * t)));
  }
  Vec3 Gyro(double t) const {  // body rate: Log(R(t−ε)ᵀR(t+ε)) / 2ε
    const double e = 1e-5;
    return so3::Log(Attitude(t - e).transpose() * Attitude(t + e)) / (2 * e);
  }
};

// 20 s of 200 Hz samples (each the motion at the middle of the 5 ms it holds over) and 10 Hz
// poses, the accelerometer through `accel`, the poses' frame rotated by Q from the IMU's. The
// samples are stamped `stamp_offset_s` early on the IMU's clock (stamp t − δ for the motion at
// t); the check is told the clock offset `configured_offset_s`.
lioapp::FrameConsistency Check(const Motion& motion, const std::function<Vec3(const Vec3&)>& accel,
                               const Mat3& Q = Mat3::Identity(), double stamp_offset_s = 0.0,
                               double configured_offset_s = 0.0) {
  lioapp::FrameConsistencyCheck check(SE3(), 0, {}, configured_offset_s);
  const int64_t dt = 5'000'000;
  const auto shift = static_cast<int64_t>(std::llround(stamp_offset_s * 1e9));
  for (int64_t k = 0; k * dt <= 20'000'000'000; ++k) {
    const double t = 1e-9 * static_cast<double>(k * dt) + 0.0025;
    imu::ImuSample s;
    s.t_ns = k * dt - shift;
    s.gyro = motion.Gyro(t);
    s.accel = accel(motion.Attitude(t).transpose() * (motion.Acceleration(t) - kGravity));
    check.AddImu(s);
    if (k % 20 == 0) {
      const double tp = 1e-9 * static_cast<double>(k * dt);
      check.AddPose(k * dt, SE3(motion.Attitude(tp) * Q, motion.Position(tp)));
    }
  }
  return check.Result();
}

TEST(FrameConsistency, AnAccelerometerInTheLidarsFrameFits) {
  const lioapp::FrameConsistency r = Check(Motion{}, [](const Vec3& f) { return f; });
  EXPECT_GT(r.windows, 150);
  EXPECT_LT(r.identity_rms, 0.02);
  EXPECT_LT(r.map_deviation, 0.05);
  EXPECT_EQ(r.map_reading, "(+x, +y, +z)");
  EXPECT_EQ(r.excited_axes, 3);
  EXPECT_LT(r.rotation_error.norm() * 180.0 / M_PI, 0.05);
  EXPECT_TRUE(r.warning.empty()) << r.warning;
}

TEST(FrameConsistency, AFlippedOrSwappedAccelerometerIsNamed) {
  lioapp::FrameConsistency r = Check(Motion{}, [](const Vec3& f) { return Vec3(-f); });
  EXPECT_GT(r.identity_rms, 1.0);
  EXPECT_EQ(r.map_reading, "(-x, -y, -z)");
  EXPECT_NE(r.warning.find("the accelerometer disagrees with the accelerations of the lidar"),
            std::string::npos)
      << r.warning;
  EXPECT_NE(r.warning.find("true (x, y, z) = reading (-x, -y, -z)"), std::string::npos);
  // A clock offset between IMU and lidar raises the same residual: it is named among the causes.
  EXPECT_NE(r.warning.find("clock offset between IMU and lidar"), std::string::npos) << r.warning;
  // The gyro is fine: no rotation verdict.
  EXPECT_EQ(r.warning.find("gyro's rotations"), std::string::npos) << r.warning;

  r = Check(Motion{}, [](const Vec3& f) { return Vec3(f.z(), f.y(), f.x()); });
  EXPECT_GT(r.identity_rms, 1.0);
  EXPECT_EQ(r.map_reading, "(+z, +y, +x)");
  EXPECT_NE(r.warning.find("reading (+z, +y, +x)"), std::string::npos) << r.warning;
  // Among the 47 relabellings other than the axes as read, the swap itself explains the positions
  // as well as the clean stream's own axes do (accel_reference.h judges by that).
  EXPECT_EQ(r.best_relabelling, "(+z, +y, +x)");
  EXPECT_LT(r.best_relabelling_rms, 0.02);
}

TEST(FrameConsistency, TheBestRelabellingOfACleanStreamFitsFarWorseThanItsAxes) {
  const lioapp::FrameConsistency r = Check(Motion{}, [](const Vec3& f) { return f; });
  EXPECT_FALSE(r.best_relabelling.empty());
  EXPECT_NE(r.best_relabelling, "(+x, +y, +z)");
  EXPECT_GT(r.best_relabelling_rms, 20.0 * r.identity_rms);
}

TEST(FrameConsistency, ARotatedExtrinsicIsFoundWhereTheRotationExcitesIt) {
  const Vec3 axis = Vec3(1.0, 0.4, 0.2).normalized();
  const Mat3 Q = so3::Exp(axis * (5.0 * M_PI / 180.0));
  lioapp::FrameConsistency r = Check(
      Motion{}, [](const Vec3& f) { return f; }, Q);
  EXPECT_EQ(r.excited_axes, 3);
  EXPECT_NEAR(r.rotation_error.norm() * 180.0 / M_PI, 5.0, 0.25);
  EXPECT_GT(std::abs(r.rotation_error.normalized().dot(axis)), 0.99);
  EXPECT_NE(r.warning.find("differ by a rotation of"), std::string::npos) << r.warning;
  EXPECT_NE(r.warning.find("extrinsic rotation"), std::string::npos) << r.warning;

  // Without rotation nothing is excited: no verdict either way (the same 5° frame error).
  Motion still;
  still.rotation = 0.0;
  r = Check(
      still, [](const Vec3& f) { return f; }, Q);
  EXPECT_EQ(r.excited_axes, 0);
  EXPECT_EQ(r.warning.find("differ by a rotation of"), std::string::npos) << r.warning;
}

// A configured clock offset (calibration.time_offset_s) places the samples on the lidar's clock
// as the estimator does. Measured before the check took it: a clean simulated fast run (16 beams,
// IMU stamps 20 ms off, the offset configured) was warned of a 9.2° extrinsic rotation.
TEST(FrameConsistency, AConfiguredClockOffsetIsAppliedToTheSamples) {
  const auto same = [](const Vec3& f) { return f; };
  const double delta = 0.1;
  lioapp::FrameConsistency r = Check(Motion{}, same, Mat3::Identity(), delta, 0.0);
  EXPECT_GT(r.identity_rms, 0.15);
  EXPECT_NE(r.warning.find("clock offset between IMU and lidar"), std::string::npos) << r.warning;

  r = Check(Motion{}, same, Mat3::Identity(), delta, delta);
  EXPECT_LT(r.identity_rms, 0.02);
  EXPECT_LT(r.rotation_error.norm() * 180.0 / M_PI, 0.05);
  EXPECT_TRUE(r.warning.empty()) << r.warning;
}

TEST(FrameConsistency, TooFewWindowsAreNotJudged) {
  lioapp::FrameConsistencyCheck check;
  for (int64_t k = 0; k <= 600; ++k) {  // 3 s: fewer than 15 windows of 2 s
    imu::ImuSample s;
    s.t_ns = k * 5'000'000;
    s.accel = Vec3(5.0, 0.0, 0.0);  // nothing like the poses' (still) motion
    check.AddImu(s);
    if (k % 20 == 0) check.AddPose(s.t_ns, SE3());
  }
  const lioapp::FrameConsistency r = check.Result();
  EXPECT_LT(r.windows, lioapp::FrameConsistencyOptions().min_windows);
  EXPECT_TRUE(r.warning.empty()) << r.warning;
}

// The medium test sequence, 4.5 s (enough windows of 2 s), every IMU sample's specific force
// passed through `mutate`.
testing::MutatedSource AccelMutated(std::function<Vec3(const Vec3&)> mutate) {
  sim::SimConfig c = testing::ShortMediumSequence();
  c.duration_s = 4.5;
  return testing::AccelMutatedSource(c, std::move(mutate));
}

TEST(FrameConsistency, SimulatedFlippedAndSwappedAccelerometersAreWarnedCleanIsNot) {
  const auto cases = testing::AccelerometerFaults();
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput}) {
    double clean = 0.0;
    for (const auto& [name, mutate] : cases) {
      SCOPED_TRACE(name + " " + LioMethodName(m));
      testing::MutatedSource source = AccelMutated(mutate);
      const lioapp::RunSummary run =
          lioapp::RunOdometry(source, testing::SimLioConfig().ForMethod(m));
      std::printf(
          "%s, %s: frame residual %.3g m/s^2 over %d windows, rotation %.3g deg (%d axes); "
          "ATE %.4f\n",
          LioMethodName(m).c_str(), name.c_str(), run.frames.identity_rms, run.frames.windows,
          run.frames.rotation_error.norm() * 180.0 / M_PI, run.frames.excited_axes,
          run.ate ? run.ate->rmse : -1.0);
      EXPECT_GE(run.frames.windows, 20);
      const double threshold = lioapp::FrameConsistencyOptions().max_identity_rms;
      if (name == "clean") {
        clean = run.frames.identity_rms;
        EXPECT_LT(clean, threshold / 2);
        EXPECT_TRUE(run.frames.warning.empty()) << run.frames.warning;
      } else if (m == LioMethod::kImuInput && name == "x and z swapped") {
        // Measured 0.135: seen (20x the clean run's) but below the threshold, which a clean
        // Livox walking run reached at 0.098 (docs/user-guide/bad-input.md).
        EXPECT_GT(run.frames.identity_rms, 10 * clean);
      } else {
        EXPECT_GT(run.frames.identity_rms, threshold);
        EXPECT_NE(run.frames.warning.find("the accelerometer disagrees"), std::string::npos)
            << run.frames.warning;
      }
    }
  }
}

TEST(FrameConsistency, UnderStrictAnInconsistentRunIsAnError) {
  testing::MutatedSource source =
      AccelMutated([](const Vec3& f) { return Vec3(f.z(), f.y(), f.x()); });
  io::WarningLimiter::SetStrict(true);
  try {
    lioapp::RunOdometry(source, testing::SimLioConfig());
    ADD_FAILURE() << "no error under strict";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the accelerometer disagrees"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("strict"), std::string::npos) << e.what();
  }
  io::WarningLimiter::SetStrict(false);
}

// The check judges the extrinsic the run starts from; a calibrating run starts from the wrong one
// on purpose. Measured before: a calibrating walk from a 3° / 10 cm wrong start under --strict
// stopped with the frame warning and wrote nothing.
TEST(FrameConsistency, UnderStrictACalibratingRunReportsItsStartValuesWithoutAnError) {
  sim::SimConfig c = testing::ShortMediumSequence();
  c.duration_s = 4.5;
  c.nominal_imu_from_lidar = SE3(so3::Exp(Vec3(0.0, 0.0, 8.0 * M_PI / 180.0)), Vec3::Zero());
  io::WarningLimiter::SetStrict(true);
  testing::MutatedSource fixed = testing::AccelMutatedSource(c, [](const Vec3& f) { return f; });
  EXPECT_THROW(lioapp::RunOdometry(fixed, testing::SimLioConfig()), std::runtime_error);
  OdometryConfig calibrating = testing::SimLioConfig();
  calibrating.calibration.estimate_extrinsic = true;
  testing::MutatedSource source = testing::AccelMutatedSource(c, [](const Vec3& f) { return f; });
  lioapp::RunSummary run;
  EXPECT_NO_THROW(run = lioapp::RunOdometry(source, calibrating));
  io::WarningLimiter::SetStrict(false);
  EXPECT_NE(run.frames.warning.find("differ by a rotation of"), std::string::npos)
      << run.frames.warning;
  EXPECT_NE(run.frames.warning.find("this run calibrates the extrinsic"), std::string::npos)
      << run.frames.warning;
  EXPECT_FALSE(run.failure);
}

}  // namespace
}  // namespace ctlio::lio
