// The IMU-as-input baseline's integration signal (SPEC §3): an IMU sample is the rate and the
// specific force AT its stamp, so holding it over the following period (ImuBuffer::Segments, the
// zero-order hold) integrates the signal half a period late. Over one preintegration interval
// [t_a, t_b] the rotation is then off by ≈ (ω(t_b) − ω(t_a))·Δt_imu/2 (≈ 0.1° at 200 Hz in the
// simulator's medium motion), an error that no noise density in the preintegrated covariance
// describes and that the lidar cannot remove: the baseline's rotation NEES was in the hundreds.
// The midpoint value (the stream interpolated linearly at each segment's centre; the trapezoid
// rule between two samples) is exact for a signal linear between samples. Measured on the
// simulator (5 s, tuning indices 100-102): rotation NEES 204 -> 6.6 (medium), 480 -> 20-37
// (fast); a cubic through four samples, alone or at two Gauss points, was worse on fast (39-61).
// What was left on fast motion came from the newest stretch of each interval, from the last
// sample to the scan's end: its next sample has not arrived when the scan is processed, and held
// it lost ω̇·δ²/2 once per scan (δ ≤ Δt, so the error fell as Δt²). It is extrapolated along the
// last two samples: rotation NEES on tuning indices 100-101 (5 s) 30.2 -> 5.6 fast, 5.7 -> 3.7
// medium (docs/experiments/covariance.md).
#pragma once

#include <deque>
#include <vector>

#include "ctlio/solvers/lio/imu_buffer.h"

namespace ctlio::lio {

// Replaces each segment's gyro and accel by the stream `samples` (one IMU's, stamps converted to
// the segments' seconds by `buffer`) interpolated at the segment's midpoint. A segment with no
// sample after its midpoint (the newest stretch, whose next sample has not arrived) takes the
// line through the last two samples at its midpoint if it ends within one sample period of the
// newest sample, else (a gap) keeps its held value. Segments must be in time order.
void InterpolateAtMidpoints(const ImuBuffer& buffer, const std::deque<ImuSample>& samples,
                            std::vector<ImuSegment>* segments);

// Splits every segment into `parts` equal segments (each keeps the segment's values until they
// are interpolated at its own midpoint). parts >= 1; 1 leaves the segments as they are.
void SplitSegments(int parts, std::vector<ImuSegment>* segments);

// As InterpolateAtMidpoints, with the cubic through the four samples around each midpoint (two
// stamped at or before it, two after) where the stream has them, evenly spaced (the longest
// period at most 1.5× the shortest); elsewhere (its first period, the newest stretch, whose next
// sample has not arrived, and around a hole) InterpolateAtMidpoints' value. The
// line's mean over a sample period Δt is off by Δt²/12·f̈ (the trapezoid rule's error); the
// cubic's by O(Δt⁴). In the simulator's fast motion at 200 Hz (f̈ up to ~7·10⁴ m/s⁴) that is
// up to 0.15 m/s² of specific force, which with the rotation's coupling inside a period biased
// the baseline's lever arm (imu.input_interpolation in odometry_config.h).
void InterpolateCubicAtMidpoints(const ImuBuffer& buffer, const std::deque<ImuSample>& samples,
                                 std::vector<ImuSegment>* segments);

}  // namespace ctlio::lio
