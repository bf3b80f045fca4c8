// The bad-input classes (docs/user-guide/bad-input.md) in the ROS 2 layout: the same defects that
// input_validation_test.cc, point_time_test.cc and reader_checks_test.cc put into ROS 1 bags and
// folders, put into the CDR messages of a ROS 2 bag (edited after decoding, encoded again), must
// get the same answer — the same error naming the bag, topic and message, or the same counted
// recovery — since both backends hand their decoded messages to one BagSource.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>

#include "common/expect_error.h"
#include "common/warning_sink.h"
#include "ctlio/io/cdr_messages.h"
#include "ctlio/io/warning_limiter.h"
#include "io/ros2_memory_bag.h"

namespace ctlio::io {
namespace {

using ::ctlio::testing::ExpectError;
using ::ctlio::testing::WarningSink;
using ros2_test::MemoryBag;
using ros2_test::Read;
using ros2_test::ReadAll;
using ros2_test::SmallBag;
using ros2_test::TopicIndex;

constexpr char kPoints[] = "/os_cloud_node/points";
constexpr char kImu[] = "/os_cloud_node/imu";

// Decodes the n-th message (from 1) of `topic`, lets `edit` change it and encodes it again.
template <class Msg>
void Edit(MemoryBag* bag, const std::string& topic, size_t n,
          const std::function<void(Msg*)>& edit) {
  const size_t index = TopicIndex(*bag, topic);
  ASSERT_NE(index, SIZE_MAX) << topic;
  size_t seen = 0;
  for (ros2::Ros2Message& m : bag->messages) {
    if (m.topic != index || ++seen != n) continue;
    Msg msg;
    ros2::DecodeCdr(m.data.data(), m.data.size(), "", &msg);
    edit(&msg);
    m.data = ros2::EncodeCdr(msg);
    return;
  }
  FAIL() << topic << " has no message " << n;
}

void EditCloud(MemoryBag* bag, size_t n, const std::function<void(sensor_msgs::PointCloud2*)>& f) {
  Edit<sensor_msgs::PointCloud2>(bag, kPoints, n, f);
}

const sensor_msgs::PointField& Field(const sensor_msgs::PointCloud2& m, const std::string& name) {
  for (const auto& f : m.fields) {
    if (f.name == name) return f;
  }
  throw std::runtime_error("no field " + name);
}

// Reads every frame (and the ground truth) of the bag; any error escapes.
std::vector<ScanFrame> ReadEverything(const MemoryBag& bag,
                                      std::unique_ptr<BagSource>* out = nullptr) {
  auto s = Read(bag);
  auto frames = ReadAll(*s);
  s->GroundTruth();
  if (out) *out = std::move(s);
  return frames;
}

TEST(Ros2BadInput, ThePointLayoutDefectsAreErrorsNamingTheMessage) {
  struct Case {
    const char* name;
    std::function<void(sensor_msgs::PointCloud2*)> corrupt;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {"point_step_0", [](auto* m) { m->point_step = 0; }, "point_step is 0 for"},
      {"field_past_step",
       [](auto* m) {
         for (auto& f : m->fields) {
           if (f.name == "t") f.offset = m->point_step - 2;
         }
       },
       "field 't' ends past the point step"},
      {"unknown_datatype",
       [](auto* m) {
         for (auto& f : m->fields) {
           if (f.name == "t") f.datatype = 42;
         }
       },
       "field 't' has an unknown datatype"},
      {"data_shorter", [](auto* m) { m->data.resize(m->data.size() - 5); }, "data holds"},
      {"row_step_short", [](auto* m) { m->row_step = m->point_step; }, "row_step"},
      // A huge width over the same bytes: refused before anything is sized from it.
      {"huge_width",
       [](auto* m) {
         m->width = 50'000'000;
         m->row_step = m->width * m->point_step;
       },
       "data holds"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    MemoryBag bag = SmallBag();
    EditCloud(&bag, 2, c.corrupt);
    ExpectError([&] { ReadEverything(bag); },
                {std::string("mem: topic ") + kPoints + ", message 2", c.needle});
  }
}

TEST(Ros2BadInput, ANonFiniteOrZeroTfStaticQuaternionIsAnErrorNamingTheMessage) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* name;
    std::function<void(geometry_msgs::Transform*)> corrupt;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {"nan_w", [&](auto* t) { t->rotation.w = nan; }, "quaternion is not finite"},
      {"inf_t", [](auto* t) { t->translation.y = std::numeric_limits<double>::infinity(); },
       "translation is not finite"},
      {"zero_q", [](auto* t) { t->rotation.w = t->rotation.x = t->rotation.y = t->rotation.z = 0; },
       "|q|^2 = 0"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    MemoryBag bag = SmallBag();
    Edit<tf2_msgs::TFMessage>(&bag, "/tf_static", 1, [&](tf2_msgs::TFMessage* m) {
      ASSERT_FALSE(m->transforms.empty());
      for (auto& e : m->transforms) c.corrupt(&e.transform);
    });
    ExpectError([&] { Read(bag); }, {"mem: topic /tf_static, message 1", c.needle});
  }
}

TEST(Ros2BadInput, EmptyAndAllNonFiniteScansAreHandedOnAndCounted) {
  MemoryBag bag = SmallBag();
  const size_t n = ReadAll(*Read(bag)).size();
  ASSERT_GE(n, 5u);
  EditCloud(&bag, 2, [](sensor_msgs::PointCloud2* m) {
    m->width = 0;
    m->row_step = 0;
    m->data.clear();
  });
  EditCloud(&bag, 3, [](sensor_msgs::PointCloud2* m) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const uint32_t x = Field(*m, "x").offset;
    for (size_t i = 0; i + m->point_step <= m->data.size(); i += m->point_step) {
      std::memcpy(m->data.data() + i + x, &nan, 4);
    }
  });
  WarningSink sink;
  std::unique_ptr<BagSource> s;
  const auto frames = ReadEverything(bag, &s);
  ASSERT_EQ(frames.size(), n);  // nothing aborted, nothing left out
  EXPECT_EQ(s->unusable_scans(), 2u);
  EXPECT_TRUE(frames[1].cloud.points.empty());
  EXPECT_TRUE(frames[2].cloud.points.empty());
  EXPECT_GT(frames[1].end_ns, frames[1].start_ns);  // the nominal interval
  EXPECT_TRUE(sink.Has(std::string("mem: topic ") + kPoints + ", message 2: 0 usable points"));
  EXPECT_TRUE(sink.Has(std::string("mem: topic ") + kPoints + ", message 3: 0 usable points"));
}

TEST(Ros2BadInput, PerPointTimesThatCannotBeASweepAreRescaledAndOutliersDropped) {
  // 't' in microseconds where the driver writes nanoseconds: rescaled by 1000, with a warning.
  MemoryBag bag = SmallBag();
  EditCloud(&bag, 2, [](sensor_msgs::PointCloud2* m) {
    const auto& t = Field(*m, "t");
    ASSERT_EQ(t.datatype, sensor_msgs::PointField::UINT32);
    for (size_t i = 0; i + m->point_step <= m->data.size(); i += m->point_step) {
      uint32_t v;
      std::memcpy(&v, m->data.data() + i + t.offset, 4);
      v /= 1000;
      std::memcpy(m->data.data() + i + t.offset, &v, 4);
    }
  });
  {
    WarningSink sink;
    std::unique_ptr<BagSource> s;
    const auto frames = ReadEverything(bag, &s);
    EXPECT_EQ(s->retimed_scans(), 1u);
    EXPECT_TRUE(sink.Has(std::string("mem: topic ") + kPoints + ", message 2: time field"));
    EXPECT_TRUE(sink.Has("unit factor 1000"));
    // The rescaled sweep spans most of a period again (not 1/1000 of it).
    EXPECT_GT(frames[1].end_ns - frames[1].start_ns, 50'000'000);
  }
  // 't' holding the ring number, and every point at the stamp: times from the azimuth.
  for (const std::string defect : {"ring_as_t", "all_at_stamp"}) {
    SCOPED_TRACE(defect);
    bag = SmallBag();
    EditCloud(&bag, 2, [&](sensor_msgs::PointCloud2* m) {
      const auto& t = Field(*m, "t");
      const auto& ring = Field(*m, "ring");
      const bool u8 = ring.datatype == sensor_msgs::PointField::UINT8;
      ASSERT_TRUE(u8 || ring.datatype == sensor_msgs::PointField::UINT16);
      for (size_t i = 0; i + m->point_step <= m->data.size(); i += m->point_step) {
        uint16_t r = 0;
        std::memcpy(&r, m->data.data() + i + ring.offset, u8 ? 1 : 2);
        const uint32_t v = defect == "ring_as_t" ? r : 0;
        std::memcpy(m->data.data() + i + t.offset, &v, 4);
      }
    });
    WarningSink sink;
    std::unique_ptr<BagSource> s;
    const auto frames = ReadEverything(bag, &s);
    EXPECT_EQ(s->retimed_scans(), 1u);
    EXPECT_TRUE(sink.Has(std::string("mem: topic ") + kPoints + ", message 2: time field"));
    EXPECT_TRUE(sink.Has("from the azimuth"));
    EXPECT_GT(frames[1].end_ns - frames[1].start_ns, 50'000'000);
  }
  // Five points three seconds after the stamp: dropped and counted, the scan not stretched.
  bag = SmallBag();
  EditCloud(&bag, 3, [](sensor_msgs::PointCloud2* m) {
    const auto& t = Field(*m, "t");
    const uint32_t far = 3'000'000'000u;
    for (size_t k = 0; k < 5; ++k)
      std::memcpy(m->data.data() + k * m->point_step + t.offset, &far, 4);
  });
  WarningSink sink;
  std::unique_ptr<BagSource> s;
  const auto frames = ReadEverything(bag, &s);
  EXPECT_EQ(s->points_outside_sweep(), 5u);
  EXPECT_LT(frames[2].end_ns - frames[2].start_ns, 200'000'000);
  EXPECT_TRUE(sink.Has(std::string("mem: topic ") + kPoints + ", message 3: dropped 5 of"));
}

// 8- and 16-bit time fields wrap every 256 ns / 65.5 µs: a driver that narrowed 't' keeps only
// its low bits (the low bytes of the little-endian uint32, so only the datatype changes here).
TEST(Ros2BadInput, EightAndSixteenBitTimeFieldsAreRecoveredFromTheAzimuthWithTheirReason) {
  for (const uint8_t type : {sensor_msgs::PointField::UINT8, sensor_msgs::PointField::UINT16}) {
    const bool u8 = type == sensor_msgs::PointField::UINT8;
    SCOPED_TRACE(u8 ? "uint8" : "uint16");
    MemoryBag bag = SmallBag();
    EditCloud(&bag, 2, [&](sensor_msgs::PointCloud2* m) {
      for (auto& f : m->fields) {
        if (f.name == "t") {
          ASSERT_EQ(f.datatype, sensor_msgs::PointField::UINT32);
          f.datatype = type;
        }
      }
    });
    WarningSink sink;
    std::unique_ptr<BagSource> s;
    const auto frames = ReadEverything(bag, &s);
    EXPECT_EQ(s->retimed_scans(), 1u);
    EXPECT_EQ(s->unusable_scans(), 0u);
    EXPECT_TRUE(sink.Has(std::string("mem: topic ") + kPoints + ", message 2: time field"));
    EXPECT_TRUE(sink.Has(u8 ? "(a uint8 field holds at most 255 units"
                            : "(a uint16 field holds at most 65535 units"))
        << sink.text();
    // The recovered sweep spans most of a period (the wrapped times spanned 256 ns / 65.5 µs).
    EXPECT_GT(frames[1].end_ns - frames[1].start_ns, 50'000'000);
  }
}

// A preset recognised from the topic names while the bag's /tf_static does not connect the IMU
// and lidar frames is a guess, and the origin and the log say so; the connected tree is not.
TEST(Ros2BadInput, APresetOverATfTreeThatDoesNotConnectTheFramesIsAGuess) {
  {
    WarningSink sink;
    const auto s = Read(SmallBag());
    EXPECT_THAT(s->ExtrinsicOrigin(), ::testing::HasSubstr("the bag's /tf_static ("));
    EXPECT_THAT(sink.text(), ::testing::Not(::testing::HasSubstr("guess")));
  }
  MemoryBag bag = SmallBag();
  Edit<tf2_msgs::TFMessage>(&bag, "/tf_static", 1, [](tf2_msgs::TFMessage* m) {
    ASSERT_FALSE(m->transforms.empty());
    for (auto& e : m->transforms) {
      e.header.frame_id = "base_link";
      e.child_frame_id = "os_sensor";
    }
  });
  WarningSink sink;
  const auto s = Read(bag);
  EXPECT_THAT(s->ExtrinsicOrigin(),
              ::testing::HasSubstr("preset (recognised from the topic names) — a guess: the "
                                   "bag's /tf_static does not connect the IMU frame"));
  EXPECT_THAT(sink.text(), ::testing::HasSubstr("mem: T_imu_lidar from the"));
  // The preset's extrinsic is the one used (the topic names are the 2021 dataset's).
  bool used = false;
  for (const BagPreset& p : BagPresets()) {
    if (p.name == "newer_college_2021")
      used = s->ImuFromLidar().Matrix().isApprox(p.imu_from_lidar.Matrix());
  }
  EXPECT_TRUE(used);
}

TEST(Ros2BadInput, ANonFiniteGroundTruthPoseIsAnErrorNamingTheMessage) {
  MemoryBag bag = SmallBag();
  Edit<nav_msgs::Odometry>(&bag, "/ground_truth", 2, [](nav_msgs::Odometry* m) {
    m->pose.pose.position.x = std::numeric_limits<double>::quiet_NaN();
  });
  ExpectError([&] { ReadEverything(bag); },
              {"mem: topic /ground_truth, message 2", "ground-truth pose is not finite"});
  bag = SmallBag();
  Edit<nav_msgs::Odometry>(&bag, "/ground_truth", 3, [](nav_msgs::Odometry* m) {
    m->pose.pose.orientation.w = m->pose.pose.orientation.x = 0.0;
    m->pose.pose.orientation.y = m->pose.pose.orientation.z = 0.0;
  });
  ExpectError([&] { ReadEverything(bag); }, {"mem: topic /ground_truth, message 3", "quaternion"});
}

TEST(Ros2BadInput, ImuTimeBackwardsIsAnErrorAndADuplicateIsCountedAsInTheFolders) {
  MemoryBag bag = SmallBag();
  int64_t fifth = 0;
  Edit<sensor_msgs::Imu>(&bag, kImu, 5,
                         [&](sensor_msgs::Imu* m) { fifth = int64_t(m->header.stamp.toNSec()); });
  Edit<sensor_msgs::Imu>(&bag, kImu, 6, [&](sensor_msgs::Imu* m) {
    m->header.stamp.fromNSec(uint64_t(fifth - 1'000'000));
  });
  ExpectError([&] { ReadEverything(bag); },
              {std::string("mem: topic ") + kImu + ", message 6", "IMU time goes backwards"});

  bag = SmallBag();
  Edit<sensor_msgs::Imu>(&bag, kImu, 6,
                         [&](sensor_msgs::Imu* m) { m->header.stamp.fromNSec(uint64_t(fifth)); });
  {
    WarningSink sink;
    std::unique_ptr<BagSource> s;
    ReadEverything(bag, &s);
    bool counted = false;
    for (const InputDefect& d : s->InputDefects()) {
      if (d.kind == "duplicate IMU time") {
        counted = true;
        EXPECT_EQ(d.count, 1u);
        EXPECT_THAT(d.first, ::testing::HasSubstr(std::string("topic ") + kImu + ", message 6"));
      }
    }
    EXPECT_TRUE(counted) << "the duplicate is not among the run's input defects";
  }
  // Under --strict the recovery is an error naming the message.
  WarningLimiter::SetStrict(true);
  ExpectError([&] { ReadEverything(bag); },
              {std::string("topic ") + kImu + ", message 6", "duplicate IMU time", "--strict"});
  WarningLimiter::SetStrict(false);
}

}  // namespace
}  // namespace ctlio::io
