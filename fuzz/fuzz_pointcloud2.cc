// Structure-aware fuzzing of the PointCloud2 decoder (pointcloud2.h, point_layout_check.h,
// ros_wire_check.h). The input is not a message but a recipe: FuzzedDataProvider reads a list of
// edits to the DECODED fields of one valid message — point_step, width, height, row_step, each
// field's name, offset, datatype and count, the field list, the data length and bytes, the byte
// order — and, after serialisation, to the lengths of the wire format (frame_id, fields, names,
// data). Raw-byte mutation of a bag almost never reaches these fields consistently; here every
// input is a plausible message with a few wrong numbers.
//
// The valid message is the simulator's first scan in the Ouster layout (the Newer College bags'),
// subsampled to 64 points; an empty input decodes it unchanged. Invariants (a violation traps):
//   * a message that decodes holds height × row_step bytes and every declared point is either in
//     the cloud or counted as dropped;
//   * bytes that pass the wire check deserialise without an exception;
// and, under -rss_limit_mb / -malloc_limit_mb, nothing allocates from a count the bytes cannot
// hold.
#include <fuzzer/FuzzedDataProvider.h>
#include <ros/serialization.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "ctlio/io/newer_college.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/ros_wire_check.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "fuzz_common.h"

namespace {

using namespace ctlio;

const sensor_msgs::PointCloud2& BaseMessage() {
  static const sensor_msgs::PointCloud2 msg = [] {
    sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 0);
    c.duration_s = 0.15;
    c.lidar.beams = 4;
    c.lidar.firing_decimation = 300;
    c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;
    c.imu_from_lidar = io::NewerCollegeImuFromLidar();
    sim::SimulatedSource source(c);
    io::ScanFrame f;
    if (!source.Next(&f)) __builtin_trap();
    io::PointCloud cloud;
    cloud.stamp_ns = f.start_ns;
    for (size_t i = 0; i < f.cloud.size() && cloud.size() < 64; ++i) {
      cloud.points.push_back(f.cloud.points[i]);
      cloud.times_ns.push_back(f.cloud.times_ns[i]);
    }
    uint32_t step = 0;
    const auto fields = io::OusterFields(&step);
    io::TimeConvention t;
    t.field = "t";
    return io::EncodePointCloud2(cloud, fields, step, t, "os_lidar");
  }();
  return msg;
}

// A 32-bit value near the interesting ones: 0, 1, the current value ± a little, the extremes.
uint32_t Value32(FuzzedDataProvider& in, uint32_t current) {
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0:
      return in.PickValueInArray<uint32_t>({0u, 1u, 0x7FFFFFFFu, 0x80000000u, 0xFFFFFFFFu});
    case 1:
      return current + in.ConsumeIntegralInRange<int32_t>(-16, 16);
    case 2:
      return current * in.ConsumeIntegralInRange<uint32_t>(0, 1024);
    default:
      return in.ConsumeIntegral<uint32_t>();
  }
}

void EditFields(FuzzedDataProvider& in, sensor_msgs::PointCloud2* m) {
  const int edits = in.ConsumeIntegralInRange<int>(0, 12);
  for (int e = 0; e < edits && in.remaining_bytes() > 0; ++e) {
    sensor_msgs::PointField* f =
        m->fields.empty() ? nullptr
                          : &m->fields[in.ConsumeIntegralInRange<size_t>(0, m->fields.size() - 1)];
    switch (in.ConsumeIntegralInRange<int>(0, 13)) {
      case 0:
        m->point_step = Value32(in, m->point_step);
        break;
      case 1:
        m->width = Value32(in, m->width);
        break;
      case 2:
        m->height = Value32(in, m->height);
        break;
      case 3:
        m->row_step = Value32(in, m->row_step);
        break;
      case 4:
        if (f) f->offset = Value32(in, f->offset);
        break;
      case 5:
        if (f) f->datatype = in.ConsumeIntegral<uint8_t>();
        break;
      case 6:
        if (f) f->count = Value32(in, f->count);
        break;
      case 7:
        if (f) {
          f->name = in.PickValueInArray<const char*>({"x", "y", "z", "t", "time", "timestamp",
                                                      "offset_time", "intensity", "ring", "tag",
                                                      "line", "range", ""});
        }
        break;
      case 8:
        if (f) m->fields.erase(m->fields.begin() + (f - m->fields.data()));
        break;
      case 9:
        if (f && m->fields.size() < 64) m->fields.push_back(*f);
        break;
      case 10: {
        // A data length near the consistent one, or anything up to twice the data.
        const size_t n = m->data.size();
        if (in.ConsumeBool()) {
          const long d = in.ConsumeIntegralInRange<long>(-32, 32);
          m->data.resize(size_t(std::max<long>(0, long(n) + d)));
        } else {
          m->data.resize(in.ConsumeIntegralInRange<size_t>(0, 2 * n + 64));
        }
        break;
      }
      case 11:
        m->is_bigendian = in.ConsumeBool();
        break;
      case 12: {
        // A value written into a point: NaN, Inf, huge or random bytes.
        if (m->data.size() < 8) break;
        const size_t at = in.ConsumeIntegralInRange<size_t>(0, m->data.size() - 8);
        const double v = in.PickValueInArray<double>({std::numeric_limits<double>::quiet_NaN(),
                                                      std::numeric_limits<double>::infinity(),
                                                      1e300, -1e30, 0.0});
        if (in.ConsumeBool()) {
          const float fv = float(v);
          std::memcpy(m->data.data() + at, &fv, 4);
        } else {
          std::memcpy(m->data.data() + at, &v, 8);
        }
        break;
      }
      case 13:
        m->header.stamp.sec = in.ConsumeIntegral<uint32_t>();
        break;
    }
  }
}

std::vector<uint8_t> Serialize(const sensor_msgs::PointCloud2& m) {
  std::vector<uint8_t> bytes(ros::serialization::serializationLength(m));
  ros::serialization::OStream out(bytes.data(), uint32_t(bytes.size()));
  ros::serialization::serialize(out, m);
  return bytes;
}

// Overwrites one length of the wire format (offsets as the format lays them out, no padding).
void EditWire(FuzzedDataProvider& in, const sensor_msgs::PointCloud2& m,
              std::vector<uint8_t>* bytes) {
  std::vector<size_t> lengths = {12};  // header frame_id
  size_t at = 16 + m.header.frame_id.size() + 8;
  lengths.push_back(at);  // fields count
  at += 4;
  for (const auto& f : m.fields) {
    lengths.push_back(at);  // field name
    at += 4 + f.name.size() + 9;
  }
  lengths.push_back(at + 9);  // data length
  const int edits = in.ConsumeIntegralInRange<int>(0, 3);
  for (int e = 0; e < edits && in.remaining_bytes() > 0; ++e) {
    const size_t pos = lengths[in.ConsumeIntegralInRange<size_t>(0, lengths.size() - 1)];
    if (pos + 4 > bytes->size()) continue;
    uint32_t v;
    std::memcpy(&v, bytes->data() + pos, 4);
    v = Value32(in, v);
    std::memcpy(bytes->data() + pos, &v, 4);
  }
  if (in.ConsumeBool() && !bytes->empty()) {
    bytes->resize(in.ConsumeIntegralInRange<size_t>(0, bytes->size()));  // truncated
  }
}

void Decode(const sensor_msgs::PointCloud2& m, bool ignore_time) {
  io::TimeFieldOptions o;
  if (ignore_time) o.field = "none";
  io::PointCloud c;
  try {
    c = io::DecodePointCloud2(m, o, "");
  } catch (const std::exception&) {
    return;
  }
  const uint64_t declared = uint64_t(m.width) * m.height;
  if (m.data.size() != uint64_t(m.height) * m.row_step) __builtin_trap();
  if (c.size() + c.dropped_non_finite != declared) __builtin_trap();
  if (c.has_times() && c.times_ns.size() != c.size()) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::QuietLogging();
  BaseMessage();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  sensor_msgs::PointCloud2 m = BaseMessage();
  EditFields(in, &m);
  const bool ignore_time = in.ConsumeBool();
  Decode(m, ignore_time);
  // The same message through the wire: lengths edited, then checked, deserialised and decoded.
  std::vector<uint8_t> bytes = Serialize(m);
  EditWire(in, m, &bytes);
  try {
    io::CheckPointCloud2Wire(bytes.data(), bytes.size(), "");
  } catch (const std::exception&) {
    return 0;
  }
  sensor_msgs::PointCloud2 back;
  try {
    ros::serialization::IStream stream(bytes.data(), uint32_t(bytes.size()));
    ros::serialization::deserialize(stream, back);
  } catch (...) {
    __builtin_trap();  // the wire check let through bytes the deserialiser cannot read
  }
  Decode(back, ignore_time);
  return 0;
}
