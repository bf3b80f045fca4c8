// Dataset folders (SPEC §6–7): the simulator written in the Newer College 2020 layout and in
// ctlio's own layout and read back through the one DataSource interface (end to end), the real
// KITTI sample, and every bad input of the bad-input table of docs/user-guide/bad-input.md: missing
// folders/files, malformed CSV lines, PCD without a time field, scans out of order, IMU time going
// backwards or duplicated, IMU gaps.
#include "ctlio/io/dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "common/test_paths.h"
#include "ctlio/io/kitti.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/sim/extrinsic_error.h"
#include "ctlio/sim/imu_specs.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path TempDir(const std::string& name) { return testing::FreshTempDir("dataset_test_" + name); }

sim::SimConfig SmallSim() {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 1);
  c.duration_s = 0.6;
  c.lidar.beams = 8;
  c.lidar.firing_decimation = 30;
  c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;  // a Newer College-like epoch
  c.imu_from_lidar = NewerCollegeImuFromLidar();
  return c;
}

using ::ctlio::testing::ExpectError;

std::vector<ScanFrame> ReadAll(DataSource& s) {
  std::vector<ScanFrame> out;
  ScanFrame f;
  while (s.Next(&f)) out.push_back(f);
  return out;
}

// Both sources describe the same data: scans (float32 points), exact times, IMU, ground truth.
void ExpectSameData(DataSource& written, DataSource& truth, double imu_tol) {
  const auto a = ReadAll(written), b = ReadAll(truth);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 0u);
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].start_ns, b[k].start_ns);
    EXPECT_EQ(a[k].end_ns, b[k].end_ns);
    ASSERT_EQ(a[k].cloud.size(), b[k].cloud.size());
    for (size_t i = 0; i < a[k].cloud.size(); ++i) {
      EXPECT_LT((a[k].cloud.points[i] - b[k].cloud.points[i]).norm(), 1e-5);
      ASSERT_EQ(a[k].cloud.times_ns[i], b[k].cloud.times_ns[i]);
    }
    ASSERT_EQ(a[k].imu.size(), b[k].imu.size()) << k;
    for (size_t j = 0; j < a[k].imu.size(); ++j) {
      EXPECT_EQ(a[k].imu[j].t_ns, b[k].imu[j].t_ns);
      EXPECT_EQ(a[k].imu[j].imu, b[k].imu[j].imu);
      EXPECT_LT((a[k].imu[j].accel - b[k].imu[j].accel).norm(), imu_tol);
      EXPECT_LT((a[k].imu[j].gyro - b[k].imu[j].gyro).norm(), imu_tol);
    }
  }
  EXPECT_LT((written.ImuFromLidar().Inverse() * truth.ImuFromLidar()).Log().norm(), 1e-9);
  const auto ga = written.GroundTruth(), gb = truth.GroundTruth();
  ASSERT_TRUE(ga && gb);
  ASSERT_EQ(ga->size(), gb->size());
  for (size_t i = 0; i < ga->size(); ++i) {
    EXPECT_EQ((*ga)[i].t_ns, (*gb)[i].t_ns);
    EXPECT_LT(((*ga)[i].pose.Inverse() * (*gb)[i].pose).Log().norm(), 1e-12);
  }
}

TEST(NewerCollege, SimulatorWrittenInTheLayoutReadsBackEndToEnd) {
  const fs::path d = TempDir("nc");
  sim::SimulatedSource source(SmallSim());
  size_t calls = 0;
  EXPECT_EQ(WriteNewerCollege(source, d.string(), [&](size_t, size_t) { ++calls; }), 6u);
  EXPECT_EQ(calls, 6u);
  EXPECT_TRUE(fs::exists(d / "raw_format/ouster_zip_files/ouster_scan/"
                             "cloud_1583836591_182590000.pcd"));
  NewerCollegeReader reader(d.string());
  EXPECT_EQ(reader.NumScans(), 6u);
  sim::SimulatedSource truth(SmallSim());
  ExpectSameData(reader, truth, 1e-12);
  // OpenDataset recognises the layout.
  EXPECT_THAT(OpenDataset(d.string())->Name(), HasSubstr("newer_college:"));
}

TEST(SimFolder, SimulatorWrittenInCtlioLayoutReadsBackEndToEnd) {
  const fs::path d = TempDir("ctlio");
  sim::SimulatedSource source(SmallSim());
  EXPECT_EQ(WriteSimFolder(source, d.string(), "{regime: medium, index: 1}"), 6u);
  auto reader = OpenDataset(d.string());
  EXPECT_THAT(reader->Name(), HasSubstr("ctlio_sim:"));
  EXPECT_DOUBLE_EQ(*reader->Gravity(), 9.81);
  sim::SimulatedSource truth(SmallSim());
  ExpectSameData(*reader, truth, 1e-12);
  EXPECT_TRUE(fs::exists(d / "ground_truth_tum.txt"));
}

// A perturbed nominal extrinsic (calibration experiments): the folder's imu_from_lidar is the
// nominal one, true_imu_from_lidar the truth; without an error the key is not written.
TEST(SimFolder, TrueExtrinsicRoundTripsNextToTheNominal) {
  const fs::path d = TempDir("extrinsic_error");
  sim::SimConfig c = SmallSim();
  c.nominal_imu_from_lidar = sim::NominalExtrinsic(
      c.imu_from_lidar, sim::ParseExtrinsicError("3deg,0.1m"), sim::kExperimentSeed, 0);
  sim::SimulatedSource source(c);
  WriteSimFolder(source, d.string());
  SimFolderReader reader(d.string());
  EXPECT_LT((reader.ImuFromLidar().Matrix() - c.nominal_imu_from_lidar->Matrix()).norm(), 1e-12);
  ASSERT_TRUE(reader.TrueImuFromLidar().has_value());
  EXPECT_LT((reader.TrueImuFromLidar()->Matrix() - c.imu_from_lidar.Matrix()).norm(), 1e-12);
  const fs::path plain = TempDir("extrinsic_none");
  sim::SimulatedSource unperturbed(SmallSim());
  WriteSimFolder(unperturbed, plain.string());
  EXPECT_FALSE(SimFolderReader(plain.string()).TrueImuFromLidar().has_value());
}

// Two asynchronous IMUs (200 Hz in the body frame + 400 Hz rotated on a lever arm, clock start
// 1.3 ms later, other noise and biases): version 2 writes one CSV per IMU and their mountings,
// rates, noise and biases; everything reads back, samples tagged with their IMU.
TEST(SimFolder, SeveralImusRoundTripInVersion2) {
  const fs::path d = TempDir("multi_imu");
  sim::SimConfig c = SmallSim();
  c.extra_imus = sim::ParseImuSpecs(
      "rate=400,xyz=0.3:-0.1:0.05,rpy=0:0:90,offset=0.0013,accel_noise=0.04,gyro_noise=0.02,"
      "accel_bias=-0.1,gyro_bias=0.01:0.02:-0.03",
      c.imu);
  sim::SimulatedSource source(c);
  EXPECT_EQ(WriteSimFolder(source, d.string()), 6u);
  EXPECT_TRUE(fs::exists(d / "imu.csv"));
  EXPECT_TRUE(fs::exists(d / "imu1.csv"));
  SimFolderReader reader(d.string());
  EXPECT_EQ(reader.version(), 2);
  const std::vector<ImuInfo> imus = reader.Imus(), truth_imus = source.Imus();
  ASSERT_EQ(imus.size(), 2u);
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_LT((imus[j].T_body_imu.Inverse() * truth_imus[j].T_body_imu).Log().norm(), 1e-12);
    EXPECT_EQ(imus[j].rate_hz, truth_imus[j].rate_hz);
    EXPECT_EQ(imus[j].accel_sigma, truth_imus[j].accel_sigma);
    EXPECT_EQ(imus[j].gyro_sigma, truth_imus[j].gyro_sigma);
    ASSERT_TRUE(imus[j].true_bias.has_value());
    EXPECT_EQ(*imus[j].true_bias, *truth_imus[j].true_bias);
  }
  EXPECT_NEAR(imus[1].T_body_imu.translation().x(), 0.3, 1e-15);
  EXPECT_EQ(imus[1].rate_hz, 400.0);
  // Both IMUs' samples up to the last scan end, interleaved in time: 200 Hz and 400 Hz.
  sim::SimulatedSource again(c);
  const int64_t last_end = ReadAll(again).back().end_ns;
  size_t per_imu[2] = {0, 0};
  for (const ImuSample& s : reader.imu()) ++per_imu[s.imu];
  for (size_t j = 0; j < 2; ++j) {
    const auto& all = source.simulator().Imu(j);
    EXPECT_EQ(per_imu[j], size_t(std::count_if(all.begin(), all.end(), [&](const ImuSample& s) {
                return s.t_ns <= last_end;
              })));
  }
  EXPECT_GT(per_imu[1], per_imu[0] * 19 / 10);
  EXPECT_EQ(source.simulator().Imu(1).front().t_ns - c.start_ns, 1300000);
  sim::SimulatedSource truth(c);
  ExpectSameData(reader, truth, 1e-12);
}

// A version-1 folder (no `imus`: one IMU in imu.csv, the body frame) still reads.
TEST(SimFolder, Version1FolderStillReads) {
  const fs::path d = TempDir("version1");
  sim::SimulatedSource source(SmallSim());
  WriteSimFolder(source, d.string());
  const SE3 T = source.ImuFromLidar();
  const Eigen::Quaterniond q = T.quaternion();
  std::ofstream meta(d / "ctlio_sim.yaml");
  meta << std::setprecision(17) << "format: ctlio_sim\nversion: 1\ngravity: 9.81\n"
       << "imu_from_lidar: {translation: [" << T.translation().x() << ", " << T.translation().y()
       << ", " << T.translation().z() << "], quaternion_xyzw: [" << q.x() << ", " << q.y() << ", "
       << q.z() << ", " << q.w() << "]}\n";
  meta.close();
  SimFolderReader reader(d.string());
  EXPECT_EQ(reader.version(), 1);
  ASSERT_EQ(reader.Imus().size(), 1u);
  EXPECT_TRUE(reader.Imus()[0].T_body_imu.Matrix().isIdentity(0.0));
  sim::SimulatedSource truth(SmallSim());
  ExpectSameData(reader, truth, 1e-12);
}

TEST(SimFolder, BadImuListNamesTheFile) {
  const fs::path d = TempDir("bad_imus");
  sim::SimulatedSource source(SmallSim());
  WriteSimFolder(source, d.string());
  const std::string meta = (d / "ctlio_sim.yaml").string();
  std::ofstream(meta) << "format: ctlio_sim\nversion: 2\ngravity: 9.81\nimu_from_lidar: "
                         "{translation: [0, 0, 0], quaternion_xyzw: [0, 0, 0, 1]}\n";
  ExpectError([&] { SimFolderReader r(d.string()); }, {meta, "imus"});
  std::ofstream(meta) << "format: ctlio_sim\nversion: 3\ngravity: 9.81\n";
  ExpectError([&] { SimFolderReader r(d.string()); }, {meta, "version 3"});
  std::ofstream(meta) << "format: ctlio_sim\nversion: 2\ngravity: 9.81\nimu_from_lidar: "
                         "{translation: [0, 0, 0], quaternion_xyzw: [0, 0, 0, 1]}\nimus:\n"
                         "  - {file: imu.csv, body_from_imu: {translation: [0, 0], "
                         "quaternion_xyzw: [0, 0, 0, 1]}}\n";
  ExpectError([&] { SimFolderReader r(d.string()); }, {meta, "imus[0].body_from_imu"});
}

// --- bad inputs -------------------------------------------------------------------------------

// A tiny Newer College folder written by the simulator, then edited by each test.
fs::path NewerCollegeFixture(const std::string& name) {
  const fs::path d = TempDir(name);
  sim::SimConfig c = SmallSim();
  c.duration_s = 0.3;
  sim::SimulatedSource source(c);
  WriteNewerCollege(source, d.string());
  return d;
}

// Replaces line `n` (1-based) of a text file.
void ReplaceLine(const fs::path& p, int n, const std::string& text) {
  std::ifstream in(p);
  std::ostringstream out;
  std::string line;
  for (int i = 1; std::getline(in, line); ++i) out << (i == n ? text : line) << '\n';
  in.close();
  std::ofstream(p) << out.str();
}

std::string Line(const fs::path& p, int n) {
  std::ifstream in(p);
  std::string line;
  for (int i = 1; i <= n; ++i) std::getline(in, line);
  return line;
}

TEST(BadInput, MissingFoldersAndFiles) {
  ExpectError([] { NewerCollegeReader("/nonexistent/ctlio_seq"); }, {"/nonexistent", "not found"});
  ExpectError([] { SimFolderReader("/nonexistent/ctlio_seq"); }, {"not found"});
  ExpectError([] { KittiReader("/nonexistent/ctlio_seq"); }, {"velodyne", "not found"});
  ExpectError([] { OpenDataset("/nonexistent/ctlio_seq"); }, {"not found"});
  const fs::path d = NewerCollegeFixture("missing_imu");
  fs::remove(d / "raw_format/ouster_imu/data.csv");
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"data.csv", "not found"});
  const fs::path e = TempDir("not_a_dataset");
  ExpectError([&] { OpenDataset(e.string()); }, {"not a dataset folder"});
  // A file, with no file opener registered (this test does not link ctlio::io_rosbag): the error
  // names the library that opens bags.
  const fs::path f = e / "x.bag";
  std::ofstream(f) << "#ROSBAG V2.0\n";
  ExpectError([&] { OpenDataset(f.string()); }, {"x.bag", "not a dataset folder", "io_rosbag"});
}

TEST(BadInput, MalformedCsvLinesNameFileAndLine) {
  const fs::path d = NewerCollegeFixture("malformed");
  const fs::path imu = d / "raw_format/ouster_imu/data.csv";
  ReplaceLine(imu, 5, "3,1583836591,197590000,0.1,0.2,zero,1,2,3");
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"data.csv:5", "field 6", "zero"});
  ReplaceLine(imu, 5, "3,1583836591,197590000,0.1,0.2");
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"data.csv:5", "expected 9", "found 5"});
  ReplaceLine(imu, 5, "3,1583836591,197590000,0.1,0.2,0.3,,2,3");
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"data.csv:5", "empty field"});
  // A trailing comma and CRLF are tolerated (documented in text_table.h).
  ReplaceLine(imu, 5, "3,1583836591,197590000,0.1,0.2,0.3,1,2,3,\r");
  EXPECT_NO_THROW(NewerCollegeReader r(d.string()));
  const fs::path e = NewerCollegeFixture("malformed_gt");
  ReplaceLine(e / "ground_truth/registered_poses.csv", 3, "1583836599,1,0,0,0,0,0,0,3");
  ExpectError([&] { NewerCollegeReader r(e.string()); }, {"registered_poses.csv:3", "quaternion"});
}

TEST(BadInput, PcdWithoutTimeField) {
  const fs::path d = NewerCollegeFixture("no_t");
  const fs::path scan =
      d / "raw_format/ouster_zip_files/ouster_scan/cloud_1583836591_282590000.pcd";
  ASSERT_TRUE(fs::exists(scan));
  PointCloud c = ReadPcd(scan.string());
  std::ofstream out(scan);
  out << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " << c.size()
      << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << c.size() << "\nDATA ascii\n";
  for (const auto& p : c.points) out << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  out.close();
  ExpectError(
      [&] {
        ReadPcd(scan.string(), {0, true});
      },
      {"cloud_1583836591_282590000.pcd", "line 2", "time field"});
  // In a sequence the scan is unusable, not fatal: handed on empty over its interval (logged).
  NewerCollegeReader r(d.string());
  ScanFrame f;
  ASSERT_TRUE(r.Next(&f));
  ASSERT_TRUE(r.Next(&f));
  EXPECT_EQ(f.cloud.size(), 0u);
  EXPECT_GT(f.end_ns, f.start_ns);
  EXPECT_TRUE(r.Next(&f));
}

TEST(BadInput, ScansOutOfOrder) {
  // Newer College: order comes from the file-name stamps (recovery); a duplicate stamp is an error.
  const fs::path d = NewerCollegeFixture("dup_scan");
  const fs::path dir = d / "raw_format/ouster_zip_files/ouster_scan";
  fs::copy_file(dir / "cloud_1583836591_182590000.pcd", dir / "copy_1583836591_182590000.pcd");
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"same stamp"});
  fs::remove(dir / "copy_1583836591_182590000.pcd");
  fs::copy_file(dir / "cloud_1583836591_182590000.pcd", dir / "cloud_x.pcd");
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"cloud_x.pcd", "<sec>_<nsec>"});
  // ctlio layout: scans.csv must be in time order.
  const fs::path s = TempDir("order");
  sim::SimConfig c = SmallSim();
  c.duration_s = 0.3;
  sim::SimulatedSource source(c);
  WriteSimFolder(source, s.string());
  const std::string l2 = Line(s / "scans.csv", 2), l3 = Line(s / "scans.csv", 3);
  ReplaceLine(s / "scans.csv", 2, l3);
  ReplaceLine(s / "scans.csv", 3, l2);
  ExpectError([&] { SimFolderReader r(s.string()); }, {"scans.csv:3", "out of order"});
}

TEST(BadInput, ImuBackwardsDuplicatedAndGaps) {
  const fs::path d = NewerCollegeFixture("imu_time");
  const fs::path imu = d / "raw_format/ouster_imu/data.csv";
  const std::string l4 = Line(imu, 4), l5 = Line(imu, 5);
  // Duplicate: documented recovery, the second sample is dropped (logged).
  const size_t before = NewerCollegeReader(d.string()).imu().size();
  ReplaceLine(imu, 5, l4);
  EXPECT_EQ(NewerCollegeReader(d.string()).imu().size(), before - 1);
  // Backwards: error naming the line.
  ReplaceLine(imu, 4, l5);
  ReplaceLine(imu, 5, l4);
  ExpectError([&] { NewerCollegeReader r(d.string()); }, {"data.csv:5", "backwards"});
  // Gap: remove 30 lines (0.15 s at 200 Hz) > 0.1 s limit.
  ReplaceLine(imu, 4, l4);
  ReplaceLine(imu, 5, l5);
  {
    std::ifstream in(imu);
    std::ostringstream out;
    std::string line;
    for (int i = 1; std::getline(in, line); ++i) {
      if (i < 10 || i >= 40) out << line << '\n';
    }
    in.close();
    std::ofstream(imu) << out.str();
  }
  // By default a gap is a warning and every sample is handed on; the limit is an opt-in error.
  EXPECT_EQ(NewerCollegeReader(d.string()).imu().size(), before - 30);
  NewerCollegeOptions strict;
  strict.max_imu_gap_error_ns = 100'000'000;
  ExpectError([&] { NewerCollegeReader r(d.string(), strict); }, {"data.csv:10", "gap of 0.15"});
  ExpectError([&] { OpenDataset(d.string(), 100'000'000); }, {"data.csv:10", "gap of 0.15"});
}

TEST(Kitti, RealSampleScansAndGroundTruth) {
  const fs::path d = fs::path(ctlio::testing::SharedDataDir()) / "kitti_odom00_start";
  if (!fs::exists(d)) GTEST_SKIP() << "shared data folder absent: " << d;
  KittiReader r(d.string());
  ASSERT_EQ(r.NumScans(), 2u);
  ScanFrame f;
  ASSERT_TRUE(r.Next(&f));
  EXPECT_EQ(f.cloud.size(), 124668u);  // SOURCE.md
  EXPECT_TRUE(f.imu.empty());
  // Azimuth-filled times span one 0.1 s revolution around the stamp 0.
  EXPECT_NEAR(double(f.end_ns - f.start_ns), 1e8, 1e6);
  EXPECT_LE(f.start_ns, 0);
  ASSERT_TRUE(r.Next(&f));
  EXPECT_EQ(f.cloud.size(), 124605u);
  EXPECT_FALSE(r.Next(&f));
  const auto gt = r.GroundTruth();
  ASSERT_TRUE(gt.has_value());
  EXPECT_EQ(gt->size(), 4541u);
  EXPECT_EQ((*gt)[1].t_ns, 103735900);
  // Velodyne frame: the car drives forward (+x) ~0.86 m per frame at the start (SOURCE.md).
  const Vec3 step = (*gt)[1].pose.translation() - (*gt)[0].pose.translation();
  EXPECT_NEAR(step.x(), 0.86, 0.02);
  EXPECT_LT(std::abs(step.y()) + std::abs(step.z()), 0.1);
}

}  // namespace
}  // namespace ctlio::io
