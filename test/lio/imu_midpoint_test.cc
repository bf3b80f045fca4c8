// The baseline's integration signal (imu_midpoint.h): instantaneous samples integrated at the
// segments' midpoints. A linearly varying rate integrates exactly; the zero-order hold lags by
// half a period, the error that made the baseline's rotation NEES hundreds.
#include "ctlio/solvers/lio/imu_midpoint.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

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

// Samples every `period` over [0, t_end] of gyro ω(t) and accel f(t), `skip` (if any) left out.
ImuBuffer Sampled(const std::function<Vec3(double)>& gyro, const std::function<Vec3(double)>& accel,
                  double period, double t_end, int skip = -1) {
  ImuBuffer b;
  b.SetOrigin(kOrigin);
  for (int k = 0; period * k <= t_end + 1e-12; ++k) {
    if (k == skip) continue;
    ImuSample s;
    const double t = period * k;
    s.t_ns = kOrigin + std::llround(t * 1e9);
    s.gyro = gyro(t);
    s.accel = accel(t);
    b.AddImu(s);
  }
  return b;
}

TEST(ImuMidpoint, SplitSegmentsKeepsTheSpanInEqualParts) {
  const ImuBuffer b = Ramp(2.0, 0.05);
  std::vector<ImuSegment> seg = b.Segments(0.0025, 0.0125, nullptr);
  ASSERT_EQ(seg.size(), 3u);
  SplitSegments(4, &seg);
  ASSERT_EQ(seg.size(), 12u);
  EXPECT_DOUBLE_EQ(seg.front().t_begin, 0.0025);
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(seg[i].dt, 0.000625, 1e-15);  // [2.5, 5] ms / 4
  for (size_t i = 4; i < 8; ++i) EXPECT_NEAR(seg[i].dt, 0.00125, 1e-15);   // [5, 10] ms / 4
  for (size_t i = 1; i < seg.size(); ++i) {
    EXPECT_NEAR(seg[i].t_begin, seg[i - 1].t_begin + seg[i - 1].dt, 1e-15);
  }
  EXPECT_NEAR(seg.back().t_begin + seg.back().dt, 0.0125, 1e-15);
  std::vector<ImuSegment> same = b.Segments(0.0025, 0.0125, nullptr);
  SplitSegments(1, &same);
  EXPECT_EQ(same.size(), 3u);
}

// A cubic signal is read exactly between samples by the cubic through the four around each
// midpoint; the line misses it by the curvature between its two samples.
TEST(ImuMidpoint, CubicReadsACubicSignalExactlyWhereTheLineDoesNot) {
  const auto cubic = [](double t) { return Vec3(1e4 * t * t * t, -3e3 * t * t, 2.0 * t); };
  const ImuBuffer b = Sampled(cubic, cubic, 0.005, 0.06);
  std::vector<ImuSegment> seg = b.Segments(0.01, 0.04, nullptr);
  SplitSegments(4, &seg);
  std::vector<ImuSegment> line = seg;
  InterpolateCubicAtMidpoints(b, b.samples(0), &seg);
  InterpolateAtMidpoints(b, b.samples(0), &line);
  double worst_line = 0.0;
  for (size_t i = 0; i < seg.size(); ++i) {
    const Vec3 truth = cubic(seg[i].t_begin + 0.5 * seg[i].dt);
    EXPECT_NEAR((seg[i].gyro - truth).norm(), 0.0, 1e-10) << i;
    EXPECT_NEAR((seg[i].accel - truth).norm(), 0.0, 1e-10) << i;
    worst_line = std::max(worst_line, (line[i].gyro - truth).norm());
  }
  EXPECT_GT(worst_line, 1e-3);  // the line: ~(Δt/2)²·|ω''|/2 between samples
}

// Around a lost sample the four samples are unevenly spaced: the line, as without the cubic.
TEST(ImuMidpoint, CubicFallsBackToTheLineAroundAHole) {
  const auto cubic = [](double t) { return Vec3(1e4 * t * t * t, 0, 0); };
  const ImuBuffer b = Sampled(cubic, cubic, 0.005, 0.06, /*skip=*/6);  // no sample at 30 ms
  std::vector<ImuSegment> seg = b.Segments(0.01, 0.05, nullptr);
  std::vector<ImuSegment> line = seg;
  InterpolateCubicAtMidpoints(b, b.samples(0), &seg);
  InterpolateAtMidpoints(b, b.samples(0), &line);
  int fallbacks = 0;
  for (size_t i = 0; i < seg.size(); ++i) {
    const double t_mid = seg[i].t_begin + 0.5 * seg[i].dt;
    const bool near_hole = t_mid >= 0.02 && t_mid < 0.04;  // four samples span the hole
    if (near_hole) {
      EXPECT_EQ(seg[i].gyro, line[i].gyro) << i;
      ++fallbacks;
    } else {
      EXPECT_NEAR(seg[i].gyro.x(), cubic(t_mid).x(), 1e-10) << i;
    }
  }
  EXPECT_GT(fallbacks, 0);
}

// The cause of the baseline's fast lever-arm bias, on one preintegration interval of the
// simulator's fast motion (rates 1-2 rad/s and specific forces of tens of m/s² at 4-8 Hz, IMU at
// 200 Hz): the line between samples and one step per period leave errors in Δv and Δp that the
// lever arm absorbed (docs/experiments/calibration.md); the cubic at 4 substeps per period brings
// them down by more than 10×. Reference: the exact signal at 0.05 ms steps.
TEST(ImuMidpoint, CubicWithSubstepsPreintegratesFastMotionTenTimesCloser) {
  constexpr double kTwoPi = 2.0 * M_PI;
  const auto gyro = [&](double t) {
    return Vec3(1.5 * std::sin(kTwoPi * 6.0 * t), 2.0 * std::sin(kTwoPi * 4.5 * t + 1.0),
                1.2 * std::sin(kTwoPi * 7.5 * t + 2.0));
  };
  const auto accel = [&](double t) {
    return Vec3(25.0 * std::sin(kTwoPi * 5.0 * t + 0.5), 20.0 * std::sin(kTwoPi * 7.0 * t),
                9.81 + 15.0 * std::sin(kTwoPi * 8.0 * t + 1.5));
  };
  const ImuBuffer b = Sampled(gyro, accel, 0.005, 0.5);
  const double t_a = 0.2013, t_b = 0.3013;  // a scan interval, between samples
  const auto preintegrate = [&](const std::vector<ImuSegment>& seg) {
    imu::PreintegratedImu pim(Vec6::Zero(), imu::ImuNoise{1e-3, 1e-3, 0.0});
    for (const ImuSegment& s : seg) pim.Integrate(s.accel, s.gyro, s.dt);
    return pim;
  };
  std::vector<ImuSegment> fine;
  for (double t = t_a; t < t_b - 1e-12; t += 5e-5) {
    ImuSegment s;
    s.t_begin = t;
    s.dt = std::min(5e-5, t_b - t);
    s.gyro = gyro(t + 0.5 * s.dt);
    s.accel = accel(t + 0.5 * s.dt);
    fine.push_back(s);
  }
  const imu::PreintegratedImu truth = preintegrate(fine);
  const auto errors = [&](bool cubic, int substeps) {
    std::vector<ImuSegment> seg = b.Segments(t_a, t_b, nullptr);
    SplitSegments(substeps, &seg);
    if (cubic) {
      InterpolateCubicAtMidpoints(b, b.samples(0), &seg);
    } else {
      InterpolateAtMidpoints(b, b.samples(0), &seg);
    }
    const imu::PreintegratedImu pim = preintegrate(seg);
    return Vec3(so3::Log(pim.delta_rotation().transpose() * truth.delta_rotation()).norm(),
                (pim.delta_velocity() - truth.delta_velocity()).norm(),
                (pim.delta_position() - truth.delta_position()).norm());
  };
  const Vec3 line = errors(false, 1), better = errors(true, 4);
  RecordProperty(
      "line_rotation_velocity_position",
      std::to_string(line[0]) + " " + std::to_string(line[1]) + " " + std::to_string(line[2]));
  RecordProperty("cubic4_rotation_velocity_position", std::to_string(better[0]) + " " +
                                                          std::to_string(better[1]) + " " +
                                                          std::to_string(better[2]));
  EXPECT_LT(better[1], 0.1 * line[1]);
  EXPECT_LT(better[2], 0.1 * line[2]);
  EXPECT_LT(better[0], line[0]);
}

}  // namespace
}  // namespace ctlio::lio
