// The drivers' cloud layouts (driver_conventions.h) are detected by point_fields.h as the
// convention they are written with: each writer's layout reads back as its driver's.
#include "ctlio/io/driver_conventions.h"

#include <gtest/gtest.h>

namespace ctlio::io {
namespace {

TEST(DriverConventions, EachLayoutIsDetectedAsItsDriver) {
  for (PointFormat f : {PointFormat::kOuster, PointFormat::kVelodyne, PointFormat::kHesai,
                        PointFormat::kLivoxPointCloud2, PointFormat::kLivoxCustomMsg}) {
    SCOPED_TRACE(PointFormatName(f));
    uint32_t step = 0;
    const std::vector<PointField> fields = DriverFields(f, &step);
    const PointLayout layout = DetectPointLayout(fields, step, {}, "");
    const TimeConvention expected = DriverTime(f);
    ASSERT_TRUE(layout.time.has_value());
    EXPECT_EQ(layout.convention.field, expected.field);
    EXPECT_EQ(layout.convention.driver, expected.driver);
    EXPECT_EQ(layout.convention.unit, expected.unit);
    EXPECT_EQ(layout.convention.reference, expected.reference);
    EXPECT_EQ(layout.convention.stamp_at, expected.stamp_at);
    for (const PointField& p : fields) EXPECT_LE(p.offset + FieldDatatypeSize(p.datatype), step);
  }
  uint32_t step = 0;
  DriverFields(PointFormat::kVelodyne, &step);
  EXPECT_EQ(step, 22u);  // velodyne_pointcloud's packed PointXYZIRT
  DriverFields(PointFormat::kLivoxPointCloud2, &step);
  EXPECT_EQ(step, 26u);  // livox_ros_driver2's packed LivoxPointXyzrtlt
  EXPECT_EQ(DriverConventionOf(PointFormat::kVelodyne).lidar_topic, "/velodyne_points");
  EXPECT_EQ(DriverConventionOf(PointFormat::kHesai).lidar_topic, "/hesai/pandar");
  EXPECT_EQ(DriverConventionOf(PointFormat::kLivoxCustomMsg).imu_topic, "/livox/imu");
  EXPECT_EQ(DriverConventionOf(PointFormat::kLivoxCustomMsg).accel_unit, 9.80665);
}

}  // namespace
}  // namespace ctlio::io
