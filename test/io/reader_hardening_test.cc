// Dataset folders that crashed a reader or were read wrongly without a word: overflowing stamps,
// short nanosecond fields, headerless CSVs, zero quaternions, unusable scans (which every layout
// hands on the same documented way), far point times, an extrinsic the layout cannot carry.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "ctlio/io/dataset.h"
#include "ctlio/io/kitti.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/io/warning_limiter.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using ::ctlio::testing::ExpectError;

sim::SimConfig TinySim() {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 1);
  c.duration_s = 0.3;
  c.lidar.beams = 8;
  c.lidar.firing_decimation = 30;
  c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;
  c.imu_from_lidar = NewerCollegeImuFromLidar();
  return c;
}

fs::path NcFixture(const std::string& name) {
  const fs::path d = testing::FreshTempDir("harden_" + name);
  sim::SimulatedSource source(TinySim());
  WriteNewerCollege(source, d.string());
  return d;
}

fs::path CtlioFixture(const std::string& name) {
  const fs::path d = testing::FreshTempDir("harden_" + name);
  sim::SimulatedSource source(TinySim());
  WriteSimFolder(source, d.string());
  return d;
}

std::vector<std::string> Lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}
void WriteLines(const fs::path& p, const std::vector<std::string>& lines) {
  std::ofstream out(p);
  for (const auto& l : lines) out << l << '\n';
}

std::vector<ScanFrame> ReadAll(DataSource& s) {
  std::vector<ScanFrame> out;
  ScanFrame f;
  while (s.Next(&f)) out.push_back(f);
  return out;
}

TEST(ReaderHardening, StampsThatOverflowOrAreShortAreErrors) {
  int64_t ns = 0;
  EXPECT_FALSE(ParseNewerCollegeScanName("cloud_0_5.pcd", &ns));  // not 5 ns
  EXPECT_TRUE(ParseNewerCollegeScanName("cloud_0_000000005.pcd", &ns));
  EXPECT_EQ(ns, 5);
  EXPECT_FALSE(ParseNewerCollegeScanName("cloud_9999999999_000000000.pcd", &ns));  // > int64 ns
  EXPECT_FALSE(ParseNewerCollegeScanName("cloud_99999999999999999999_000000000.pcd", &ns));
  EXPECT_FALSE(ParseSecondsNs("-1e300", &ns));
  EXPECT_FALSE(ParseSecondsNs("99999999999.5", &ns));
  EXPECT_TRUE(ParseSecondsNs("9223372035.5", &ns));
  EXPECT_EQ(ns, 9223372035500000000);

  const fs::path d = NcFixture("stamp");
  const fs::path imu = d / "raw_format/ouster_imu/data.csv";
  auto lines = Lines(imu);
  lines[3] = "2,9223372036854775807,0,0,0,0,0,0,9.8";
  WriteLines(imu, lines);
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"data.csv:4", "out of range"});
  const fs::path dir = d / "raw_format/ouster_zip_files/ouster_scan";
  fs::copy_file(dir / "cloud_1583836591_182590000.pcd", dir / "cloud_0_5.pcd");
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"cloud_0_5.pcd", "9 digits"});

  const fs::path k = testing::FreshTempDir("harden_kitti_times");
  fs::create_directories(k / "velodyne");
  std::ofstream(k / "velodyne" / "000000.bin", std::ios::binary).flush();
  std::ofstream(k / "times.txt") << "-1e300\n";
  ExpectError([&] { KittiReader r(k.string()); }, {"times.txt:1", "not a time"});
}

TEST(ReaderHardening, HeaderlessCsvAndByteOrderMarkKeepTheFirstRow) {
  const fs::path d = CtlioFixture("headerless");
  const size_t scans = SimFolderReader(d.string()).NumScans();
  auto lines = Lines(d / "scans.csv");
  lines.erase(lines.begin());  // no header: the first row ends in a file name
  WriteLines(d / "scans.csv", lines);
  EXPECT_EQ(SimFolderReader(d.string()).NumScans(), scans);

  const fs::path n = NcFixture("bom");
  const fs::path imu = n / "raw_format/ouster_imu/data.csv";
  const size_t samples = NewerCollegeReader(n.string()).imu().size();
  auto imu_lines = Lines(imu);
  imu_lines.erase(imu_lines.begin());
  imu_lines[0] = "\xEF\xBB\xBF" + imu_lines[0];
  WriteLines(imu, imu_lines);
  EXPECT_EQ(NewerCollegeReader(n.string()).imu().size(), samples);
}

TEST(ReaderHardening, ZeroQuaternionInTheCtlioYamlIsAnError) {
  const fs::path d = CtlioFixture("zero_q");
  auto lines = Lines(d / "ctlio_sim.yaml");
  for (auto& l : lines) {
    // Keep the line's indentation: the key sits at several depths (extrinsic, imus list).
    const size_t k = l.find("quaternion_xyzw");
    if (k != std::string::npos) l = l.substr(0, k) + "quaternion_xyzw: [0, 0, 0, 0]";
  }
  WriteLines(d / "ctlio_sim.yaml", lines);
  ExpectError([&] { SimFolderReader r(d.string()); },
              {"ctlio_sim.yaml", "quaternion is not a rotation: |q|^2 = 0"});
  // NaN in a translation (the shared extrinsic check, as for a bag's /tf_static).
  const fs::path n = CtlioFixture("nan_t");
  lines = Lines(n / "ctlio_sim.yaml");
  for (auto& l : lines) {
    const size_t k = l.find("translation:");
    if (k != std::string::npos) l = l.substr(0, k) + "translation: [0, .nan, 0]";
  }
  WriteLines(n / "ctlio_sim.yaml", lines);
  ExpectError([&] { SimFolderReader r(n.string()); },
              {"ctlio_sim.yaml", "translation is not finite"});
}

// Replaces one Newer College scan by an ascii PCD with the given fields and rows.
void ReplaceScan(const fs::path& scan, const std::string& fields, const std::string& types,
                 const std::vector<std::string>& rows) {
  std::ofstream out(scan);
  std::istringstream f(fields);
  size_t k = 0;
  for (std::string s; f >> s;) ++k;
  out << "FIELDS " << fields << "\nSIZE";
  for (size_t i = 0; i < k; ++i) out << " 4";
  out << "\nTYPE " << types << "\nWIDTH " << rows.size() << "\nPOINTS " << rows.size()
      << "\nDATA ascii\n";
  for (const auto& r : rows) out << r << '\n';
}

TEST(ReaderHardening, UnusableScansAreHandedOnEmptyInEveryLayout) {
  const fs::path d = NcFixture("unusable");
  const fs::path dir = d / "raw_format/ouster_zip_files/ouster_scan";
  const size_t scans = NewerCollegeReader(d.string()).NumScans();
  ASSERT_EQ(scans, 3u);
  const fs::path s1 = dir / "cloud_1583836591_282590000.pcd";
  const std::vector<std::vector<std::string>> bad = {
      {},                          // empty
      {"nan 1 1 0", "1 nan 1 5"},  // all non-finite
      {"1 1 1 0", "2 2 2 0"},      // all at the stamp: the points are kept
  };
  for (const auto& rows : bad) {
    ReplaceScan(s1, "x y z t", "F F F U", rows);
    NewerCollegeReader r(d.string());
    const auto frames = ReadAll(r);
    ASSERT_EQ(frames.size(), scans);
    EXPECT_EQ(frames[1].cloud.size(), rows.size() == 2 && rows[0][0] == '1' ? 2u : 0u);
    EXPECT_GT(frames[1].end_ns, frames[1].start_ns);
    EXPECT_GT(frames[1].start_ns, frames[0].end_ns - 10'000'000);
    EXPECT_GT(frames[2].end_ns, frames[1].end_ns);
    EXPECT_GT(frames[2].cloud.size(), 0u);
  }
  ReplaceScan(s1, "x y z t", "F F F F", {"1 1 1 0.5"});  // 't' of a wrong type
  NewerCollegeReader r(d.string());
  EXPECT_EQ(ReadAll(r)[1].cloud.size(), 0u);

  // ctlio layout: all non-finite → the same empty scan (its interval comes from scans.csv).
  const fs::path c = CtlioFixture("unusable_ctlio");
  const std::string bin = (c / "scans" / "000001.bin").string();
  PointCloud nan_cloud = ReadSimScan(bin, 0);
  for (auto& p : nan_cloud.points) p.x() = std::numeric_limits<double>::quiet_NaN();
  WriteSimScan(bin, nan_cloud);
  SimFolderReader sr(c.string());
  const auto frames = ReadAll(sr);
  EXPECT_EQ(frames[1].cloud.size(), 0u);
  EXPECT_EQ(frames[1].cloud.dropped_non_finite, nan_cloud.size());
  EXPECT_GT(frames[1].end_ns, frames[1].start_ns);

  // KITTI: an empty .bin without per-point times.
  const fs::path k = testing::FreshTempDir("harden_kitti_empty");
  fs::create_directories(k / "velodyne");
  std::ofstream(k / "velodyne" / "000000.bin", std::ios::binary).flush();
  std::ofstream(k / "velodyne" / "000001.bin", std::ios::binary).flush();
  std::ofstream(k / "times.txt") << "0.0\n0.1\n";
  KittiReader kr(k.string());
  const auto kf = ReadAll(kr);
  ASSERT_EQ(kf.size(), 2u);
  EXPECT_GT(kf[0].end_ns, kf[0].start_ns);
  EXPECT_GT(kf[1].end_ns, kf[0].end_ns);
}

TEST(ReaderHardening, FarPointTimeOnTheLastScanDoesNotStretchIt) {
  const fs::path d = NcFixture("far_t");
  const fs::path last =
      d / "raw_format/ouster_zip_files/ouster_scan/cloud_1583836591_382590000.pcd";
  ReplaceScan(last, "x y z t", "F F F U", {"1 1 1 0", "2 2 2 50000000", "3 3 3 4000000000"});
  NewerCollegeReader r(d.string());
  const auto frames = ReadAll(r);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].cloud.size(), 2u);  // the point 4 s later is dropped (logged)
  EXPECT_EQ(frames[2].end_ns - frames[2].start_ns, 50'000'000);
}

// A folder written with an IMU outage (0.6 s, as in the dropout experiments) reads back in both
// layouts with every sample and its hole: the gap is a warning unless the opt-in limit is set.
TEST(ReaderHardening, FolderWithAnImuOutageReadsBack) {
  sim::SimConfig c = TinySim();
  c.duration_s = 1.0;
  c.imu.outages = {{0.3, 0.6}};
  size_t samples = 0;
  {
    sim::SimulatedSource truth(c);
    for (const auto& f : ReadAll(truth)) samples += f.imu.size();
  }
  const fs::path a = testing::FreshTempDir("harden_outage_ctlio");
  const fs::path b = testing::FreshTempDir("harden_outage_nc");
  sim::SimulatedSource sa(c), sb(c);
  WriteSimFolder(sa, a.string());
  WriteNewerCollege(sb, b.string());
  for (const fs::path& d : {a, b}) {
    auto reader = OpenDataset(d.string());
    size_t read = 0;
    int64_t widest = 0, last = 0;
    for (const auto& f : ReadAll(*reader)) {
      for (const auto& s : f.imu) {
        if (read++ > 0) widest = std::max(widest, s.t_ns - last);
        last = s.t_ns;
      }
    }
    EXPECT_EQ(read, samples) << d;
    EXPECT_NEAR(double(widest), 0.6e9, 0.01e9) << d;
    ExpectError([&] { OpenDataset(d.string(), 100'000'000); }, {"gap of 0.6"});
  }
}

TEST(ReaderHardening, NewerCollegeWriterRefusesAnExtrinsicTheLayoutCannotCarry) {
  sim::SimConfig c = TinySim();
  c.imu_from_lidar = SE3();
  sim::SimulatedSource source(c);
  const fs::path d = testing::FreshTempDir("harden_extrinsic");
  ExpectError([&] { WriteNewerCollege(source, d.string()); },
              {d.string(), "published T_imu_lidar"});
}

// Issue 40: a folder reader hands on what it recovered from (DataSource::InputDefects), so that
// the run reports it in evaluation.txt: none for a clean folder, the duplicate for one with an IMU
// line repeated, with the line of the first.
TEST(InputDefects, AFolderReaderHandsOnWhatItRecoveredFrom) {
  const fs::path d = CtlioFixture("defects");
  EXPECT_TRUE(SimFolderReader(d.string()).InputDefects().empty());
  std::vector<std::string> lines;
  {
    std::ifstream in(d / "imu.csv");
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  lines.insert(lines.begin() + 10, lines[10]);  // line 12 repeats line 11
  {
    std::ofstream out(d / "imu.csv");
    for (const auto& l : lines) out << l << "\n";
  }
  SimFolderReader reader(d.string());
  const std::vector<InputDefect> defects = reader.InputDefects();
  ASSERT_EQ(defects.size(), 1u);
  EXPECT_EQ(defects[0].kind, "duplicate IMU time");
  EXPECT_EQ(defects[0].count, 1u);
  EXPECT_NE(defects[0].first.find("imu.csv:12"), std::string::npos) << defects[0].first;
}

}  // namespace
}  // namespace ctlio::io
