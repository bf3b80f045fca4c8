// The baseline's integration signal (imu_midpoint.h): instantaneous samples integrated at the
// segments' midpoints. A linearly varying rate integrates exactly; the zero-order hold lags by
// half a period, the error that made the baseline's rotation NEES hundreds.
#include "ctlio/solvers/lio/imu_midpoint.h"

#include <gtest/gtest.h>

#include <cmath>

#include "ctlio/factors/imu/preintegrated_imu.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio::lio {
namespace {

constexpr int64_t kOrigin = 2'000'000'000;  // ns

// Samples every 5 ms over [0, t_end] of the rate ω(t) = (0, 0, α t) and accel (t, 0, 0).
ImuBuffer Ramp(double alpha, double t_end) {
  ImuBuffer b;
  b.SetOrigin(kOrigin);
  for (int k = 0; 0.005 * k <= t_end + 1e-12; ++k) {
    ImuSample s;
    const double t = 0.005 * k;
    s.t_ns = kOrigin + std::llround(t * 1e9);
    s.gyro = Vec3(0, 0, alpha * t);
    s.accel = Vec3(t, 0, 0);
    b.AddImu(s);
  }
  return b;
}

TEST(ImuMidpoint, SegmentsCarryTheLinearSignalAtTheirCentres) {
  const ImuBuffer b = Ramp(2.0, 0.05);
  std::vector<ImuSegment> seg = b.Segments(0.0025, 0.0125, nullptr);
  ASSERT_EQ(seg.size(), 3u);  // [2.5, 5], [5, 10], [10, 12.5] ms
  InterpolateAtMidpoints(b, b.samples(0), &seg);
  EXPECT_NEAR(seg[0].gyro.z(), 2.0 * 0.00375, 1e-12);
  EXPECT_NEAR(seg[1].gyro.z(), 2.0 * 0.0075, 1e-12);
  EXPECT_NEAR(seg[2].gyro.z(), 2.0 * 0.01125, 1e-12);
  EXPECT_NEAR(seg[1].accel.x(), 0.0075, 1e-12);
  EXPECT_DOUBLE_EQ(seg[1].dt, 0.005);  // the segments themselves are unchanged
}

// The newest stretch (after the newest sample, before the next has arrived) takes the line
// through the last two samples at its centre: exact for a ramp. Beyond one sample period after
// the newest sample (a gap) the sample is held.
TEST(ImuMidpoint, NewestStretchIsExtrapolatedFromTheLastTwoSamples) {
  const ImuBuffer b = Ramp(2.0, 0.01);  // samples at 0, 5, 10 ms
  std::vector<ImuSegment> seg = b.Segments(0.005, 0.013, nullptr);
  ASSERT_EQ(seg.size(), 2u);
  InterpolateAtMidpoints(b, b.samples(0), &seg);
  EXPECT_NEAR(seg[0].gyro.z(), 2.0 * 0.0075, 1e-12);
  EXPECT_NEAR(seg[1].gyro.z(), 2.0 * 0.0115, 1e-12);  // centre of [10, 13] ms
  EXPECT_NEAR(seg[1].accel.x(), 0.0115, 1e-12);

  std::vector<ImuSegment> gap = b.Segments(0.005, 0.02, nullptr);  // ends 10 ms after the newest
  InterpolateAtMidpoints(b, b.samples(0), &gap);
  EXPECT_DOUBLE_EQ(gap.back().gyro.z(), 2.0 * 0.01);  // held
}

// A scan ending between samples, its next sample not yet arrived (as the odometry sees it):
// constant angular acceleration α, the angle over [0, T] is αT²/2. Held, the newest stretch of
// length δ = 3 ms loses α·δ²/2 (here 0.09 mrad, 10× the baseline's rotation σ in fast motion); the
// extrapolation makes it exact.
TEST(ImuMidpoint, ScanEndingBetweenSamplesIntegratesARampExactly) {
  const double alpha = 20.0, T = 0.103;
  const ImuBuffer b = Ramp(alpha, 0.1);  // newest sample at 100 ms
  std::vector<ImuSegment> seg = b.Segments(0.0, T, nullptr);
  InterpolateAtMidpoints(b, b.samples(0), &seg);
  imu::PreintegratedImu pim(Vec6::Zero(), imu::ImuNoise{1e-3, 1e-3, 0.0});
  for (const ImuSegment& s : seg) pim.Integrate(s.accel, s.gyro, s.dt);
  EXPECT_NEAR(so3::Log(pim.delta_rotation()).z(), 0.5 * alpha * T * T, 1e-12);
  // The held value at 100 ms over [100, 103] ms would be short by α·δ²/2 = 9e-5 rad.
  const double held = 0.5 * alpha * 0.1 * 0.1 + alpha * 0.1 * 0.003;
  EXPECT_GT(0.5 * alpha * T * T - held, 8.9e-5);
}

// Constant angular acceleration α about z: the angle over [0, T] is αT²/2. At the midpoints it
// comes out exact; held, it is short by α·T·Δt/2 (here 1 mrad, 0.06°: the baseline's error).
TEST(ImuMidpoint, PreintegratedRotationOfARampIsExact) {
  const double alpha = 20.0, T = 0.1;
  const ImuBuffer b = Ramp(alpha, T + 0.01);
  const auto angle = [&](bool midpoint) {
    std::vector<ImuSegment> seg = b.Segments(0.0, T, nullptr);
    if (midpoint) InterpolateAtMidpoints(b, b.samples(0), &seg);
    imu::PreintegratedImu pim(Vec6::Zero(), imu::ImuNoise{1e-3, 1e-3, 0.0});
    for (const ImuSegment& s : seg) pim.Integrate(s.accel, s.gyro, s.dt);
    return so3::Log(pim.delta_rotation()).z();
  };
  EXPECT_NEAR(angle(true), 0.5 * alpha * T * T, 1e-12);
  EXPECT_NEAR(angle(false), 0.5 * alpha * T * T - 0.5 * alpha * T * 0.005, 1e-9);
}

}  // namespace
}  // namespace ctlio::lio
