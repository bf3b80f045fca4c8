// What every dense-trajectory test checks of a run (RunOptions::trajectory_rate_hz): the poses
// come at the sampling rate and pass exactly through the scan poses.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>

#include "lio/run_odometry.h"

namespace ctlio::testing {

// run.dense has strictly increasing times at most `max_step_ns` apart, and holds every pose of
// run.trajectory at its time, equal to 1e-12 m.
inline void ExpectDenseThroughTheScanPoses(const lioapp::RunSummary& run, int64_t max_step_ns) {
  const auto& dense = run.dense;
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

}  // namespace ctlio::testing
