// PCD files that crashed PCL's reader or were read wrongly without a word: every one must give a
// clear error naming the file (and the line where there is one), never a crash, a huge allocation
// or a partial read. Also the KITTI .bin corner cases of the same kind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "ctlio/io/point_cloud_io.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using ::ctlio::testing::ExpectError;

std::string Write(const fs::path& dir, const std::string& name, const std::string& bytes) {
  const std::string p = (dir / name).string();
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

const char* kHeader3 = "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

std::string Floats(std::initializer_list<float> v) {
  return std::string(reinterpret_cast<const char*>(std::data(v)), v.size() * sizeof(float));
}

TEST(PcdHardening, BytesAfterDataThatLookLikeHeaderLines) {
  const fs::path d = testing::FreshTempDir("pcd_after_data");
  // ascii: header keywords, comments and blank lines after DATA are data, and malformed data.
  const std::string a =
      Write(d, "a.pcd",
            std::string(kHeader3) + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\nFIELDS x\n");
  ExpectError([&] { ReadPcd(a); }, {"a.pcd", "line 11", "expected 3 values"});
  const std::string c =
      Write(d, "c.pcd",
            std::string(kHeader3) + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n# x\n\n");
  ExpectError([&] { ReadPcd(c); }, {"c.pcd", "line 11", "expected 3 values, found 2"});
  const std::string e = Write(
      d, "e.pcd", std::string(kHeader3) + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n\n");
  ExpectError([&] { ReadPcd(e); }, {"e.pcd", "holds 1 points, POINTS declares 2"});
  // binary: header-like bytes are data; their length must be exactly POINTS records.
  const std::string b =
      Write(d, "b.pcd",
            std::string(kHeader3) + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary\nVERSION .7\n#\n\n");
  ExpectError([&] { ReadPcd(b); }, {"b.pcd", "binary data holds 14 B", "12 B"});
}

TEST(PcdHardening, DataLongerOrShorterThanHeaderIsAnError) {
  const fs::path d = testing::FreshTempDir("pcd_length");
  const std::string head = std::string(kHeader3) + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary\n";
  const std::string more = Write(d, "more.pcd", head + Floats({1, 2, 3, 4, 5, 6}));
  ExpectError([&] { ReadPcd(more); }, {"more.pcd", "holds 24 B", "12 B"});
  // Zero bytes after the data are PCL's padding, not points.
  const std::string pad = Write(d, "pad.pcd", head + Floats({1, 2, 3, 0, 0}));
  EXPECT_EQ(ReadPcd(pad).size(), 1u);
  const std::string ok = Write(d, "ok.pcd", head + Floats({1, 2, 3}));
  ASSERT_EQ(ReadPcd(ok).size(), 1u);
  EXPECT_EQ(ReadPcd(ok).points[0].z(), 3.0);
  const std::string ascii =
      Write(d, "more.txt.pcd",
            std::string(kHeader3) + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n4 5 6\n");
  ExpectError([&] { ReadPcd(ascii); }, {"more.txt.pcd", "line 11", "more points than POINTS"});
}

TEST(PcdHardening, HugePointCountIsRejectedBeforeAnyAllocation) {
  const fs::path d = testing::FreshTempDir("pcd_huge");
  const std::string h =
      Write(d, "h.pcd",
            std::string(kHeader3) + "WIDTH 2147483648\nHEIGHT 1\nPOINTS 2147483648\nDATA binary\n");
  ExpectError([&] { ReadPcd(h); }, {"h.pcd", "line 6", "exceeds the limit"});
  const std::string w =
      Write(d, "w.pcd",
            std::string(kHeader3) + "WIDTH 65536\nHEIGHT 65536\nDATA binary\n" + Floats({1, 2, 3}));
  ExpectError([&] { ReadPcd(w); }, {"w.pcd", "line 8", "2^31"});
  // Just under the limit: the file size decides, before any buffer of that size exists.
  const std::string m =
      Write(d, "m.pcd",
            std::string(kHeader3) + "WIDTH 2147483647\nHEIGHT 1\nPOINTS 2147483647\nDATA binary\n" +
                Floats({1, 2, 3}));
  ExpectError([&] { ReadPcd(m); }, {"m.pcd", "binary data holds 12 B"});
  const std::string c =
      Write(d, "c.pcd",
            std::string(kHeader3) + "WIDTH 2147483647\nHEIGHT 1\nDATA binary_compressed\n" +
                std::string("\x04\0\0\0\xf4\xff\xff\x7f\x03"
                            "abcd",
                            13));
  ExpectError([&] { ReadPcd(c); }, {"c.pcd", "binary_compressed"});
}

TEST(PcdHardening, BinaryCompressedRoundTripAndCountMismatch) {
  const fs::path d = testing::FreshTempDir("pcd_compressed");
  pcl::PCLPointCloud2 c;
  const char* names[] = {"x", "y", "z", "t"};
  for (int k = 0; k < 4; ++k) {
    pcl::PCLPointField f;
    f.name = names[k];
    f.offset = 4 * k;
    f.datatype = k < 3 ? pcl::PCLPointField::FLOAT32 : pcl::PCLPointField::UINT32;
    f.count = 1;
    c.fields.push_back(f);
  }
  c.point_step = 16;
  c.width = 300;
  c.height = 1;
  c.row_step = c.point_step * c.width;
  c.data.resize(c.row_step);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-10.f, 10.f);
  for (uint32_t i = 0; i < c.width; ++i) {
    const float x[3] = {u(rng), u(rng), u(rng)};
    const uint32_t t = 1000 * i;
    std::memcpy(c.data.data() + 16 * i, x, 12);
    std::memcpy(c.data.data() + 16 * i + 12, &t, 4);
  }
  const std::string path = (d / "z.pcd").string();
  ASSERT_EQ(pcl::PCDWriter().writeBinaryCompressed(path, c), 0);
  const PointCloud r = ReadPcd(path, {5000, true});
  ASSERT_EQ(r.size(), 300u);
  for (uint32_t i = 0; i < 300; i += 37) {
    float x[3];
    std::memcpy(x, c.data.data() + 16 * i, 12);
    EXPECT_EQ(r.points[i], Vec3(x[0], x[1], x[2]));
    EXPECT_EQ(r.times_ns[i], 5000 + 1000 * int64_t(i));
  }
  // COUNT 2 on one field: the decompressed size no longer matches the records (PCL overflowed).
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = bytes.find("COUNT 1 1 1 1");
  ASSERT_NE(at, std::string::npos);
  bytes.replace(at, 13, "COUNT 1 1 1 2");
  const std::string bad = Write(d, "count.pcd", bytes);
  ExpectError([&] { ReadPcd(bad); }, {"count.pcd", "decompresses to 4800 B", "6000 B"});
  // A corrupt compressed block (a back reference before the start) is an error, not a read.
  bytes.replace(at, 13, "COUNT 1 1 1 1");
  const size_t data = bytes.find("DATA binary_compressed\n") + 23;
  bytes[data + 8] = char(0xE0);
  bytes[data + 9] = char(0xFF);
  const std::string corrupt = Write(d, "corrupt.pcd", bytes);
  ExpectError([&] { ReadPcd(corrupt); }, {"corrupt.pcd", "corrupt"});
}

TEST(PcdHardening, FieldValuesThatCannotBeConverted) {
  const fs::path d = testing::FreshTempDir("pcd_values");
  const std::string ring = Write(d, "ring.pcd",
                                 "FIELDS x y z ring\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 1\n"
                                 "POINTS 1\nDATA ascii\n1 2 3 nan\n");
  ExpectError([&] { ReadPcd(ring); }, {"ring.pcd", "point 0", "ring"});
  const std::string t = Write(d, "t.pcd",
                              "FIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 1\n"
                              "POINTS 1\nDATA ascii\n1 2 3 0.5\n");
  EXPECT_THROW(ReadPcd(t), UnusableCloudError);
  const std::string time = Write(d, "time.pcd",
                                 "FIELDS x y z time\nSIZE 4 4 4 8\nTYPE F F F F\nWIDTH 1\n"
                                 "POINTS 1\nDATA ascii\n1 2 3 -1e300\n");
  ExpectError([&] { ReadPcd(time); }, {"time.pcd", "point 0", "not a valid time"});
  const std::string u8 = Write(d, "u8.pcd",
                               "FIELDS x y z ring\nSIZE 4 4 4 1\nTYPE F F F U\nWIDTH 1\n"
                               "POINTS 1\nDATA ascii\n1 2 3 300\n");
  ExpectError([&] { ReadPcd(u8); }, {"u8.pcd", "line 7", "not a valid ring"});
  const std::string size = Write(d, "size.pcd",
                                 "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 1\n"
                                 "POINTS 1\nDATA ascii\n1 2 3\n");
  ExpectError([&] { ReadPcd(size); }, {"size.pcd", "line 6", "not a PCD scalar"});
  const std::string twice = Write(d, "twice.pcd",
                                  "FIELDS x y z\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\n"
                                  "DATA ascii\n1 2 3\n");
  ExpectError([&] { ReadPcd(twice); }, {"twice.pcd", "line 2", "given twice"});
}

// PLY is read by ctlio too: PCL's parser aborted on an assertion for a PCL-written file whose
// obj_info num_cols (15) no longer matched the vertex count (found by fuzzing).
TEST(PlyHardening, HeaderAndDataMustAgree) {
  const fs::path d = testing::FreshTempDir("ply");
  const std::string head =
      "ply\nformat binary_little_endian 1.0\nobj_info num_cols 15\n"
      "element vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  const std::string ok = Write(d, "ok.ply", head + Floats({1, 2, 3, 4, 5, 6}));
  ASSERT_EQ(ReadPly(ok).size(), 2u);
  EXPECT_EQ(ReadPly(ok).points[1], Vec3(4, 5, 6));
  const std::string short_data = Write(d, "short.ply", head + Floats({1, 2, 3, 4}));
  ExpectError([&] { ReadPly(short_data); }, {"short.ply", "holds 16 B", "24 B"});
  const std::string more = Write(d, "more.ply", head + Floats({1, 2, 3, 4, 5, 6, 7}));
  ExpectError([&] { ReadPly(more); }, {"more.ply", "holds 28 B"});
  const std::string big =
      Write(d, "big.ply",
            "ply\nformat binary_big_endian 1.0\nelement vertex 1\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property uint t\nend_header\n" +
                std::string("\x3f\x80\0\0\x40\0\0\0\x40\x40\0\0\0\0\x01\0", 16));
  const PointCloud b = ReadPly(big, {10, true});
  EXPECT_EQ(b.points[0], Vec3(1, 2, 3));
  EXPECT_EQ(b.times_ns[0], 10 + 256);
  const std::string ascii = Write(d, "a.ply",
                                  "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                  "property float y\nproperty float z\nelement face 1\n"
                                  "property list uchar int vertex_indices\nend_header\n"
                                  "1 2 3\n3 0 0 0\n");
  EXPECT_EQ(ReadPly(ascii).size(), 1u);
  const std::string huge = Write(d, "huge.ply",
                                 "ply\nformat ascii 1.0\nelement vertex 4294967296\n"
                                 "property float x\nend_header\n");
  ExpectError([&] { ReadPly(huge); }, {"huge.ply", "line 3", "not in [0, 2^31)"});
  const std::string list = Write(d, "list.ply",
                                 "ply\nformat ascii 1.0\nelement vertex 1\n"
                                 "property list uchar float x\nend_header\n");
  ExpectError([&] { ReadPly(list); }, {"list.ply", "line 4", "no lists"});
  ExpectError([&] { ReadPly(Write(d, "j.ply", "plx\n")); }, {"j.ply", "not a PLY file"});
}

// Every input a fuzz target ever crashed on (fuzz/regressions/<target>_*): a clear error or a
// cloud, never a crash.
TEST(FuzzRegressions, EveryReproducerReadsOrGivesAnError) {
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(CTLIO_FUZZ_REGRESSIONS_DIR)) {
    const std::string name = e.path().filename().string();
    ++files;
    try {
      if (name.rfind("ply_", 0) == 0) ReadPly(e.path().string());
      if (name.rfind("pcd_", 0) == 0) ReadPcd(e.path().string(), {0, true});
    } catch (const std::runtime_error& err) {
      EXPECT_THAT(err.what(), HasSubstr(e.path().string()));
    }
  }
  EXPECT_GT(files, 0u);
}

TEST(KittiBinHardening, EmptyScanAndImpossibleTimes) {
  const fs::path d = testing::FreshTempDir("kitti_bin");
  const std::string empty = Write(d, "e.bin", ""), empty_t = Write(d, "e_t.bin", "");
  EXPECT_EQ(ReadKittiBin(empty, 4, empty_t, 7).size(), 0u);
  const std::string one = Write(d, "one.bin", Floats({1, 2, 3, 0}));
  const std::string far = Write(d, "far.bin", Floats({-1e30f}));
  ExpectError([&] { ReadKittiBin(one, 4, far, 0); }, {"far.bin", "value 0", "not a valid time"});
}

}  // namespace
}  // namespace ctlio::io
