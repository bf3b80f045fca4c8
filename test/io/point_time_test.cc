// Issue 40, per-point times: one rule in every reader (point_time_check.h, dataset.h).
//   * times that cannot be a sweep — microseconds where nanoseconds are expected, milliseconds
//     where seconds are, 8/16-bit fields, every point at one instant (at the stamp or mid-scan), a
//     `t` that is really `ring` or `range` — are rescaled with a logged reason or replaced by
//     azimuth times with a warning, in a bag (PointCloud2), a Newer College PCD folder and KITTI;
//   * points timed seconds outside their sweep are dropped and counted in the bag and KITTI
//     readers, as the folder readers did already, so that the scan is not stretched.
#include <glog/logging.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <random>

#include "common/temp_dir.h"
#include "common/warning_sink.h"
#include "ctlio/io/kitti.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/point_time_check.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;

constexpr int64_t kPeriod = 100'000'000;  // 10 Hz
constexpr int64_t kStamp0 = 1'000'000'000;
constexpr int kPoints = 720;

// One clockwise sweep (as a spinning lidar fires): point i at azimuth −2π i/N, offset i·P/N.
std::vector<Vec3> SweepPoints() {
  std::vector<Vec3> p;
  for (int i = 0; i < kPoints; ++i) {
    const double a = -2 * M_PI * i / kPoints;
    p.emplace_back(10 * std::cos(a), 10 * std::sin(a), 0.1 * (i % 16));
  }
  return p;
}
int64_t SweepOffset(int i) { return int64_t(i) * kPeriod / kPoints; }

// The raw per-point time values of each defect, as the file or message stores them.
enum class Defect { kNone, kMicroseconds, kAtStamp, kMidScan, kRing, kRange, kOutliers };

double RawValue(Defect d, int i, std::mt19937* rng, double unit_per_ns) {
  switch (d) {
    case Defect::kNone:
      return double(SweepOffset(i)) * unit_per_ns;
    case Defect::kMicroseconds:  // µs stored, the convention's unit expected: 10⁻³ of the sweep
      return double(SweepOffset(i)) * unit_per_ns * 1e-3;
    case Defect::kAtStamp:
      return 0;
    case Defect::kMidScan:
      return 0.05e9 * unit_per_ns;
    case Defect::kRing:  // 0 … 15 in the convention's unit
      return double(i % 16);
    case Defect::kRange:  // ranges in mm (5 … 80 m) in the convention's unit
      return std::uniform_real_distribution<double>(5000, 80000)(*rng);
    case Defect::kOutliers:  // five points 3 s after the sweep
      return double(i % 150 == 7 ? SweepOffset(i) + 3'000'000'000 : SweepOffset(i)) * unit_per_ns;
  }
  return 0;
}

using ::ctlio::testing::WarningSink;

// Each scan's interval is a sweep again: about one period, and the points' times inside it.
void ExpectSweeps(const std::vector<ScanFrame>& frames, size_t points) {
  for (const ScanFrame& f : frames) {
    SCOPED_TRACE(f.index);
    EXPECT_EQ(f.cloud.size(), points);
    EXPECT_GT(f.end_ns - f.start_ns, kPeriod / 2);
    EXPECT_LT(f.end_ns - f.start_ns, kPeriod + kPeriod / 10);
  }
}

template <typename Source>
std::vector<ScanFrame> ReadAll(Source& s) {
  std::vector<ScanFrame> frames;
  ScanFrame f;
  while (s.Next(&f)) frames.push_back(f);
  return frames;
}

// ---------------------------------------------------------------------------------------------
// The check itself.

PointCloud Cloud(Defect d, double unit_per_ns = 1.0) {
  std::mt19937 rng(7);
  PointCloud c;
  c.stamp_ns = kStamp0;
  c.points = SweepPoints();
  for (int i = 0; i < kPoints; ++i) {
    c.times_ns.push_back(kStamp0 + int64_t(std::llround(RawValue(d, i, &rng, unit_per_ns))));
  }
  return c;
}

TEST(PointTimeCheck, VerdictPerDefect) {
  {
    PointCloud c = Cloud(Defect::kNone);
    const auto before = c.times_ns;
    EXPECT_EQ(CheckPointTimes(&c, kPeriod).verdict, PointTimeCheck::kSweep);
    EXPECT_EQ(c.times_ns, before);
  }
  {
    PointCloud c = Cloud(Defect::kOutliers);  // five points 3 s away do not spoil the spread
    EXPECT_EQ(CheckPointTimes(&c, kPeriod).verdict, PointTimeCheck::kSweep);
  }
  {
    PointCloud c = Cloud(Defect::kMicroseconds);
    const PointTimeCheck r = CheckPointTimes(&c, kPeriod);
    EXPECT_EQ(r.verdict, PointTimeCheck::kRescaled);
    EXPECT_EQ(r.factor, 1e3);
    EXPECT_NE(r.reason.find("microseconds where nanoseconds are expected"), std::string::npos);
    for (int i = 0; i < kPoints; ++i) EXPECT_NEAR(c.times_ns[i] - kStamp0, SweepOffset(i), 1000);
  }
  {
    PointCloud c = Cloud(Defect::kAtStamp);
    const PointTimeCheck r = CheckPointTimes(&c, kPeriod);
    EXPECT_EQ(r.verdict, PointTimeCheck::kNotASweep);
    EXPECT_EQ(r.reason, "all 720 points at the scan stamp");
  }
  {
    PointCloud c = Cloud(Defect::kMidScan);
    const PointTimeCheck r = CheckPointTimes(&c, kPeriod);
    EXPECT_EQ(r.verdict, PointTimeCheck::kNotASweep);
    EXPECT_NE(r.reason.find("all 720 points at one instant, 0.05 s from the scan stamp"),
              std::string::npos)
        << r.reason;
  }
  for (Defect d : {Defect::kRing, Defect::kRange}) {
    PointCloud c = Cloud(d);
    const PointTimeCheck r = CheckPointTimes(&c, kPeriod);
    EXPECT_EQ(r.verdict, PointTimeCheck::kNotASweep) << r.reason;
  }
  {
    PointCloud c = Cloud(Defect::kRange);
    EXPECT_NE(CheckPointTimes(&c, kPeriod).reason.find("do not follow a scan"), std::string::npos);
  }
  // 8- and 16-bit nanosecond fields wrap every 256 ns / 65.5 µs.
  for (int64_t wrap : {int64_t{256}, int64_t{65536}}) {
    PointCloud c = Cloud(Defect::kNone);
    for (int64_t& t : c.times_ns) t = kStamp0 + (t - kStamp0) % wrap;
    const PointTimeCheck r = CheckPointTimes(&c, kPeriod);
    EXPECT_EQ(r.verdict, PointTimeCheck::kNotASweep) << wrap << ": " << r.reason;
  }
  // Milliseconds where seconds are expected (Velodyne's float `time`): 1000× too long.
  {
    PointCloud c = Cloud(Defect::kNone);
    for (int64_t& t : c.times_ns) t = kStamp0 + (t - kStamp0) * 1000;
    const PointTimeCheck r = CheckPointTimes(&c, kPeriod);
    EXPECT_EQ(r.verdict, PointTimeCheck::kRescaled);
    EXPECT_EQ(r.factor, 1e-3);
  }
  // A few points say nothing about the period; only "all at one instant" is judged.
  {
    PointCloud c = Cloud(Defect::kMicroseconds);
    c.points.resize(10);
    c.times_ns.resize(10);
    EXPECT_EQ(CheckPointTimes(&c, kPeriod).verdict, PointTimeCheck::kSweep);
  }
}

// A multi-beam lidar: 90 firings of 8 beams, the beams of a firing at one time and azimuth. Its
// times wrapped by a 16-bit field (every 65.5 µs) span ~59 µs, which a unit factor 1000 would
// make a 59 ms "sweep"; in time order the firings are scrambled, but the steps between beams of
// one firing are 0 and made the median step 0 until only steps between different times counted.
TEST(PointTimeCheck, BeamsSharingAFiringTimeDoNotMakeScrambledTimesLookLikeASweep) {
  auto firings = [](int64_t wrap, double unit) {
    PointCloud c;
    c.stamp_ns = kStamp0;
    for (int f = 0; f < 90; ++f) {
      const double a = -2 * M_PI * f / 90;
      const int64_t t = int64_t(f) * kPeriod / 90;
      for (int b = 0; b < 8; ++b) {
        c.points.emplace_back(10 * std::cos(a), 10 * std::sin(a), 0.5 * b - 2.0);
        c.times_ns.push_back(kStamp0 + std::llround(double(t % wrap) * unit));
      }
    }
    return c;
  };
  const int64_t none = int64_t{1} << 62;
  PointCloud sweep = firings(none, 1.0);
  EXPECT_EQ(CheckPointTimes(&sweep, kPeriod).verdict, PointTimeCheck::kSweep);
  PointCloud us = firings(none, 1e-3);  // the same sweep in µs: still rescaled, ties and all
  const PointTimeCheck r = CheckPointTimes(&us, kPeriod);
  EXPECT_EQ(r.verdict, PointTimeCheck::kRescaled) << r.reason;
  EXPECT_EQ(r.factor, 1e3);
  PointCloud wrapped = firings(65536, 1.0);
  const PointTimeCheck w = CheckPointTimes(&wrapped, kPeriod);
  EXPECT_EQ(w.verdict, PointTimeCheck::kNotASweep) << w.reason;
  EXPECT_NE(w.reason.find("do not follow a scan"), std::string::npos) << w.reason;
}

// ---------------------------------------------------------------------------------------------
// Bag (sensor_msgs/PointCloud2): x y z float32 + a time field of the given name and datatype.

sensor_msgs::PointCloud2 Message(int64_t stamp, Defect d, const std::string& name, uint8_t type,
                                 double unit_per_ns) {
  std::mt19937 rng(11);
  const std::vector<Vec3> p = SweepPoints();
  const uint32_t size = uint32_t(FieldDatatypeSize(type));
  sensor_msgs::PointCloud2 m;
  m.header.stamp.fromNSec(uint64_t(stamp));
  m.header.frame_id = "lidar";
  for (const auto& [n, t, o] : std::vector<std::tuple<std::string, uint8_t, uint32_t>>{
           {"x", kFloat32, 0}, {"y", kFloat32, 4}, {"z", kFloat32, 8}, {name, type, 12}}) {
    sensor_msgs::PointField f;
    f.name = n;
    f.datatype = t;
    f.offset = o;
    f.count = 1;
    m.fields.push_back(f);
  }
  m.height = 1;
  m.width = kPoints;
  m.point_step = 12 + size;
  m.row_step = m.point_step * m.width;
  m.is_dense = true;
  m.data.assign(size_t(m.row_step), 0);
  for (int i = 0; i < kPoints; ++i) {
    uint8_t* r = m.data.data() + size_t(i) * m.point_step;
    const float xyz[3] = {float(p[i].x()), float(p[i].y()), float(p[i].z())};
    std::memcpy(r, xyz, 12);
    const double v = RawValue(d, i, &rng, unit_per_ns);
    if (type == kFloat32) {
      const float f = float(v);
      std::memcpy(r + 12, &f, 4);
    } else {
      // Integers keep their low bits, as a driver's narrow field would.
      const uint64_t u = uint64_t(std::llround(v));
      std::memcpy(r + 12, &u, size);
    }
  }
  return m;
}

std::vector<ScanFrame> ReadBag(const std::string& path, Defect d, const std::string& name,
                               uint8_t type, double unit_per_ns,
                               std::unique_ptr<RosbagSource>* source) {
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (int64_t t = kStamp0 - 50'000'000; t <= kStamp0 + 5 * kPeriod; t += 5'000'000) {
      sensor_msgs::Imu m;
      m.header.stamp.fromNSec(uint64_t(t));
      m.header.frame_id = "imu";
      m.linear_acceleration.z = 9.81;
      bag.write("/imu", m.header.stamp, m);
    }
    for (int k = 0; k < 3; ++k) {
      const auto m = Message(kStamp0 + k * kPeriod, d, name, type, unit_per_ns);
      bag.write("/points", m.header.stamp, m);
    }
  }
  *source = std::make_unique<RosbagSource>(path);
  return ReadAll(**source);
}

TEST(PointTimeBag, TimesThatCannotBeASweepAreRescaledOrRecoveredFromTheAzimuth) {
  const fs::path dir = testing::FreshTempDir("point_time_bag");
  struct Case {
    std::string label;
    Defect defect;
    std::string field;
    uint8_t type;
    double unit_per_ns;
    std::string warning;
  };
  const std::vector<Case> cases = {
      {"us_in_t", Defect::kMicroseconds, "t", kUInt32, 1.0, "unit factor 1000"},
      {"at_stamp", Defect::kAtStamp, "t", kUInt32, 1.0, "all 720 points at the scan stamp"},
      {"mid_scan", Defect::kMidScan, "t", kUInt32, 1.0, "all 720 points at one instant"},
      {"uint16_t", Defect::kNone, "t", kUInt16, 1.0, "(a uint16 field holds at most 65535 units"},
      {"uint8_t", Defect::kNone, "t", kUInt8, 1.0, "(a uint8 field holds at most 255 units"},
      {"ring_as_t", Defect::kRing, "t", kUInt32, 1.0, "from the azimuth"},
      {"range_as_t", Defect::kRange, "t", kUInt32, 1.0, "do not follow a scan"},
      {"ms_in_time", Defect::kNone, "time", kFloat32, 1e-6, "unit factor 0.001"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    WarningSink sink;
    std::unique_ptr<RosbagSource> s;
    const auto frames =
        ReadBag((dir / (c.label + ".bag")).string(), c.defect, c.field, c.type, c.unit_per_ns, &s);
    ASSERT_EQ(frames.size(), 3u);
    ExpectSweeps(frames, kPoints);
    EXPECT_EQ(s->retimed_scans(), 3u);
    EXPECT_EQ(s->unusable_scans(), 0u);
    EXPECT_TRUE(sink.Has(".bag: topic /points, message 1: time field")) << c.label;
    EXPECT_TRUE(sink.Has(c.warning)) << c.label;
  }
  // The clean bag is left alone.
  WarningSink sink;
  std::unique_ptr<RosbagSource> s;
  const auto frames = ReadBag((dir / "clean.bag").string(), Defect::kNone, "t", kUInt32, 1.0, &s);
  ExpectSweeps(frames, kPoints);
  EXPECT_EQ(s->retimed_scans(), 0u);
  EXPECT_EQ(frames[1].cloud.times_ns[719], kStamp0 + kPeriod + SweepOffset(719));
}

TEST(PointTimeBag, PointsSecondsOutsideTheirSweepAreDroppedAndCounted) {
  const fs::path dir = testing::FreshTempDir("point_time_bag_outliers");
  WarningSink sink;
  std::unique_ptr<RosbagSource> s;
  const auto frames =
      ReadBag((dir / "outliers.bag").string(), Defect::kOutliers, "t", kUInt32, 1.0, &s);
  ASSERT_EQ(frames.size(), 3u);  // no scan stretched over 3 s, none skipped
  ExpectSweeps(frames, kPoints - 5);
  EXPECT_EQ(s->points_outside_sweep(), 15u);
  EXPECT_EQ(s->retimed_scans(), 0u);
  EXPECT_TRUE(sink.Has("outliers.bag: topic /points, message 2: dropped 5 of 720 points"));
}

// ---------------------------------------------------------------------------------------------
// KITTI: velodyne/*.bin with velodyne_times/*.bin (float32 s since the stamp).

std::vector<ScanFrame> ReadKitti(const fs::path& dir, Defect d, double unit_per_ns) {
  fs::create_directories(dir / "velodyne");
  fs::create_directories(dir / "velodyne_times");
  std::ofstream times(dir / "times.txt");
  std::mt19937 rng(5);
  const std::vector<Vec3> p = SweepPoints();
  for (int k = 0; k < 3; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.bin", k);
    std::ofstream bin(dir / "velodyne" / name, std::ios::binary);
    std::ofstream tb(dir / "velodyne_times" / name, std::ios::binary);
    for (int i = 0; i < kPoints; ++i) {
      const float v[4] = {float(p[i].x()), float(p[i].y()), float(p[i].z()), 0.5f};
      bin.write(reinterpret_cast<const char*>(v), sizeof(v));
      const float t = float(RawValue(d, i, &rng, unit_per_ns));
      tb.write(reinterpret_cast<const char*>(&t), sizeof(t));
    }
    times << 1.0 + 0.1 * k << "\n";
  }
  times.close();
  KittiReader r(dir.string());
  return ReadAll(r);
}

TEST(PointTimeKitti, TimesThatCannotBeASweepAreRescaledOrRecoveredFromTheAzimuth) {
  const fs::path dir = testing::FreshTempDir("point_time_kitti");
  struct Case {
    std::string label;
    Defect defect;
    double unit_per_ns;
    std::string warning;
  };
  const std::vector<Case> cases = {
      {"ms_as_s", Defect::kNone, 1e-6, "unit factor 0.001"},
      {"us_as_s", Defect::kNone, 1e-3, "unit factor 1e-06"},
      {"at_stamp", Defect::kAtStamp, 1e-9, "all 720 points at the scan stamp"},
      {"mid_scan", Defect::kMidScan, 1e-9, "all 720 points at one instant"},
      {"range_as_s", Defect::kRange, 1.0, "from the azimuth"},  // ranges in mm read as s
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    WarningSink sink;
    const auto frames = ReadKitti(dir / c.label, c.defect, c.unit_per_ns);
    ASSERT_EQ(frames.size(), 3u);
    ExpectSweeps(frames, kPoints);
    EXPECT_TRUE(sink.Has("velodyne_times/000000.bin: ")) << c.label;
    EXPECT_TRUE(sink.Has(c.warning)) << c.label;
  }
}

TEST(PointTimeKitti, PointsSecondsOutsideTheirSweepAreDroppedAndCounted) {
  const fs::path dir = testing::FreshTempDir("point_time_kitti_outliers");
  WarningSink sink;
  const auto frames = ReadKitti(dir / "outliers", Defect::kOutliers, 1e-9);
  ASSERT_EQ(frames.size(), 3u);
  ExpectSweeps(frames, kPoints - 5);  // it used to span 3 s, and the run kept one point per scan
  EXPECT_TRUE(sink.Has("velodyne_times/000001.bin: dropped 5 of 720 points"));
}

// ---------------------------------------------------------------------------------------------
// Newer College: ascii PCD scans (x y z float32 + t of the given size) named by their stamp.

std::vector<ScanFrame> ReadNewerCollege(const fs::path& dir, Defect d, int t_size) {
  const fs::path scans = dir / "raw_format" / "ouster_zip_files" / "ouster_scan";
  fs::create_directories(scans);
  fs::create_directories(dir / "raw_format" / "ouster_imu");
  std::ofstream imu(dir / "raw_format" / "ouster_imu" / "data.csv");
  imu << "counter,sec,nsec,wx,wy,wz,ax,ay,az\n";
  int counter = 0;
  for (int64_t t = kStamp0 - 50'000'000; t <= kStamp0 + 5 * kPeriod; t += 5'000'000) {
    imu << counter++ << ',' << t / 1'000'000'000 << ',' << t % 1'000'000'000 << ",0,0,0,0,0,9.81\n";
  }
  imu.close();
  std::mt19937 rng(3);
  const std::vector<Vec3> p = SweepPoints();
  for (int k = 0; k < 3; ++k) {
    const int64_t stamp = kStamp0 + k * kPeriod;
    char name[64];
    std::snprintf(name, sizeof(name), "cloud_%lld_%09lld.pcd", (long long)(stamp / 1'000'000'000),
                  (long long)(stamp % 1'000'000'000));
    std::ofstream out(scans / name);
    out << "FIELDS x y z t\nSIZE 4 4 4 " << t_size << "\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH "
        << kPoints << "\nHEIGHT 1\nPOINTS " << kPoints << "\nDATA ascii\n";
    const uint64_t mask = t_size >= 8 ? ~uint64_t{0} : (uint64_t{1} << (8 * t_size)) - 1;
    for (int i = 0; i < kPoints; ++i) {
      const uint64_t t = uint64_t(std::llround(RawValue(d, i, &rng, 1.0))) & mask;
      out << float(p[i].x()) << ' ' << float(p[i].y()) << ' ' << float(p[i].z()) << ' ' << t
          << '\n';
    }
  }
  NewerCollegeReader r(dir.string());
  return ReadAll(r);
}

TEST(PointTimeNewerCollege, TimesThatCannotBeASweepAreRescaledOrRecoveredFromTheAzimuth) {
  const fs::path dir = testing::FreshTempDir("point_time_nc");
  struct Case {
    std::string label;
    Defect defect;
    int t_size;
    std::string warning;
  };
  const std::vector<Case> cases = {
      {"us_in_t", Defect::kMicroseconds, 4, "unit factor 1000"},
      {"at_stamp", Defect::kAtStamp, 4, "all 720 points at the scan stamp"},
      {"mid_scan", Defect::kMidScan, 4, "all 720 points at one instant"},
      {"uint16_t", Defect::kNone, 2, "from the azimuth"},
      {"uint8_t", Defect::kNone, 1, "from the azimuth"},
      {"ring_as_t", Defect::kRing, 4, "from the azimuth"},
      {"range_as_t", Defect::kRange, 4, "do not follow a scan"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    WarningSink sink;
    const auto frames = ReadNewerCollege(dir / c.label, c.defect, c.t_size);
    ASSERT_EQ(frames.size(), 3u);
    ExpectSweeps(frames, kPoints);
    EXPECT_TRUE(sink.Has("cloud_1_000000000.pcd: ")) << c.label;
    EXPECT_TRUE(sink.Has(c.warning)) << c.label;
  }
}

// ---------------------------------------------------------------------------------------------
// ctlio layout (ctlio's own writer; the interval is in scans.csv): the same rule, scan 1 edited.

TEST(PointTimeCtlioLayout, TimesThatCannotBeASweepAreRescaledOrRecoveredFromTheAzimuth) {
  sim::SimConfig config = sim::ExperimentConfig(sim::Regime::kMedium, 1);
  config.duration_s = 0.3;
  config.lidar.beams = 16;
  config.lidar.firing_decimation = 8;
  struct Case {
    std::string label;
    std::function<int64_t(int64_t offset)> edit;  // the stored offset [ns] from the true one
    std::string warning;
  };
  const std::vector<Case> cases = {
      {"microseconds", [](int64_t o) { return o / 1000; }, "unit factor 1000"},
      {"at_stamp", [](int64_t) { return int64_t{0}; }, "points at the scan stamp"},
      {"mid_scan", [](int64_t) { return int64_t{50'000'000}; }, "points at one instant"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    const fs::path d = testing::FreshTempDir("point_time_ctlio_" + c.label);
    sim::SimulatedSource source(config);
    WriteSimFolder(source, d.string());
    const std::string bin = (d / "scans" / "000001.bin").string();
    SimFolderReader clean(d.string());
    const std::vector<ScanFrame> before = ReadAll(clean);
    ASSERT_GE(before.size(), 2u);
    PointCloud cloud = before[1].cloud;
    ASSERT_GE(cloud.size(), kMinPointsForSpread);
    for (int64_t& t : cloud.times_ns) t = cloud.stamp_ns + c.edit(t - cloud.stamp_ns);
    WriteSimScan(bin, cloud);
    WarningSink sink;
    SimFolderReader r(d.string());
    const std::vector<ScanFrame> after = ReadAll(r);
    ASSERT_EQ(after.size(), before.size());
    const auto [lo, hi] =
        std::minmax_element(after[1].cloud.times_ns.begin(), after[1].cloud.times_ns.end());
    const int64_t length = before[1].end_ns - before[1].start_ns;
    EXPECT_GT(*hi - *lo, length / 2);  // a sweep again
    EXPECT_EQ(after[1].cloud.size(), cloud.size());
    EXPECT_TRUE(sink.Has("scans/000001.bin: ")) << c.label;
    EXPECT_TRUE(sink.Has(c.warning)) << c.label;
  }
}

}  // namespace
}  // namespace ctlio::io
