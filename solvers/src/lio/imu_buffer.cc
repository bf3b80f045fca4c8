#include "ctlio/solvers/lio/imu_buffer.h"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ctlio::lio {

bool ImuBuffer::AddImu(const ImuSample& s) {
  if (s.imu < 0 || s.imu >= kMaxImus) {
    throw std::invalid_argument("LioOdometry::AddImu: IMU index " + std::to_string(s.imu) +
                                " outside [0, " + std::to_string(kMaxImus) + ")");
  }
  if (s.imu >= num_imus()) {
    streams_.resize(s.imu + 1);
    constant_.resize(s.imu + 1);
  }
  std::deque<ImuSample>& stream = streams_[s.imu];
  if (!stream.empty()) {
    if (s.t_ns == stream.back().t_ns) {
      ++duplicates_;  // documented recovery: keep the first of two equal stamps
      return true;
    }
    if (s.t_ns < stream.back().t_ns) {
      throw std::invalid_argument("LioOdometry::AddImu: IMU time goes backwards (" +
                                  std::to_string(s.t_ns) + " ns after " +
                                  std::to_string(stream.back().t_ns) + " ns)");
    }
  }
  if (const auto why = CheckImuRange(s, checks_)) {
    // Documented recovery: the zero-order hold of the previous sample bridges the hole.
    ++rejected_;
    if (pending_.count++ == 0) {
      std::ostringstream m;
      m << "IMU sample at " << std::fixed << std::setprecision(9) << 1e-9 * double(s.t_ns)
        << " s rejected: " << *why;
      pending_.first = m.str();
    }
    return false;
  }
  constant_[s.imu].Add(s);
  stream.push_back(s);
  return true;
}

ImuBuffer::Rejections ImuBuffer::TakeRejections() {
  Rejections r = std::move(pending_);
  pending_ = Rejections();
  return r;
}

double ImuBuffer::ConstantSeconds() const {
  double longest = 0.0;
  for (const ConstantImuDetector& d : constant_) longest = std::max(longest, d.ConstantSeconds());
  return longest;
}

const std::deque<ImuSample>& ImuBuffer::samples(int imu) const {
  static const std::deque<ImuSample> kNone;
  return imu >= 0 && imu < num_imus() ? streams_[imu] : kNone;
}

std::vector<ImuSegment> ImuBuffer::Segments(double t_a, double t_b, double* max_gap,
                                            int imu_index) const {
  const std::deque<ImuSample>& imu = samples(imu_index);
  std::vector<ImuSegment> out;
  double gap = 0.0;
  if (imu.empty() || t_b <= t_a) {
    if (max_gap) *max_gap = imu.empty() ? t_b - t_a : 0.0;
    return out;
  }
  // Index of the last sample at or before t_a (or the first sample).
  size_t i = 0;
  while (i + 1 < imu.size() && Seconds(imu[i + 1].t_ns) <= t_a) ++i;
  double t = t_a;
  double last_sample_time = std::min(Seconds(imu[i].t_ns), t_a);
  const auto hold = [&](double from, double to) {
    ImuSegment seg;
    seg.gyro = imu[i].gyro;
    seg.accel = imu[i].accel;
    seg.t_begin = from;
    seg.dt = to - from;
    out.push_back(seg);
  };
  while (t < t_b) {
    const double t_next = (i + 1 < imu.size()) ? std::min(Seconds(imu[i + 1].t_ns), t_b) : t_b;
    if (t_next > t) hold(t, t_next);
    if (i + 1 < imu.size() && Seconds(imu[i + 1].t_ns) <= t_b) {
      gap = std::max(gap, Seconds(imu[i + 1].t_ns) - last_sample_time);
      last_sample_time = Seconds(imu[i + 1].t_ns);
      ++i;
    }
    t = t_next;
    if (i + 1 >= imu.size()) {
      // No sample after this one: hold it to t_b (an IMU gap at the end of the stream).
      if (t < t_b) hold(t, t_b);
      break;
    }
  }
  gap = std::max(gap, t_b - last_sample_time);
  if (max_gap) *max_gap = gap;
  return out;
}

double ImuBuffer::MaxGap(double t_a, double t_b, int imu) const {
  double gap = 0.0;
  Segments(t_a, t_b, &gap, imu);
  return gap;
}

std::vector<ImuSample> ImuBuffer::Samples(double t_a, double t_b, int imu) const {
  std::vector<ImuSample> out;
  for (const ImuSample& s : samples(imu)) {
    const double t = Seconds(s.t_ns);
    if (t > t_a && t <= t_b) out.push_back(s);
  }
  return out;
}

void ImuBuffer::Trim(double t) {
  for (std::deque<ImuSample>& samples : streams_) {
    while (samples.size() > 1 && Seconds(samples[1].t_ns) <= t) samples.pop_front();
  }
}

}  // namespace ctlio::lio
