// What every dense-trajectory test checks of a run (RunOptions::trajectory_rate_hz): the live
// poses come at the sampling rate and pass exactly through the scan poses; the final estimates'
// trajectory has no jump at the scan boundaries.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "lio/run_odometry.h"

namespace ctlio::testing {

// run.dense_live (the live, causal trajectory) has strictly increasing times at most
// `max_step_ns` apart, and holds every pose of run.trajectory at its time, equal to 1e-12 m.
inline void ExpectDenseThroughTheScanPoses(const lioapp::RunSummary& run, int64_t max_step_ns) {
  const auto& dense = run.dense_live;
  for (size_t i = 1; i < dense.size(); ++i) {
    ASSERT_GT(dense[i].t_ns, dense[i - 1].t_ns);
    EXPECT_LE(dense[i].t_ns - dense[i - 1].t_ns, max_step_ns);
  }
  size_t j = 0;
  for (const io::StampedPose& p : run.trajectory) {
    while (j < dense.size() && dense[j].t_ns < p.t_ns) ++j;
    ASSERT_LT(j, dense.size());
    ASSERT_EQ(dense[j].t_ns, p.t_ns);
    EXPECT_LT((dense[j].pose.translation() - p.pose.translation()).norm(), 1e-12);
  }
}

// The continuity criterion of a dense trajectory at the boundaries (times that must be in
// `dense`, each with two poses either side): the larger of the two position steps to the
// boundary's neighbours over the larger of the next steps out; the largest over the boundaries
// (a jump of a stitched trajectory makes it several; a continuous one stays near 1).
inline double MaxBoundaryStepRatio(const std::vector<io::StampedPose>& dense,
                                   const std::vector<int64_t>& boundaries) {
  const auto step = [&](size_t i) {  // from pose i to i + 1
    return (dense[i + 1].pose.translation() - dense[i].pose.translation()).norm();
  };
  double worst = 0.0;
  for (const int64_t t : boundaries) {
    const auto it =
        std::lower_bound(dense.begin(), dense.end(), t,
                         [](const io::StampedPose& p, int64_t x) { return p.t_ns < x; });
    EXPECT_TRUE(it != dense.end() && it->t_ns == t) << "boundary " << t << " not in the trajectory";
    if (it == dense.end() || it->t_ns != t) continue;
    const size_t i = static_cast<size_t>(it - dense.begin());
    EXPECT_TRUE(i >= 2 && i + 2 < dense.size()) << "boundary " << t << " at the end";
    if (i < 2 || i + 2 >= dense.size()) continue;
    const double at = std::max(step(i - 1), step(i));
    const double next = std::max(step(i - 2), step(i + 1));
    worst = std::max(worst, at / next);
  }
  return worst;
}

}  // namespace ctlio::testing
