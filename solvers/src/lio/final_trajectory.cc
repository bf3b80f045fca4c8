#include "ctlio/solvers/lio/final_trajectory.h"

#include <algorithm>
#include <cmath>

namespace ctlio::lio {

void FinalTrajectory::MarkFailed(double t_begin, double t_end) {
  if (rate_hz_ > 0.0) {
    failed_.emplace_back(t_begin, t_end);
  }
}

bool FinalTrajectory::Failed(double t) const {
  return std::any_of(failed_.begin(), failed_.end(), [t](const std::pair<double, double>& f) {
    return t > f.first && t <= f.second;
  });
}

void FinalTrajectory::SegmentTimes(std::optional<double> from, double t_b, int64_t origin_ns,
                                   std::vector<int64_t>* ns, std::vector<double>* t) const {
  const int64_t end = origin_ns + std::llround(t_b * 1e9);
  if (from) {
    const int64_t begin = origin_ns + std::llround(*from * 1e9);
    const int64_t period = std::max<int64_t>(1, std::llround(1e9 / rate_hz_));
    for (int64_t x = (begin / period + 1) * period; x < end; x += period) {
      ns->push_back(x);
      t->push_back(1e-9 * static_cast<double>(x - origin_ns));
    }
  }
  // The state's own time exactly (not the rounded ns): its final pose, not an interpolation.
  ns->push_back(end);
  t->push_back(t_b);
}

void FinalTrajectory::SealOldest(Estimator* estimator, int64_t origin_ns) {
  if (rate_hz_ <= 0.0) {
    return;
  }
  const double t_k = estimator->StateTimes().front();
  const bool failed = Failed(t_k);
  std::vector<int64_t> ns;
  std::vector<double> t;
  if (!failed) {
    SegmentTimes(sealed_, t_k, origin_ns, &ns, &t);
  }
  const std::vector<SE3> poses = estimator->SealOldest(t);
  for (size_t i = 0; i < ns.size(); ++i) {
    samples_.emplace_back(ns[i], poses[i]);
  }
  sealed_.reset();
  if (!failed) {
    sealed_ = t_k;
  }
  while (!failed_.empty() && failed_.front().second <= t_k) {
    failed_.pop_front();
  }
}

FinalTrajectory::Samples FinalTrajectory::Take() {
  Samples out;
  out.swap(samples_);
  return out;
}

FinalTrajectory::Samples FinalTrajectory::Tail(const Estimator& estimator,
                                               int64_t origin_ns) const {
  Samples out;
  if (rate_hz_ <= 0.0 || estimator.num_states() == 0) {
    return out;
  }
  std::vector<int64_t> ns;
  std::vector<double> t;
  std::optional<double> from = sealed_;
  for (const double t_k : estimator.StateTimes()) {
    if (Failed(t_k)) {
      from.reset();
      continue;
    }
    SegmentTimes(from, t_k, origin_ns, &ns, &t);
    from = t_k;
  }
  const std::vector<SE3> poses = estimator.UnsealedPoses(t);
  for (size_t i = 0; i < ns.size(); ++i) {
    out.emplace_back(ns[i], poses[i]);
  }
  return out;
}

}  // namespace ctlio::lio
