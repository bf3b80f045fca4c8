// TUM and KITTI trajectory files: exact ns times, round trips, errors with file and line.
#include "ctlio/io/trajectory_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

TEST(TrajectoryIo, SecondsParseExactlyToNanoseconds) {
  int64_t ns = 0;
  ASSERT_TRUE(ParseSecondsNs("1583836591.182590001", &ns));
  EXPECT_EQ(ns, 1583836591182590001LL);
  ASSERT_TRUE(ParseSecondsNs("0.5", &ns));
  EXPECT_EQ(ns, 500000000);
  ASSERT_TRUE(ParseSecondsNs("1.037359e-01", &ns));
  EXPECT_EQ(ns, 103735900);
  EXPECT_FALSE(ParseSecondsNs("abc", &ns));
  EXPECT_EQ(FormatSecondsNs(1583836591182590001LL), "1583836591.182590001");
  EXPECT_EQ(FormatSecondsNs(-1), "-0.000000001");
}

TEST(TrajectoryIo, TumAndKittiRoundTrip) {
  const fs::path d = testing::FreshTempDir("traj_io_roundtrip");
  std::vector<StampedPose> poses;
  for (int i = 0; i < 50; ++i) {
    poses.push_back({1583836591000000000LL + i * 100000007LL,
                     SE3(so3::Exp(Vec3(0.1 * i, -0.05 * i, 0.3)), Vec3(i, 2.0 * i, -0.5 * i))});
  }
  WriteTum((d / "a.txt").string(), poses);
  const auto tum = ReadTrajectory((d / "a.txt").string());
  ASSERT_EQ(tum.size(), poses.size());
  WriteKittiPoses((d / "k.txt").string(), poses);
  const auto kitti = ReadTrajectory((d / "k.txt").string());
  ASSERT_EQ(kitti.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(tum[i].t_ns, poses[i].t_ns);
    EXPECT_LT((tum[i].pose.Inverse() * poses[i].pose).Log().norm(), 1e-12);
    EXPECT_EQ(kitti[i].t_ns, int64_t(i) * 100000000);  // no times file: index · 0.1 s
    EXPECT_LT((kitti[i].pose.Inverse() * poses[i].pose).Log().norm(), 1e-9);
  }
}

TEST(TrajectoryIo, BadLinesNameFileAndLine) {
  const fs::path d = testing::FreshTempDir("traj_io_bad_lines");
  const std::string p = (d / "bad.txt").string();
  auto expect = [&](const std::string& text, const std::vector<std::string>& parts) {
    std::ofstream(p) << text;
    try {
      ReadTum(p);
      FAIL() << "no exception for: " << text;
    } catch (const std::runtime_error& e) {
      for (const auto& s : parts) EXPECT_THAT(e.what(), HasSubstr(s));
    }
  };
  expect("# header\n0.0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0\n", {"bad.txt:3", "expected 8"});
  expect("0.0 0 0 0 0 0 0 1\n0.1 0 0 x 0 0 0 1\n", {"bad.txt:2", "field 4"});
  expect("0.2 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n", {"bad.txt:2", "not after"});
  expect("0.0 0 0 0 0 0 0 2\n", {"bad.txt:1", "quaternion"});
  EXPECT_THROW(ReadTum((d / "none.txt").string()), std::runtime_error);
}

}  // namespace
}  // namespace ctlio::io
