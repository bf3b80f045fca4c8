// Point-cloud files: round trips through PCD/PLY/.bin, the real Newer College sweep files of
// ../shared/data, and every bad input of the bad-input table of docs/user-guide/bad-input.md that
// concerns a single cloud.
#include "ctlio/io/point_cloud_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "common/test_paths.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path TempDir(const std::string& name) { return testing::FreshTempDir("io_test_" + name); }

PointCloud RandomCloud(size_t n, int64_t stamp) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-40.0, 40.0);
  PointCloud c;
  c.stamp_ns = stamp;
  for (size_t i = 0; i < n; ++i) {
    c.points.emplace_back(u(rng), u(rng), u(rng));
    c.times_ns.push_back(stamp + int64_t(i) * 55555);
    c.ring.push_back(uint16_t(i % 128));
    c.intensity.push_back(float(i % 100));
  }
  return c;
}

// Expect `f` to throw std::runtime_error whose message contains every string of `parts`.
using ::ctlio::testing::ExpectError;

TEST(PointCloudIo, PcdRoundTripKeepsOusterFieldsAndTimes) {
  const fs::path d = TempDir("pcd");
  const int64_t stamp = 1583836591LL * 1000000000LL + 182590000LL;
  const PointCloud c = RandomCloud(1000, stamp);
  const std::string path = (d / "cloud_1583836591_182590000.pcd").string();
  WritePcd(path, c);
  const PointCloud r = ReadPcd(path, {stamp, true});
  ASSERT_EQ(r.size(), c.size());
  ASSERT_TRUE(r.has_times());
  for (size_t i = 0; i < c.size(); ++i) {
    EXPECT_LT((r.points[i] - c.points[i]).norm(), 1e-5);  // float32 storage
    EXPECT_EQ(r.times_ns[i], c.times_ns[i]);              // exact: uint32 ns offsets
    EXPECT_EQ(r.ring[i], c.ring[i]);
  }
  EXPECT_NEAR(r.RelativeTime(999), 999 * 55555e-9, 1e-12);
}

TEST(PointCloudIo, PlyAndKittiBinRoundTrip) {
  const fs::path d = TempDir("plybin");
  const PointCloud c = RandomCloud(500, 123456789);
  WritePly((d / "a.ply").string(), c);
  const PointCloud p = ReadPly((d / "a.ply").string(), {123456789, true});
  ASSERT_EQ(p.size(), c.size());
  EXPECT_EQ(p.times_ns.back(), c.times_ns.back());
  EXPECT_LT((p.points[17] - c.points[17]).norm(), 1e-5);

  WriteKittiBin((d / "a.bin").string(), c, (d / "a_times.bin").string());
  const PointCloud b =
      ReadKittiBin((d / "a.bin").string(), 4, (d / "a_times.bin").string(), 123456789);
  ASSERT_EQ(b.size(), c.size());
  EXPECT_LT((b.points[499] - c.points[499]).norm(), 1e-5);
  // float32 seconds: ~28 ms offsets are kept to well under a microsecond.
  EXPECT_NEAR(double(b.times_ns[499] - c.times_ns[499]), 0.0, 1e3);
  // Dispatch on the extension.
  EXPECT_EQ(ReadPointCloud((d / "a.ply").string()).size(), 500u);
}

TEST(PointCloudIo, RealNewerCollegeSweepWithTimes) {
  const fs::path d = fs::path(ctlio::testing::SharedDataDir()) / "gtsam_points_lidar_samples" /
                     "newer_college_2020_06";
  if (!fs::exists(d)) GTEST_SKIP() << "shared data folder absent: " << d;
  const PointCloud c =
      ReadKittiBin((d / "raw_00.bin").string(), 3, (d / "times_00.bin").string(), 1000);
  EXPECT_EQ(c.size(), 25109u);  // SOURCE.md
  int64_t lo = c.times_ns.front(), hi = lo;
  for (int64_t t : c.times_ns) lo = std::min(lo, t), hi = std::max(hi, t);
  EXPECT_GE(lo, 1000);
  EXPECT_LE(hi, 1000 + 101'000'000);  // 0 … 0.1001 s
  EXPECT_GT(hi - lo, 90'000'000);
}

TEST(PointCloudIo, BadInputsGiveClearErrors) {
  const fs::path d = TempDir("bad");
  ExpectError([&] { ReadPcd((d / "missing.pcd").string()); }, {"missing.pcd", "not found"});
  // A PCD without a time field: named file and the FIELDS line.
  const std::string no_t = (d / "no_t.pcd").string();
  {
    std::ofstream f(no_t);
    f << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
         "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n";
  }
  EXPECT_EQ(ReadPcd(no_t).size(), 2u);  // fine when times are not required
  ExpectError([&] { ReadPcd(no_t, {0, true}); }, {"no_t.pcd", "line 3", "time field"});
  // Garbage instead of a PCD.
  const std::string junk = (d / "junk.pcd").string();
  { std::ofstream(junk) << "this is not a point cloud\n"; }
  ExpectError([&] { ReadPcd(junk); }, {"junk.pcd"});
  // A truncated .bin and a time file of the wrong length.
  const std::string bin = (d / "t.bin").string();
  { std::ofstream(bin, std::ios::binary) << "0123456789"; }
  ExpectError([&] { ReadKittiBin(bin, 4); }, {"t.bin", "multiple of 16"});
  const PointCloud c = RandomCloud(10, 0);
  WriteKittiBin(bin, c);
  const std::string times = (d / "t_times.bin").string();
  { std::ofstream(times, std::ios::binary) << "01234567"; }
  ExpectError([&] { ReadKittiBin(bin, 4, times); }, {"t_times.bin", "2 times for 10 points"});
  ExpectError([&] { ReadPointCloud((d / "x.xyz").string()); }, {"x.xyz", "extension"});
}

}  // namespace
}  // namespace ctlio::io
