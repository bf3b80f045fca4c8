// A small valid PointCloud2 for the reader tests: `n` points x y z float32 + t uint32 (16 B a
// point), t = 0, 1, … µs after the stamp, points 1 m apart along x.
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include <cstdint>

#include "ctlio/io/dataset.h"
#include "ctlio/io/pointcloud2.h"

namespace ctlio::testing {

inline sensor_msgs::PointCloud2 SmallPointCloud2(int64_t stamp_ns, int n = 10) {
  io::PointCloud c;
  c.stamp_ns = stamp_ns;
  for (int i = 0; i < n; ++i) {
    c.points.emplace_back(1.0 + i, 2.0, 0.5);
    c.times_ns.push_back(stamp_ns + i * 1000);
  }
  io::TimeConvention t;
  t.field = "t";
  return io::EncodePointCloud2(c,
                               {{"x", io::kFloat32, 0, 1},
                                {"y", io::kFloat32, 4, 1},
                                {"z", io::kFloat32, 8, 1},
                                {"t", io::kUInt32, 12, 1}},
                               16, t, "lidar");
}

}  // namespace ctlio::testing
