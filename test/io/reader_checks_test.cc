// The readers' shared checks of issue 40's second round (docs/user-guide/bad-input.md):
//   * ground truth: one rule in every reader (ground_truth_check.h) — a NaN or non-unit pose in a
//     bag's nav_msgs/Odometry is an error naming the bag, topic and message, as it is in the
//     folder layouts (naming file and line);
//   * repeated warnings (warning_limiter.h): 10⁴ duplicate IMU stamps or gaps log the first few in
//     full and then one total, in a CSV and in a bag.
#include <glog/logging.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "common/warning_sink.h"
#include "ctlio/io/dataset.h"
#include "ctlio/io/ground_truth_check.h"
#include "ctlio/io/kitti.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/io/trajectory_io.h"
#include "ctlio/io/warning_limiter.h"
#include "io/small_pointcloud2.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::ctlio::testing::ExpectError;

using ::ctlio::testing::WarningSink;

// 10 points, times 0 … 9 µs after the stamp (x y z float32, t uint32).
sensor_msgs::PointCloud2 Cloud(int64_t stamp_ns) { return testing::SmallPointCloud2(stamp_ns); }

// A bag with clouds at 0.2, 0.3, 0.4 s, the IMU at the given stamps, and ground-truth poses
// (qw qx qy qz x y z) at 0.1 s, 0.2 s, ... on /ground_truth.
void WriteBag(const std::string& path, const std::vector<int64_t>& imu_ns,
              const std::vector<std::vector<double>>& truth) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (const int64_t t : imu_ns) {
    sensor_msgs::Imu m;
    m.header.stamp.fromNSec(uint64_t(t));
    m.header.frame_id = "imu";
    m.linear_acceleration.z = 9.81;
    bag.write("/imu", m.header.stamp, m);
  }
  for (int k = 0; k < 3; ++k) {
    const auto c = Cloud(200'000'000 + k * 100'000'000);
    bag.write("/points", c.header.stamp, c);
  }
  for (size_t i = 0; i < truth.size(); ++i) {
    nav_msgs::Odometry o;
    o.header.stamp.fromNSec(uint64_t(100'000'000 * (i + 1)));
    o.pose.pose.orientation.w = truth[i][0];
    o.pose.pose.orientation.x = truth[i][1];
    o.pose.pose.orientation.y = truth[i][2];
    o.pose.pose.orientation.z = truth[i][3];
    o.pose.pose.position.x = truth[i][4];
    o.pose.pose.position.y = truth[i][5];
    o.pose.pose.position.z = truth[i][6];
    bag.write("/ground_truth", o.header.stamp, o);
  }
}

std::vector<int64_t> RegularImu(int64_t until_ns) {
  std::vector<int64_t> t;
  for (int64_t s = 10'000'000; s <= until_ns; s += 10'000'000) t.push_back(s);
  return t;
}

TEST(GroundTruthCheck, ANonFiniteOrNonUnitPoseInABagIsAnErrorNamingTheMessage) {
  const fs::path d = testing::FreshTempDir("gt_check_bag");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    std::string name;
    std::vector<double> pose;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {"nan_q", {nan, 0, 0, 0, 0, 0, 0}, "ground-truth pose is not finite"},
      {"nan_t", {1, 0, 0, 0, 0, nan, 0}, "ground-truth pose is not finite"},
      {"inf_t", {1, 0, 0, 0, inf, 0, 0}, "ground-truth pose is not finite"},
      {"zero_q", {0, 0, 0, 0, 0, 0, 0}, "ground-truth quaternion norm 0.000000 is not 1"},
      {"scaled_q", {2, 0, 0, 0, 0, 0, 0}, "ground-truth quaternion norm 2.000000 is not 1"},
  };
  const std::vector<double> good = {1, 0, 0, 0, 0.5, 0, 0};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string bag = (d / (c.name + ".bag")).string();
    // The second of four poses is bad: the error names message 2, not the first or the next.
    WriteBag(bag, RegularImu(700'000'000), {good, c.pose, good, good});
    ExpectError([&] { RosbagSource s(bag); },
                {c.name + ".bag", "topic /ground_truth, message 2", c.needle});
  }
  // Good poses pass (a quaternion with 4 decimals is normalised).
  const std::string ok = (d / "ok.bag").string();
  WriteBag(ok, RegularImu(700'000'000), {good, {0.7071, 0, 0, 0.7071, 0, 0, 0}, good});
  RosbagSource s(ok);
  ASSERT_TRUE(s.GroundTruth().has_value());
  EXPECT_EQ(s.GroundTruth()->size(), 3u);
  EXPECT_NEAR(s.GroundTruth()->at(1).pose.quaternion().norm(), 1.0, 1e-12);
}

TEST(GroundTruthCheck, TheFolderLayoutsApplyTheSameRuleWithFileAndLine) {
  const fs::path d = testing::FreshTempDir("gt_check_tum");
  const std::string tum = (d / "gt.tum").string();
  std::ofstream(tum) << "0.1 0 0 0 0 0 0 1\n0.2 0 0 0 0 0 0 0\n";
  ExpectError([&] { ReadTum(tum); }, {"gt.tum:2: ", "ground-truth quaternion norm 0.000000"});
  std::ofstream(tum) << "0.1 0 0 0 0 0 0 1\n0.2 nan 0 0 0 0 0 1\n";
  ExpectError([&] { ReadTum(tum); }, {"gt.tum:2: ", "is not a number"});
  EXPECT_THROW(CheckedGroundTruthPose(1, 0, 0, 0, Vec3(0, 0, NAN), "x: "), std::runtime_error);
  const SE3 T = CheckedGroundTruthPose(1.0005, 0, 0, 0, Vec3(1, 2, 3), "x: ");
  EXPECT_NEAR(T.quaternion().w(), 1.0, 1e-15);
}

TEST(WarningLimiter, TenThousandDuplicateImuStampsInACsvLogAFewLinesAndATotal) {
  std::vector<ImuSample> imu;
  std::vector<int> lines;
  for (int i = 0; i < 10'000; ++i) {
    ImuSample s;
    s.t_ns = 1'000'000'000 + int64_t(i / 2) * 5'000'000;  // every stamp twice
    imu.push_back(s);
    lines.push_back(i + 2);
  }
  WarningSink sink;
  CheckImuStream("imu.csv", lines, 0, &imu);
  EXPECT_EQ(imu.size(), 5'000u);  // the repeats are still dropped
  EXPECT_EQ(sink.CountContaining("ns, sample dropped"), WarningLimiter::kDefaultShown);
  EXPECT_EQ(sink.CountContaining("imu.csv:3: duplicate IMU time"), 1u);  // with its line
  EXPECT_EQ(sink.CountContaining("imu.csv: 5000 duplicate IMU time warnings in all (the first 5 "
                                 "logged)"),
            1u);
  EXPECT_EQ(sink.CountContaining("imu.csv: dropped 5000 duplicate IMU sample(s)"), 1u);
  EXPECT_LE(sink.lines().size(), 10u);
}

TEST(WarningLimiter, DefectsListEachKindWithItsCountAndFirstPlace) {
  WarningLimiter limiter("seq");
  limiter.Count("IMU gap", "imu.csv:9");
  limiter.Count("IMU gap", "imu.csv:40");
  limiter.Count("unusable scan");
  const std::vector<InputDefect> d = limiter.Defects();
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].kind, "IMU gap");
  EXPECT_EQ(d[0].count, 2u);
  EXPECT_EQ(d[0].first, "imu.csv:9");  // the first place, not the last
  EXPECT_EQ(d[1].kind, "unusable scan");
  EXPECT_EQ(d[1].first, "seq");  // without a detail: the source
}

TEST(InputDefects, AReaderReportsTheImuStreamsRecoveriesItsCheckCounted) {
  std::vector<ImuSample> imu(6);
  for (int i = 0; i < 6; ++i) imu[i].t_ns = int64_t(i < 3 ? i : i - 1) * 5'000'000;  // 2 = 3
  WarningLimiter reader("seq");
  CheckImuStream("imu.csv", {2, 3, 4, 5, 6, 7}, 0, &imu, &reader);
  EXPECT_EQ(imu.size(), 5u);
  const std::vector<InputDefect> d = reader.Defects();
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].kind, "duplicate IMU time");
  EXPECT_EQ(d[0].count, 1u);
  EXPECT_EQ(d[0].first, "imu.csv:5");
}

TEST(WarningLimiter, ManyImuGapsInABagLogAFewLinesAndATotal) {
  const fs::path d = testing::FreshTempDir("limiter_bag");
  // 100 gaps of 0.2 s in a 10 ms IMU (the bag warns above 0.1 s).
  std::vector<int64_t> imu;
  int64_t t = 10'000'000;
  for (int g = 0; g < 101; ++g) {
    for (int k = 0; k < 3; ++k, t += 10'000'000) imu.push_back(t);
    t += 200'000'000;
  }
  const std::string bag = (d / "gaps.bag").string();
  WriteBag(bag, imu, {});
  WarningSink sink;
  RosbagSource s(bag);
  ScanFrame f;
  while (s.Next(&f)) {
  }
  EXPECT_EQ(sink.CountContaining("s in the IMU; samples handed on"), WarningLimiter::kDefaultShown);
  EXPECT_EQ(sink.CountContaining("gaps.bag: 100 IMU gap warnings in all (the first 5 logged)"), 1u);
}

// A folder of 40 empty KITTI scans: each is handed on with its nominal interval, and the log has
// the first 5 of those warnings and one total at the end of the sequence.
TEST(WarningLimiter, ManyUnusableScansInAFolderLogAFewLinesAndATotal) {
  const fs::path k = testing::FreshTempDir("limiter_kitti");
  fs::create_directories(k / "velodyne");
  std::ofstream times(k / "times.txt");
  for (int i = 0; i < 40; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.bin", i);
    std::ofstream(k / "velodyne" / name, std::ios::binary).flush();
    times << 0.1 * i << "\n";
  }
  times.close();
  WarningSink sink;
  KittiReader reader(k.string());
  ScanFrame f;
  int frames = 0;
  while (reader.Next(&f)) ++frames;
  EXPECT_EQ(frames, 40);
  EXPECT_EQ(sink.CountContaining("scan interval set to its nominal 0.1 s"),
            WarningLimiter::kDefaultShown);
  EXPECT_EQ(sink.CountContaining(": 40 scan without an interval warnings in all (the first 5 "
                                 "logged)"),
            1u);
}

TEST(WarningLimiter, CountsPerKindAndReportsTotalsOnce) {
  WarningSink sink;
  WarningLimiter limiter("f.csv", 2);
  int logged_a = 0, logged_b = 0;
  for (int i = 0; i < 7; ++i) logged_a += limiter.Count("a");
  logged_b += limiter.Count("b");
  EXPECT_EQ(logged_a, 2);
  EXPECT_EQ(logged_b, 1);
  EXPECT_EQ(limiter.count("a"), 7u);
  limiter.LogTotals();
  limiter.LogTotals();
  EXPECT_EQ(sink.CountContaining("f.csv: 7 a warnings in all (the first 2 logged)"), 1u);
  EXPECT_EQ(sink.CountContaining(" b warnings"), 0u);  // all of them were shown
}

// Strict input (ctlio_odometry --strict): the first recovery of any kind is an error naming the
// source and the defect, in every reader (they all count their recoveries with a WarningLimiter).
class StrictInput {
 public:
  StrictInput() { WarningLimiter::SetStrict(true); }
  ~StrictInput() { WarningLimiter::SetStrict(false); }
};

TEST(WarningLimiter, StrictThrowsOnTheFirstWarningNamingSourceAndKind) {
  {
    StrictInput strict;
    WarningLimiter limiter("f.csv");
    testing::ExpectError([&] { limiter.Count("duplicate IMU time"); },
                         {"f.csv: duplicate IMU time", "--strict"});
  }
  WarningLimiter lenient("f.csv");  // and off again: counted, not thrown
  EXPECT_TRUE(lenient.Count("duplicate IMU time"));
}

TEST(WarningLimiter, StrictMakesADuplicateImuStampAnError) {
  std::vector<ImuSample> imu(3);
  imu[0].t_ns = 1'000'000;
  imu[1].t_ns = imu[2].t_ns = 6'000'000;
  std::vector<ImuSample> copy = imu;
  CheckImuStream("imu.csv", {2, 3, 4}, 0, &copy);
  EXPECT_EQ(copy.size(), 2u);  // recovered without strict
  StrictInput strict;
  testing::ExpectError(
      [&] {
        CheckImuStream("imu.csv", {2, 3, 4}, 0, &imu);
      },
      {"imu.csv:4: duplicate IMU time", "--strict"});
}

TEST(WarningLimiter, StrictMakesAnUnusableKittiScanAnError) {
  const fs::path k = testing::FreshTempDir("strict_kitti");
  fs::create_directories(k / "velodyne");
  std::ofstream(k / "velodyne" / "000000.bin", std::ios::binary).flush();
  std::ofstream(k / "times.txt") << "0.0\n";
  StrictInput strict;
  KittiReader reader(k.string());
  ScanFrame f;
  testing::ExpectError([&] { reader.Next(&f); }, {"000000.bin", "--strict"});
}

TEST(WarningLimiter, StrictMakesAnImuGapInABagAnErrorNamingTheMessage) {
  const fs::path d = testing::FreshTempDir("strict_bag");
  std::vector<int64_t> imu;  // a 0.2 s gap in a 10 ms IMU after the third sample
  for (int64_t t : {10, 20, 30, 230, 240}) imu.push_back(t * 1'000'000);
  const std::string bag = (d / "gap.bag").string();
  WriteBag(bag, imu, {});
  StrictInput strict;
  testing::ExpectError(
      [&] {
        RosbagSource s(bag);
        ScanFrame f;
        while (s.Next(&f)) {
        }
      },
      {"gap.bag", "message 4", "IMU gap", "--strict"});
}

}  // namespace
}  // namespace ctlio::io
