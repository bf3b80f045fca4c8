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

TEST(ImuMidpoint, NewestStretchWithoutNextSampleKeepsTheHeldValue) {
  const ImuBuffer b = Ramp(2.0, 0.01);  // samples at 0, 5, 10 ms
  std::vector<ImuSegment> seg = b.Segments(0.005, 0.013, nullptr);
  ASSERT_EQ(seg.size(), 2u);
  InterpolateAtMidpoints(b, b.samples(0), &seg);
  EXPECT_NEAR(seg[0].gyro.z(), 2.0 * 0.0075, 1e-12);
  EXPECT_DOUBLE_EQ(seg[1].gyro.z(), 2.0 * 0.01);  // sample at 10 ms held: nothing after it
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
