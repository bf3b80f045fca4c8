// The dense trajectory from the final estimates: T_mr sampled on a time grid between the states,
// written segment by segment as the window lets go of the states (SPEC §5). A state's estimate
// is final once the window marginalises it; the segment between two consecutive states is
// written when the later one leaves, both ends at their final values, so the trajectory is
// continuous at every state (a scan boundary), unlike one stitched from each scan's live window,
// where every interval ends at the estimate of that moment and the next begins at a revised one.
//
// Times: the multiples of the period in absolute ns strictly between the two states, and each
// state's own time (its final pose, exactly). The segments still in the window at the end of the
// run come from Tail: their current estimates are final once no scan follows.
//
// Failed scans (ScanStatus::kFailed): no segment touches a state added for a failed scan. The
// trajectory is written in pieces then: one ends at the last state before the failure, the next
// starts at the first state after it (the gap in time is the break).
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include "ctlio/solvers/lio/estimator.h"

namespace ctlio::lio {

class FinalTrajectory {
 public:
  using Samples = std::vector<std::pair<int64_t, SE3>>;  // (t [ns], T_mr), time order

  // Sampled every 1/rate_hz s; 0 (the default) writes nothing.
  void set_rate(double rate_hz) { rate_hz_ = rate_hz; }
  double rate() const { return rate_hz_; }
  // The states with times in (t_begin, t_end] (odometry seconds) belong to a failed scan.
  void MarkFailed(double t_begin, double t_end);
  // Right before the window marginalises the estimator's oldest state: the segment from the state
  // sealed before it to it, into the samples (`origin_ns`: the odometry's time origin).
  void SealOldest(Estimator* estimator, int64_t origin_ns);
  // The samples sealed since the previous call (moved out: a long run keeps nothing twice).
  Samples Take();
  // The segments from the state sealed last to the newest, from the current estimates.
  Samples Tail(const Estimator& estimator, int64_t origin_ns) const;

 private:
  bool Failed(double t) const;
  // The sample times of the segment ending at state time t_b (ns and odometry seconds): the grid
  // in (t_a, t_b) when the segment is written (`from` set), and t_b.
  void SegmentTimes(std::optional<double> from, double t_b, int64_t origin_ns,
                    std::vector<int64_t>* ns, std::vector<double>* t) const;

  double rate_hz_ = 0.0;
  std::optional<double> sealed_;  // time of the state sealed last, if it was not failed
  std::deque<std::pair<double, double>> failed_;
  Samples samples_;
};

}  // namespace ctlio::lio
