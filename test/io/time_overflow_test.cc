// Issue 40: times near the int64 nanosecond range (±9.22e18 ns) in interval arithmetic. A
// tolerance window [stamp − d, end + d] wrapped past INT64_MAX used to be inverted, so every point
// of the scan fell outside it and the whole scan was dropped; a nominal interval past the limit is
// now an error naming the file. ctlio/factors/imu/saturating_ns.h is the one place of that rule.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "common/warning_sink.h"
#include "ctlio/factors/imu/saturating_ns.h"
#include "ctlio/io/kitti.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/solvers/lio/scan_preparation.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
constexpr int64_t kMin = std::numeric_limits<int64_t>::min();

TEST(SaturatingNs, ClampsAtTheInt64LimitsAndIsExactInside) {
  EXPECT_EQ(SaturatingAddNs(kMax - 10, 100), kMax);
  EXPECT_EQ(SaturatingAddNs(kMin + 10, -100), kMin);
  EXPECT_EQ(SaturatingSubNs(kMin + 10, 100), kMin);
  EXPECT_EQ(SaturatingSubNs(kMax - 10, -100), kMax);
  EXPECT_EQ(SaturatingSubNs(kMax, kMin), kMax);  // a span over the whole range
  EXPECT_EQ(SaturatingAddNs(kMax - 100, 100), kMax);
  EXPECT_EQ(SaturatingSubNs(5, 7), -2);
  EXPECT_EQ(CheckedAddNs(kMax - 1, 1, "f"), kMax);
  testing::ExpectError([] { CheckedAddNs(kMax - 1, 2, "scan.bin"); },
                       {"scan.bin: time 9223372036854775806 ns + 2 ns", "int64"});
}

// KITTI scans with per-point times (velodyne_times, float32 s since the stamp) stamped at the
// given seconds of times.txt; `points` per scan over one 0.1 s sweep (0 = an empty scan).
fs::path WriteKitti(const std::string& name, const std::vector<std::string>& stamps, int points) {
  const fs::path dir = testing::FreshTempDir(name);
  fs::create_directories(dir / "velodyne");
  fs::create_directories(dir / "velodyne_times");
  std::ofstream times(dir / "times.txt");
  for (size_t k = 0; k < stamps.size(); ++k) {
    char file[32];
    std::snprintf(file, sizeof(file), "%06zu.bin", k);
    std::ofstream bin(dir / "velodyne" / file, std::ios::binary);
    std::ofstream tb(dir / "velodyne_times" / file, std::ios::binary);
    for (int i = 0; i < points; ++i) {
      const double a = -2 * M_PI * i / points;
      const float v[4] = {float(10 * std::cos(a)), float(10 * std::sin(a)), float(0.1 * (i % 16)),
                          0.5f};
      bin.write(reinterpret_cast<const char*>(v), sizeof(v));
      const float t = float(0.1 * i / points);
      tb.write(reinterpret_cast<const char*>(&t), sizeof(t));
    }
    times << stamps[k] << "\n";
  }
  return dir;
}

// The last scan's stamp + 0.11 s (the reader's window: a period + 10 %) passes INT64_MAX
// (9223372036.854775807 s) while its sweep [stamp, stamp + 0.1 s) does not: every point is kept
// and the interval is the sweep's, not an inverted one.
TEST(TimeOverflow, KittiScansNearInt64MaxKeepTheirPointsAndIntervals) {
  const fs::path dir =
      WriteKitti("overflow_kitti_max", {"9223372036.55", "9223372036.65", "9223372036.75"}, 720);
  testing::WarningSink sink;
  KittiReader r(dir.string());
  ScanFrame f;
  int scans = 0;
  while (r.Next(&f)) {
    ++scans;
    EXPECT_EQ(f.cloud.size(), 720u) << "scan " << f.index;
    EXPECT_LT(f.start_ns, f.end_ns) << "scan " << f.index;
    EXPECT_GT(f.start_ns, 9'223'372'036'500'000'000) << "scan " << f.index;
  }
  EXPECT_EQ(scans, 3);
  EXPECT_FALSE(sink.Has("dropped"));
}

// An empty scan stamped 0.05 s before INT64_MAX gets no nominal 0.1 s interval: an error naming the
// scan file, not an interval wrapped around to 1970 − 292 years.
TEST(TimeOverflow, AnEmptyKittiScanWithoutRoomForItsNominalIntervalIsAnErrorNamingTheFile) {
  const fs::path dir = WriteKitti("overflow_kitti_empty", {"9223372036.80"}, 0);
  testing::WarningSink sink;
  KittiReader r(dir.string());
  ScanFrame f;
  testing::ExpectError([&] { r.Next(&f); }, {"000000.bin", "int64 nanosecond range"});
}

// The odometry's tolerance window [previous end − tol, end + tol] (input.scan_time_tolerance)
// near either limit: no point inside the scan's interval is dropped.
TEST(TimeOverflow, TheOdometryToleranceWindowNearTheLimitsDropsNoPointOfTheScan) {
  for (const int64_t end : {kMax - 1'000'000, kMin + 101'000'000}) {
    lio::LidarScan scan;
    scan.begin_ns = end - 100'000'000;
    scan.end_ns = end;
    for (int i = 0; i <= 100; ++i) {
      scan.points.emplace_back(1.0 * i, 2.0, 3.0);
      scan.times_ns.push_back(scan.begin_ns + int64_t(i) * 1'000'000);
    }
    lio::LidarScan trimmed;
    std::string note;
    const lio::LidarScan& kept =
        lio::DropPointsOutsideInterval(scan, scan.begin_ns, 0.01, &trimmed, &note);
    EXPECT_EQ(kept.points.size(), 101u) << end;
    EXPECT_TRUE(note.empty()) << note;
  }
}

// Newer College (PCD scans named by their stamp, per-point `t` in ns since it): the reader's window
// for the last scan, [stamp − 10 ms, stamp + period + 10 ms], passes INT64_MAX; its points stay.
TEST(TimeOverflow, NewerCollegeScansNearInt64MaxKeepTheirPoints) {
  const fs::path dir = testing::FreshTempDir("overflow_nc");
  const fs::path scans = dir / "raw_format" / "ouster_zip_files" / "ouster_scan";
  fs::create_directories(scans);
  fs::create_directories(dir / "raw_format" / "ouster_imu");
  constexpr int64_t kSec = 9'223'372'036, kPeriod = 100'000'000;
  std::ofstream imu(dir / "raw_format" / "ouster_imu" / "data.csv");
  imu << "counter,sec,nsec,wx,wy,wz,ax,ay,az\n";
  for (int64_t ns = 500'000'000, k = 0; ns <= 850'000'000; ns += 5'000'000, ++k) {
    imu << k << ',' << kSec << ',' << ns << ",0,0,0,0,0,9.81\n";
  }
  imu.close();
  constexpr int kPoints = 360;
  for (int k = 0; k < 3; ++k) {
    const int64_t ns = 550'000'000 + k * kPeriod;  // the last stamp: 0.105 s before INT64_MAX
    std::ofstream out(scans /
                      ("cloud_" + std::to_string(kSec) + "_" + std::to_string(ns) + ".pcd"));
    out << "FIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH " << kPoints
        << "\nHEIGHT 1\nPOINTS " << kPoints << "\nDATA ascii\n";
    for (int i = 0; i < kPoints; ++i) {
      const double a = -2 * M_PI * i / kPoints;
      out << float(10 * std::cos(a)) << ' ' << float(10 * std::sin(a)) << ' '
          << float(0.1 * (i % 16)) << ' ' << int64_t(i) * kPeriod / kPoints << '\n';
    }
  }
  testing::WarningSink sink;
  NewerCollegeReader r(dir.string());
  ScanFrame f;
  int frames = 0;
  while (r.Next(&f)) {
    ++frames;
    EXPECT_EQ(f.cloud.size(), size_t(kPoints)) << "scan " << f.index;
    EXPECT_LT(f.start_ns, f.end_ns) << "scan " << f.index;
  }
  EXPECT_EQ(frames, 3);
  EXPECT_FALSE(sink.Has("dropped"));
}

}  // namespace
}  // namespace ctlio::io
