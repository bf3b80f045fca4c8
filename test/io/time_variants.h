// The per-point time layouts of the common lidar drivers (point_fields.h), as test fixtures: each
// variant is a field list plus the convention its values are written with, and the detection
// result the reader must arrive at on its own.
#pragma once

#include <string>
#include <vector>

#include "ctlio/io/point_fields.h"

namespace ctlio::io::fixtures {

struct TimeVariant {
  std::string driver;  // expected TimeConvention::driver
  std::vector<PointField> fields;
  uint32_t point_step;
  TimeConvention written;  // how the values are stored
  double tolerance_ns;     // storage resolution of the time field
};

inline std::vector<TimeVariant> TimeVariants() {
  using R = TimeReference;
  auto conv = [](const char* f, TimeUnit u, R r, StampAt s) {
    TimeConvention c;
    c.field = f;
    c.unit = u;
    c.reference = r;
    c.stamp_at = s;
    return c;
  };
  uint32_t ouster_step = 0;
  const auto ouster = OusterFields(&ouster_step);
  const PointField x{"x", kFloat32, 0, 1}, y{"y", kFloat32, 4, 1}, z{"z", kFloat32, 8, 1};
  return {
      {"Ouster", ouster, ouster_step,
       conv("t", TimeUnit::kNanoseconds, R::kRelativeToStamp, StampAt::kScanStart), 0.0},
      {"Livox CustomPoint",
       {x, y, z, {"reflectivity", kUInt8, 12, 1}, {"offset_time", kUInt32, 13, 1}},
       17,
       conv("offset_time", TimeUnit::kNanoseconds, R::kRelativeToStamp, StampAt::kScanStart),
       0.0},
      // float32 seconds over a 0.1 s sweep: resolution 7.5e-9 s.
      {"Velodyne",
       {x,
        y,
        z,
        {"intensity", kFloat32, 12, 1},
        {"ring", kUInt16, 16, 1},
        {"time", kFloat32, 18, 1}},
       22,
       conv("time", TimeUnit::kSeconds, R::kRelativeToStamp, StampAt::kScanEnd),
       8.0},
      // float64 absolute seconds at ~1.6e9 s: resolution 2.4e-7 s.
      {"Hesai/Robosense",
       {x,
        y,
        z,
        {"intensity", kFloat32, 12, 1},
        {"timestamp", kFloat64, 16, 1},
        {"ring", kUInt16, 24, 1}},
       26,
       conv("timestamp", TimeUnit::kSeconds, R::kAbsolute, StampAt::kScanStart),
       240.0},
      // float64 absolute nanoseconds at ~1.6e18 ns: resolution 256 ns.
      {"Livox driver 2",
       {x,
        y,
        z,
        {"intensity", kFloat32, 12, 1},
        {"tag", kUInt8, 16, 1},
        {"line", kUInt8, 17, 1},
        {"timestamp", kFloat64, 18, 1}},
       26,
       conv("timestamp", TimeUnit::kNanoseconds, R::kAbsolute, StampAt::kScanStart),
       256.0},
  };
}

}  // namespace ctlio::io::fixtures
