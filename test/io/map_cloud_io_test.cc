// Map files (ctlio/io/map_cloud_io.h): PCD and PLY with x y z only, read back by the project's
// own readers (ReadPcd, ReadPly, ReadPointCloud) to the float32 rounding, an empty map, and bad
// names and paths as errors naming the file.
#include "ctlio/io/map_cloud_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "ctlio/io/point_cloud_io.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;

std::vector<Vec3> RandomMap(size_t n) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-300.0, 300.0);
  std::vector<Vec3> points(n);
  for (Vec3& p : points) p = Vec3(u(rng), u(rng), 0.1 * u(rng));
  return points;
}

TEST(MapCloudIo, PcdAndPlyRoundTripThroughTheReaders) {
  const fs::path d = testing::FreshTempDir("map_cloud_io");
  const std::vector<Vec3> points = RandomMap(10000);  // more than one 4096-point write block
  for (const std::string name : {"map.pcd", "map.ply"}) {
    const std::string path = (d / name).string();
    WriteMapCloud(path, points);
    // x y z float32 and the header: nothing else in the file.
    EXPECT_LT(fs::file_size(path), 12 * points.size() + 400) << name;
    const PointCloud r = name == "map.pcd" ? ReadPcd(path) : ReadPly(path);
    ASSERT_EQ(r.size(), points.size()) << name;
    EXPECT_FALSE(r.has_times());
    double worst = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      worst = std::max(worst, (r.points[i] - points[i]).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst, 3e-5) << name;  // float32 at 300 m: 2^-15 m spacing
    EXPECT_GT(worst, 0.0) << name;   // (rounded, so the check above is not trivially met)
    EXPECT_EQ(ReadPointCloud(path).size(), points.size()) << name;
  }
}

TEST(MapCloudIo, EmptyMapIsAValidFile) {
  const fs::path d = testing::FreshTempDir("map_cloud_io_empty");
  for (const std::string name : {"empty.pcd", "empty.ply"}) {
    const std::string path = (d / name).string();
    WriteMapCloud(path, {});
    EXPECT_EQ(ReadPointCloud(path).size(), 0u) << name;
  }
}

TEST(MapCloudIo, BadNamesAndPathsNameTheFile) {
  EXPECT_EQ(MapFormatOf("/a/b/c.pcd"), MapFormat::kPcd);
  EXPECT_EQ(MapFormatOf("x.ply"), MapFormat::kPly);
  // Lower case only, as ReadPointCloud reads them back.
  for (const std::string bad : {"map.xyz", "map", "map.pcd.gz", "/tmp/dir.pcd/", "map.PCD"}) {
    EXPECT_THROW(MapFormatOf(bad), std::invalid_argument) << bad;
  }
  try {
    WriteMapCloud("map.las", {Vec3::Zero()});
    ADD_FAILURE() << "no error for .las";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("map.las: a map file must end in .pcd or .ply"),
              std::string::npos)
        << e.what();
  }
  const fs::path d = testing::FreshTempDir("map_cloud_io_bad");
  const std::string missing = (d / "no_such_folder" / "map.pcd").string();
  testing::ExpectError([&] { WriteMapCloud(missing, {Vec3::Zero()}); },
                       {missing, "cannot open for writing"});
}

}  // namespace
}  // namespace ctlio::io
