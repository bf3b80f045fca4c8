// Per-point field layouts (point_fields.h): every driver's time convention written into a PCD file
// and read back through the PCD reader's detection, the layout errors (missing x/y/z, wrong field
// types, a time-like field of the wrong type), overrides, and the azimuth recovery.
#include "ctlio/io/point_fields.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "common/expect_error.h"
#include "common/temp_dir.h"
#include "io/time_variants.h"

namespace ctlio::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using ::ctlio::testing::ExpectError;

// A 0.1 s sweep of `n` points with absolute times starting at a Newer College-like epoch.
PointCloud Sweep(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  std::uniform_int_distribution<int64_t> dt(0, 99'999'999);
  PointCloud c;
  c.stamp_ns = 1583836591LL * 1000000000LL + 182590000LL;
  for (size_t i = 0; i < n; ++i) {
    c.points.emplace_back(u(rng), u(rng), u(rng));
    c.times_ns.push_back(c.stamp_ns + (i == 0 ? 0 : i == 1 ? 99'999'999 : dt(rng)));
  }
  return c;
}

// A binary PCD file with the given layout (PCL needs the fields packed in order).
void WriteBinaryPcd(const std::string& path, const std::vector<PointField>& fields,
                    const std::vector<uint8_t>& data, size_t n) {
  std::ofstream f(path, std::ios::binary);
  f << "VERSION 0.7\nFIELDS";
  for (const auto& x : fields) f << ' ' << x.name;
  f << "\nSIZE";
  for (const auto& x : fields) f << ' ' << FieldDatatypeSize(x.datatype);
  f << "\nTYPE";
  for (const auto& x : fields) {
    f << ' ' << (x.datatype >= kFloat32 ? 'F' : x.datatype % 2 == 1 ? 'I' : 'U');
  }
  f << "\nCOUNT";
  for (size_t i = 0; i < fields.size(); ++i) f << " 1";
  f << "\nWIDTH " << n << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << n << "\nDATA binary\n";
  f.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
}

TEST(PointFields, EveryDriverTimeFieldRoundTripsThroughPcd) {
  const fs::path d = testing::FreshTempDir("point_fields_pcd");
  for (const auto& v : fixtures::TimeVariants()) {
    SCOPED_TRACE(v.driver);
    PointCloud c = Sweep(500, 3);
    // A stamp at the scan end (Velodyne) makes the stored offsets negative.
    const int64_t stamp =
        v.written.stamp_at == StampAt::kScanEnd ? c.stamp_ns + 100'000'000 : c.stamp_ns;
    c.stamp_ns = stamp;
    const auto data = EncodePoints(c, v.fields, v.point_step, v.written);
    const std::string path = (d / "cloud.pcd").string();
    WriteBinaryPcd(path, v.fields, data, c.size());
    const PointCloud r = ReadPcd(path, {stamp, true});
    ASSERT_EQ(r.size(), c.size());
    ASSERT_TRUE(r.has_times());
    double worst = 0.0;
    for (size_t i = 0; i < c.size(); ++i) {
      worst = std::max(worst, std::abs(double(r.times_ns[i] - c.times_ns[i])));
      EXPECT_LT((r.points[i] - c.points[i]).norm(), 1e-5);
    }
    EXPECT_LE(worst, v.tolerance_ns);
    // The detection names the driver convention it matched.
    const PointLayout layout = DetectPointLayout(v.fields, v.point_step, {}, "");
    EXPECT_EQ(layout.convention.driver, v.driver);
    EXPECT_EQ(layout.convention.stamp_at, v.written.stamp_at);
  }
}

TEST(PointFields, LayoutErrorsNameTheFieldsFound) {
  const PointField x{"x", kFloat32, 0, 1}, y{"y", kFloat32, 4, 1}, z{"z", kFloat32, 8, 1};
  ExpectError(
      [&] {
        DetectPointLayout({x, y, {"t", kUInt32, 8, 1}}, 12, {}, "bag: ");
      },
      {"bag: ", "no 'z' field", "x:float32 y:float32 t:uint32"});
  ExpectError(
      [&] {
        DetectPointLayout({x, y, {"z", kUInt16, 8, 1}}, 10, {}, "");
      },
      {"'z' must be one float32 or float64", "z:uint16"});
  ExpectError(
      [&] {
        DetectPointLayout({x, y, z, {"t", kFloat32, 12, 1}}, 16, {}, "");
      },
      {"time field 't' is float32", "integer", "t:float32"});
  ExpectError(
      [&] {
        DetectPointLayout({x, y, z, {"time", kUInt32, 12, 1}}, 16, {}, "");
      },
      {"time field 'time' is uint32", "Velodyne"});
  ExpectError(
      [&] {
        DetectPointLayout({x, y, z, {"timestamp", kFloat32, 12, 1}}, 16, {}, "");
      },
      {"'timestamp' is float32", "float64"});
  ExpectError(
      [&] {
        DetectPointLayout({x, y, z, {"t", kUInt32, 12, 1}}, 14, {}, "");
      },
      {"'t' ends past the point step of 14 B"});
  TimeFieldOptions o;
  o.field = "stamp_us";
  ExpectError(
      [&] {
        DetectPointLayout({x, y, z}, 12, o, "");
      },
      {"no time field 'stamp_us'", "x:float32 y:float32 z:float32"});
  // No time field at all is not an error: the caller recovers the times from the azimuth.
  EXPECT_FALSE(DetectPointLayout({x, y, z, {"intensity", kFloat32, 12, 1}}, 16, {}, "").time);
}

TEST(PointFields, ATimeThatIsNotOneIsAnError) {
  const std::vector<PointField> fields = {{"x", kFloat32, 0, 1},
                                          {"y", kFloat32, 4, 1},
                                          {"z", kFloat32, 8, 1},
                                          {"timestamp", kFloat64, 12, 1}};
  const PointLayout layout = DetectPointLayout(fields, 20, {}, "");
  for (const double bad : {std::nan(""), 1e300, -1e11}) {
    std::vector<uint8_t> data(40, 0);
    std::memcpy(data.data() + 20 + 12, &bad, sizeof(bad));  // the second point
    PointCloud c;
    ExpectError([&] { DecodePoints(data.data(), 2, layout, 0, "cloud.pcd: ", &c); },
                {"cloud.pcd: point 1", "time is not finite or outside int64 ns"});
  }
}

TEST(PointFields, OverrideReadsAnUndocumentedField) {
  // A driver storing microseconds since the stamp in a uint32 field named "offset_us".
  const std::vector<PointField> fields = {{"x", kFloat32, 0, 1},
                                          {"y", kFloat32, 4, 1},
                                          {"z", kFloat32, 8, 1},
                                          {"offset_us", kUInt32, 12, 1}};
  PointCloud c = Sweep(100, 5);
  for (auto& t : c.times_ns) t = c.stamp_ns + (t - c.stamp_ns) / 1000 * 1000;  // µs resolution
  TimeConvention written;
  written.field = "offset_us";
  written.unit = TimeUnit::kMicroseconds;
  const auto data = EncodePoints(c, fields, 16, written);
  // Without the override the field is not a time: no times (azimuth recovery by the caller).
  EXPECT_FALSE(DetectPointLayout(fields, 16, {}, "").time);
  TimeFieldOptions o;
  o.field = "offset_us";
  o.unit = ParseTimeUnit("us");
  const PointLayout layout = DetectPointLayout(fields, 16, o, "");
  ASSERT_TRUE(layout.time);
  PointCloud r;
  DecodePoints(data.data(), c.size(), layout, c.stamp_ns, "", &r);
  EXPECT_EQ(r.times_ns, c.times_ns);
  EXPECT_THROW(ParseTimeUnit("sec"), std::invalid_argument);
  EXPECT_EQ(ParseStampAt("end"), StampAt::kScanEnd);
  EXPECT_EQ(ParseTimeReference("absolute"), TimeReference::kAbsolute);
}

TEST(PointFields, AzimuthRecoveryFollowsAClockwiseSweep) {
  // Points every 10° clockwise from +y (azimuth 90°): one revolution = 0.1 s.
  PointCloud c;
  c.stamp_ns = 1'000'000'000;
  for (int k = 0; k < 36; ++k) {
    const double a = M_PI / 2 - k * M_PI / 18;
    c.points.emplace_back(10 * std::cos(a), 10 * std::sin(a), 0.0);
  }
  FillTimesFromAzimuth(&c, StampAt::kScanStart, 100'000'000);
  for (int k = 0; k < 36; ++k) {
    EXPECT_NEAR(double(c.times_ns[k] - c.stamp_ns), k * 100'000'000.0 / 36, 1.0) << k;
  }
  FillTimesFromAzimuth(&c, StampAt::kScanEnd, 100'000'000);
  EXPECT_EQ(c.times_ns.front(), c.stamp_ns - 100'000'000);
  EXPECT_LT(c.times_ns.back(), c.stamp_ns);
}

}  // namespace
}  // namespace ctlio::io
