// Two data sources hand the odometry the same input: every scan's interval, points and per-point
// times, its IMU samples (time, gyro, accelerometer) and the ground truth, to the bit (the bag
// layouts of issue 41 against each other and against the ctlio folder). Returns the scan count.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>

#include "ctlio/io/dataset.h"

namespace ctlio::testing {

inline size_t ExpectSameFrames(io::DataSource& expected, io::DataSource& read) {
  io::ScanFrame a, b;
  size_t n = 0;
  while (expected.Next(&a)) {
    EXPECT_TRUE(read.Next(&b)) << "scan " << n;
    if (::testing::Test::HasFailure()) return n;
    EXPECT_EQ(a.start_ns, b.start_ns);
    EXPECT_EQ(a.end_ns, b.end_ns);
    EXPECT_EQ(a.cloud.points, b.cloud.points) << "scan " << n;
    EXPECT_EQ(a.cloud.times_ns, b.cloud.times_ns) << "scan " << n;
    EXPECT_EQ(a.imu.size(), b.imu.size()) << "scan " << n;
    for (size_t i = 0; i < std::min(a.imu.size(), b.imu.size()); ++i) {
      EXPECT_EQ(a.imu[i].t_ns, b.imu[i].t_ns);
      EXPECT_EQ(a.imu[i].gyro, b.imu[i].gyro);
      EXPECT_EQ(a.imu[i].accel, b.imu[i].accel);
    }
    ++n;
  }
  EXPECT_FALSE(read.Next(&b));
  const auto gt_a = expected.GroundTruth(), gt_b = read.GroundTruth();
  EXPECT_EQ(gt_a.has_value(), gt_b.has_value());
  if (gt_a && gt_b) {
    EXPECT_EQ(gt_a->size(), gt_b->size());
    for (size_t i = 0; i < std::min(gt_a->size(), gt_b->size()); ++i) {
      EXPECT_EQ((*gt_a)[i].t_ns, (*gt_b)[i].t_ns);
      EXPECT_LT(((*gt_a)[i].pose.Matrix() - (*gt_b)[i].pose.Matrix()).norm(), 1e-12);
    }
  }
  return n;
}

}  // namespace ctlio::testing
