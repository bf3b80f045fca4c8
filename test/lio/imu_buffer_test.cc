// ImuBuffer (SPEC §3, §4): the odometry's single entry point for IMU samples — order check, the
// input gates (finiteness, range, constant output), duplicate recovery — and the zero-order-hold
// segments, gaps, samples in an interval and trimming the pipelines read.
#include "ctlio/solvers/lio/imu_buffer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace ctlio::lio {
namespace {

constexpr int64_t kOrigin = 1'000'000'000;  // ns

ImuSample Sample(double t, double value) {
  ImuSample s;
  s.t_ns = kOrigin + static_cast<int64_t>(std::llround(t * 1e9));
  s.gyro = Vec3::Constant(value);
  s.accel = Vec3::Constant(-value);
  return s;
}

ImuBuffer Buffer(const std::vector<double>& times) {
  ImuBuffer b;
  b.SetOrigin(kOrigin);
  for (size_t i = 0; i < times.size(); ++i) b.AddImu(Sample(times[i], static_cast<double>(i)));
  return b;
}

TEST(ImuBuffer, ThrowsOnBackwardsRejectsNonFiniteDropsDuplicates) {
  ImuBuffer b = Buffer({0.00, 0.01});
  EXPECT_THROW(b.AddImu(Sample(0.005, 9)), std::invalid_argument);
  ImuSample bad = Sample(0.02, 0);
  bad.accel.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(b.AddImu(bad));  // refused: not stored, counted, reported once
  bad.accel.x() = std::numeric_limits<double>::infinity();
  bad.t_ns += 1'000'000;
  EXPECT_FALSE(b.AddImu(bad));
  EXPECT_EQ(b.rejected(), 2u);
  const ImuBuffer::Rejections r = b.TakeRejections();
  EXPECT_EQ(r.count, 2u);
  EXPECT_NE(r.first.find("not finite"), std::string::npos) << r.first;
  EXPECT_EQ(b.TakeRejections().count, 0u);  // taken
  EXPECT_TRUE(b.AddImu(Sample(0.01, 7)));   // same stamp: the first sample is kept
  EXPECT_EQ(b.duplicates(), 1u);
  ASSERT_EQ(b.samples().size(), 2u);
  EXPECT_EQ(b.samples().back().gyro.x(), 1.0);
}

TEST(ImuBuffer, RangeGateAndConstantOutput) {
  InputCheckOptions checks;
  checks.max_gyro = 2.0;
  checks.max_accel = 20.0;
  ImuBuffer b(checks);
  b.SetOrigin(kOrigin);
  EXPECT_TRUE(b.AddImu(Sample(0.00, 1.0)));   // |ω| = √3 rad/s
  EXPECT_FALSE(b.AddImu(Sample(0.01, 2.0)));  // |ω| = 2√3 rad/s > 2
  EXPECT_NE(b.TakeRejections().first.find("input.max_gyro"), std::string::npos);
  ImuSample s = Sample(0.02, 1.0);
  s.accel = Vec3(0, 0, 25);
  EXPECT_FALSE(b.AddImu(s));
  EXPECT_NE(b.TakeRejections().first.find("input.max_accel"), std::string::npos);
  // Accepted samples identical to the first: the constant run grows with their time span.
  EXPECT_TRUE(b.AddImu(Sample(0.03, 1.0)));
  EXPECT_TRUE(b.AddImu(Sample(0.05, 1.0)));
  EXPECT_NEAR(b.ConstantSeconds(), 0.05, 1e-12);
  EXPECT_TRUE(b.AddImu(Sample(0.06, 1.0 + 1e-9)));  // any change restarts it
  EXPECT_EQ(b.ConstantSeconds(), 0.0);
  EXPECT_EQ(b.samples().size(), 4u);
}

TEST(ImuBuffer, SegmentsHoldEachSampleUntilTheNext) {
  const ImuBuffer b = Buffer({0.00, 0.01, 0.02, 0.03});
  double gap = -1.0;
  const std::vector<ImuSegment> segments = b.Segments(0.005, 0.025, &gap);
  ASSERT_EQ(segments.size(), 3u);
  EXPECT_NEAR(segments[0].t_begin, 0.005, 1e-12);
  EXPECT_NEAR(segments[0].dt, 0.005, 1e-12);
  EXPECT_EQ(segments[0].gyro.x(), 0.0);  // the sample in force at t_a
  EXPECT_EQ(segments[1].gyro.x(), 1.0);
  EXPECT_EQ(segments[2].accel.x(), -2.0);
  double total = 0.0;
  for (const ImuSegment& s : segments) total += s.dt;
  EXPECT_NEAR(total, 0.02, 1e-12);
  EXPECT_NEAR(gap, 0.01, 1e-12);
}

TEST(ImuBuffer, GapInsideAndAtTheEndOfTheStream) {
  const ImuBuffer b = Buffer({0.00, 0.01, 0.09, 0.10});
  EXPECT_NEAR(b.MaxGap(0.0, 0.1), 0.08, 1e-12);
  // Past the last sample the signal is held, and the hole up to t_b is the gap.
  const ImuBuffer end = Buffer({0.00, 0.01});
  double gap = 0.0;
  const std::vector<ImuSegment> held = end.Segments(0.0, 0.2, &gap);
  ASSERT_FALSE(held.empty());
  EXPECT_NEAR(held.back().t_begin + held.back().dt, 0.2, 1e-12);
  EXPECT_NEAR(gap, 0.19, 1e-12);
  EXPECT_NEAR(ImuBuffer().MaxGap(0.0, 0.3), 0.3, 1e-12);  // no IMU at all
}

TEST(ImuBuffer, SamplesInHalfOpenIntervalAndTrim) {
  ImuBuffer b = Buffer({0.00, 0.01, 0.02, 0.03, 0.04});
  // (t_a, t_b] with both ends on samples 1 and 3.
  const std::vector<ImuSample> in =
      b.Samples(b.Seconds(b.samples()[1].t_ns), b.Seconds(b.samples()[3].t_ns));
  ASSERT_EQ(in.size(), 2u);
  EXPECT_EQ(in.front().gyro.x(), 2.0);
  EXPECT_EQ(in.back().gyro.x(), 3.0);
  b.Trim(0.025);  // keeps the sample in force at 0.025
  ASSERT_EQ(b.samples().size(), 3u);
  EXPECT_EQ(b.samples().front().gyro.x(), 2.0);
}

}  // namespace
}  // namespace ctlio::lio
