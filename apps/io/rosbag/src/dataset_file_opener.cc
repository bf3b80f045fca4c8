// Registers the bag reader as OpenDataset's file opener (dataset.h), so that a program linking
// ctlio::io_rosbag opens `x.bag`, a ROS 2 bag folder, `.mcap` or `.db3` with OpenDataset as
// ctlio_odometry does without --format (BagSource detects which): the
// only PointCloud2 and Imu topics (or a preset's), the extrinsic from /tf_static or the preset.
//
// A static library's object is linked only when something references it; nothing calls into
// this file, so the library's link interface names `ctlio_io_rosbag_file_opener` undefined
// (LINKER:--undefined, apps/io/rosbag/CMakeLists.txt), which pulls it in with its initializer.
#include <memory>
#include <string>

#include "ctlio/io/dataset.h"
#include "ctlio/io/rosbag_source.h"

namespace ctlio::io {
namespace {

std::unique_ptr<DataSource> OpenBag(const std::string& path, int64_t max_imu_gap_error_ns) {
  RosbagOptions options;
  options.max_imu_gap_ns = max_imu_gap_error_ns;
  return std::make_unique<RosbagSource>(path, options);
}

int Register() {
  RegisterDatasetFileOpener(&OpenBag);
  return 1;
}

}  // namespace
}  // namespace ctlio::io

extern "C" {
// Referenced by name from the link interface only; its initializer does the registration.
extern const int ctlio_io_rosbag_file_opener;
const int ctlio_io_rosbag_file_opener = ctlio::io::Register();
}
