#include "ctlio/io/rosbag_source.h"

#include <glog/logging.h>
#include <nav_msgs/Odometry.h>
#include <ros/exception.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <queue>

#include "ctlio/io/bag_structure.h"
#include "ctlio/io/extrinsic_check.h"
#include "ctlio/io/ground_truth_check.h"
#include "ctlio/io/livox_custom_msg.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/point_time_check.h"
#include "ctlio/io/pointcloud2.h"
#include "ctlio/io/ros_wire_check.h"
#include "ctlio/io/warning_limiter.h"

namespace ctlio::io {
namespace {

constexpr char kPointCloud2[] = "sensor_msgs/PointCloud2";
constexpr char kImu[] = "sensor_msgs/Imu";
// Scans held back waiting for IMU samples up to their end before they are handed out anyway
// (the odometry then reports the IMU gap): bounds the memory when the IMU topic stops early.
constexpr size_t kMaxPendingScans = 50;

// One /tf_static transform with where it was read (bag, topic, message index), checked when the
// search below composes it (extrinsic_check.h): a NaN or zero quaternion on the path from the IMU
// to the lidar is an error naming the message, one on an unrelated branch of the tree is not used.
struct StaticEdge {
  geometry_msgs::TransformStamped msg;
  std::string where;
  SE3 T() const {
    const auto& q = msg.transform.rotation;
    const auto& t = msg.transform.translation;
    return CheckedExtrinsic(
        q.w, q.x, q.y, q.z, Vec3(t.x, t.y, t.z),
        where + "transform " + msg.header.frame_id + " → " + msg.child_frame_id + ": ");
  }
};

// T_from_to over the static transform tree (edges parent → child hold T_parent_child), by a
// breadth-first search that composes along the path; false if the frames are not connected.
bool FindStaticTransform(const std::vector<StaticEdge>& edges, const std::string& from,
                         const std::string& to, SE3* T) {
  std::map<std::string, SE3> reached{{from, SE3()}};
  std::queue<std::string> open;
  open.push(from);
  while (!open.empty()) {
    const std::string u = open.front();
    open.pop();
    const SE3 T_from_u = reached.at(u);
    if (u == to) {
      *T = T_from_u;
      return true;
    }
    for (const StaticEdge& edge : edges) {
      const auto& e = edge.msg;
      if (e.header.frame_id == u && !reached.count(e.child_frame_id)) {
        reached[e.child_frame_id] = T_from_u * edge.T();
        open.push(e.child_frame_id);
      } else if (e.child_frame_id == u && !reached.count(e.header.frame_id)) {
        reached[e.header.frame_id] = T_from_u * edge.T().Inverse();
        open.push(e.header.frame_id);
      }
    }
  }
  return false;
}

// The message as M; a message whose type or md5sum is not M's (a corrupt or foreign connection
// header) is an error, not a null pointer.
template <class M>
boost::shared_ptr<M> Instantiate(const rosbag::MessageInstance& m, const std::string& where) {
  boost::shared_ptr<M> msg = m.instantiate<M>();
  if (!msg) {
    throw std::runtime_error(where + "message on " + m.getTopic() + " is not a " +
                             ros::message_traits::datatype<M>() + " (type " + m.getDataType() +
                             ", md5sum " + m.getMD5Sum() + ")");
  }
  return msg;
}

std::string PickTopic(const std::map<std::string, std::string>& topics, const std::string& type,
                      const std::string& given, const std::string& preset_topic,
                      const std::string& flag, const std::string& path) {
  if (!given.empty()) {
    const auto it = topics.find(given);
    if (it == topics.end()) {
      std::string all;
      for (const auto& [t, ty] : topics) all += "\n  " + t + " (" + ty + ")";
      throw std::runtime_error(path + ": no topic '" + given + "' (--" + flag +
                               "); the bag has:" + all);
    }
    if (it->second != type) {
      throw std::runtime_error(path + ": topic '" + given + "' is " + it->second + ", not " + type);
    }
    return given;
  }
  if (!preset_topic.empty() && topics.count(preset_topic)) return preset_topic;
  std::vector<std::string> candidates;
  for (const auto& [t, ty] : topics) {
    if (ty == type) candidates.push_back(t);
  }
  if (candidates.size() == 1) return candidates.front();
  std::string list;
  for (const auto& c : candidates) list += " " + c;
  throw std::runtime_error(path + ": " + std::to_string(candidates.size()) + " " + type +
                           " topics" + (candidates.empty() ? "" : ":" + list) + "; choose with --" +
                           flag);
}

}  // namespace

const std::vector<BagPreset>& BagPresets() {
  // Both are Ouster sensors through ouster_ros (`t` uint32 ns since the scan-start stamp).
  // 2020: the published T_imu_lidar of SPEC §6 (cloud in the lidar frame, rotated by π about z).
  // 2021: the cloud is in the Ouster sensor frame, nearly aligned with the IMU; T_imu_lidar as used
  // for this dataset by the evalio benchmark's loader (imu_T_lidar: q_xyzw = (0.0032925,
  // −0.004627, −0.0024302, 0.99998), t = (0.013801, −0.012207, −0.01514) m). Neither was run on a
  // real bag here; a bag's /tf_static takes precedence.
  static const std::vector<BagPreset> presets = {
      {"newer_college_2020", "/os1_cloud_node/points", "/os1_cloud_node/imu",
       NewerCollegeImuFromLidar(), "Newer College 2020 (Ouster OS1-64 and its IMU)"},
      {"newer_college_2021", "/os_cloud_node/points", "/os_cloud_node/imu",
       SE3(Eigen::Quaterniond(0.99998, 0.0032925, -0.004627, -0.0024302)
               .normalized()
               .toRotationMatrix(),
           Vec3(0.013801, -0.012207, -0.01514)),
       "Newer College 2021 (Ouster 128-beam and its IMU)"},
  };
  return presets;
}

bool IsRosbagFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  std::ifstream in(path, std::ios::binary);
  char magic[13] = {};
  in.read(magic, 13);
  return in.gcount() == 13 && std::string(magic, 13) == "#ROSBAG V2.0\n";
}

struct RosbagSource::Impl {
  std::string path;
  RosbagOptions options;
  const BagPreset* preset = nullptr;
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> view;
  rosbag::View::iterator it;
  bool exhausted = false;
  std::string lidar_topic, imu_topic, lidar_frame, imu_frame;
  bool custom_msg = false;  // the lidar topic is livox_ros_driver2/CustomMsg (livox_custom_msg.h)
  size_t num_scans = 0, lidar_messages = 0, imu_messages = 0, next_index = 0;
  std::deque<ScanFrame> pending;
  std::vector<ImuSample> imu;  // samples not yet handed out
  int64_t last_imu_ns = INT64_MIN, last_scan_start_ns = INT64_MIN;
  size_t duplicates = 0;
  size_t unusable_scans = 0;        // handed on empty or with their nominal interval (AddScan)
  size_t retimed_scans = 0;         // per-point times rescaled or replaced (point_time_check.h)
  size_t points_outside_sweep = 0;  // dropped: timed over a period from the stamp
  // Header stamps of the lidar messages: the last one and the last spacing (the scan period as
  // the bag shows it, for the nominal interval of an unusable scan).
  int64_t last_lidar_stamp_ns = INT64_MIN, last_lidar_spacing_ns = 0;
  uint64_t bytes = 0;
  double accel_norm_sum = 0.0;
  bool azimuth_logged = false;
  SE3 extrinsic;
  std::string extrinsic_origin;  // empty: unknown
  std::vector<StampedPose> ground_truth;
  // Repeated warnings (IMU gaps, unusable scans): the first few in full, then a total at the end.
  std::unique_ptr<WarningLimiter> warnings;

  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(path + ": " + what);
  }
  std::string Where(const std::string& topic, size_t n) const {
    return path + ": topic " + topic + ", message " + std::to_string(n) + ": ";
  }
  void ReadOne();
  void AddImu(const sensor_msgs::Imu& m);
  void AddScan(const sensor_msgs::PointCloud2& m);
};

RosbagSource::RosbagSource(const std::string& path, const RosbagOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.path = path;
  s.options = options;
  s.warnings = std::make_unique<WarningLimiter>(path);
  if (!std::filesystem::is_regular_file(path)) s.Fail("file not found");
  if (!IsRosbagFile(path)) s.Fail("not a ROS 1 bag (no '#ROSBAG V2.0' header)");
  // The bag library trusts the file's lengths and offsets: check them first (bag_structure.h).
  CheckBagStructure(path);
  std::map<std::string, std::string> topics;
  try {
    s.bag.open(path, rosbag::bagmode::Read);
    rosbag::View all(s.bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) topics[c->topic] = c->datatype;
  } catch (const std::exception& e) {
    s.Fail(std::string("cannot read the bag (truncated or corrupted?): ") + e.what());
  }
  if (!options.preset.empty()) {
    for (const BagPreset& p : BagPresets()) {
      if (p.name == options.preset) s.preset = &p;
    }
    if (!s.preset) {
      std::string names;
      for (const BagPreset& p : BagPresets()) names += " " + p.name;
      s.Fail("unknown preset '" + options.preset + "' (known:" + names + ")");
    }
  } else {
    for (const BagPreset& p : BagPresets()) {
      if (topics.count(p.lidar_topic) && topics.count(p.imu_topic)) s.preset = &p;
    }
  }
  s.custom_msg = livox::IsCustomMsgLidar(topics, options.lidar_topic);
  s.lidar_topic =
      PickTopic(topics, s.custom_msg ? livox::kCustomMsgType : kPointCloud2, options.lidar_topic,
                s.preset ? s.preset->lidar_topic : "", "lidar_topic", path);
  s.imu_topic = PickTopic(topics, kImu, options.imu_topic, s.preset ? s.preset->imu_topic : "",
                          "imu_topic", path);
  if (s.preset) LOG(INFO) << path << ": preset " << s.preset->name << " (" << s.preset->note << ")";
  try {
    rosbag::View lidar(s.bag, rosbag::TopicQuery(s.lidar_topic));
    s.num_scans = lidar.size();
    if (lidar.begin() != lidar.end()) {
      s.lidar_frame =
          livox::ReadLidarMessage(*lidar.begin(), s.custom_msg, s.Where(s.lidar_topic, 1))
              .header.frame_id;
    }
    rosbag::View imu(s.bag, rosbag::TopicQuery(s.imu_topic));
    if (imu.begin() != imu.end()) {
      s.imu_frame = Instantiate<sensor_msgs::Imu>(*imu.begin(), path + ": ")->header.frame_id;
    }
    // Extrinsic: /tf_static, then the preset, then a shared frame (header comment).
    std::vector<StaticEdge> edges;
    rosbag::View tf(s.bag, rosbag::TopicQuery("/tf_static"));
    size_t tf_index = 0;
    for (const rosbag::MessageInstance& m : tf) {
      ++tf_index;
      if (!m.isType<tf2_msgs::TFMessage>()) continue;  // (a foreign type: not ours to read)
      const std::string where = s.Where("/tf_static", tf_index);
      const auto msg = ReadCheckedMessage<tf2_msgs::TFMessage>(m, where, CheckTfMessageWire);
      for (const auto& t : msg.transforms) edges.push_back({t, where});
    }
    if (!s.lidar_frame.empty() && !s.imu_frame.empty() &&
        FindStaticTransform(edges, s.imu_frame, s.lidar_frame, &s.extrinsic)) {
      s.extrinsic_origin = "the bag's /tf_static (" + s.imu_frame + " → " + s.lidar_frame + ")";
    } else if (s.preset) {
      s.extrinsic = s.preset->imu_from_lidar;
      s.extrinsic_origin = "the " + s.preset->name + " preset";
      if (!edges.empty()) {
        // The bag carries a tree, but not between these frames: the preset (recognised from the
        // topic names unless --preset) is a guess that the bag is the preset's sensor (issue 40).
        auto frame = [](const std::string& f) {
          return f.empty() ? "(no frame_id)" : "'" + f + "'";
        };
        std::string why = " — a guess: the bag's /tf_static does not connect the IMU frame " +
                          frame(s.imu_frame) + " and the lidar frame " + frame(s.lidar_frame);
        if (options.preset.empty()) why = " (recognised from the topic names)" + why;
        s.extrinsic_origin += why;
        LOG(WARNING) << path << ": T_imu_lidar from " << s.extrinsic_origin
                     << "; give `extrinsic:` in the config if the bag is another sensor's";
      }
    } else if (!s.lidar_frame.empty() && s.lidar_frame == s.imu_frame) {
      s.extrinsic_origin = "identity (lidar and IMU share frame_id '" + s.lidar_frame + "')";
    }
    if (topics.count(options.ground_truth_topic) &&
        topics.at(options.ground_truth_topic) == "nav_msgs/Odometry") {
      rosbag::View gt(s.bag, rosbag::TopicQuery(options.ground_truth_topic));
      size_t gt_messages = 0;
      for (const rosbag::MessageInstance& m : gt) {
        const auto o = Instantiate<nav_msgs::Odometry>(m, path + ": ");
        const geometry_msgs::Pose& p = o->pose.pose;
        // The readers' one rule for ground truth (ground_truth_check.h): a NaN pose is an error
        // naming the message, not an ATE of "nan" on a good run.
        s.ground_truth.push_back(
            {int64_t(o->header.stamp.toNSec()),
             CheckedGroundTruthPose(p.orientation.w, p.orientation.x, p.orientation.y,
                                    p.orientation.z, Vec3(p.position.x, p.position.y, p.position.z),
                                    path + ": topic " + options.ground_truth_topic + ", message " +
                                        std::to_string(++gt_messages) + ": ")});
      }
      std::stable_sort(s.ground_truth.begin(), s.ground_truth.end(),
                       [](const StampedPose& a, const StampedPose& b) { return a.t_ns < b.t_ns; });
    }
    s.view = std::make_unique<rosbag::View>(
        s.bag, rosbag::TopicQuery(std::vector<std::string>{s.lidar_topic, s.imu_topic}));
    s.it = s.view->begin();
    s.exhausted = s.it == s.view->end();
  } catch (const ros::Exception& e) {
    s.Fail(std::string("cannot read the bag (truncated or corrupted?): ") + e.what());
  }
  LOG(INFO) << path << ": lidar " << s.lidar_topic << " (" << s.num_scans << " scans, frame '"
            << s.lidar_frame << "'), IMU " << s.imu_topic << " (frame '" << s.imu_frame << "')";
}

RosbagSource::~RosbagSource() = default;

std::string RosbagSource::Name() const { return "rosbag:" + impl_->path; }
size_t RosbagSource::NumScans() const { return impl_->num_scans; }
const std::string& RosbagSource::lidar_topic() const { return impl_->lidar_topic; }
const std::string& RosbagSource::imu_topic() const { return impl_->imu_topic; }
uint64_t RosbagSource::bytes_read() const { return impl_->bytes; }
size_t RosbagSource::unusable_scans() const { return impl_->unusable_scans; }
size_t RosbagSource::retimed_scans() const { return impl_->retimed_scans; }
size_t RosbagSource::points_outside_sweep() const { return impl_->points_outside_sweep; }

SE3 RosbagSource::ImuFromLidar() const {
  if (impl_->extrinsic_origin.empty()) {
    auto frame = [](const std::string& f) { return f.empty() ? "(no frame_id)" : "'" + f + "'"; };
    impl_->Fail("no lidar → IMU extrinsic: /tf_static does not connect the IMU frame " +
                frame(impl_->imu_frame) + " and the lidar frame " + frame(impl_->lidar_frame) +
                " and no preset applies; give `extrinsic:` in the config or --preset");
  }
  return impl_->extrinsic;
}

std::string RosbagSource::ExtrinsicOrigin() const { return impl_->extrinsic_origin; }

std::optional<std::vector<StampedPose>> RosbagSource::GroundTruth() const {
  if (impl_->ground_truth.empty()) return std::nullopt;
  return impl_->ground_truth;
}

void RosbagSource::Impl::AddImu(const sensor_msgs::Imu& m) {
  ++imu_messages;
  const int64_t t = int64_t(m.header.stamp.toNSec());
  if (t == last_imu_ns) {
    if (duplicates++ == 0) LOG(WARNING) << Where(imu_topic, imu_messages) << "duplicate IMU time";
    return;
  }
  if (t < last_imu_ns) {
    throw std::runtime_error(Where(imu_topic, imu_messages) + "IMU time goes backwards (" +
                             std::to_string(t) + " ns after " + std::to_string(last_imu_ns) +
                             " ns)");
  }
  if (last_imu_ns != INT64_MIN && t - last_imu_ns > options.imu_gap_warning_ns) {
    const double gap = 1e-9 * double(t - last_imu_ns);
    // Opt-in error; by default the samples are handed on and the odometry bridges the hole
    // (docs/user-guide/bad-input.md).
    if (options.max_imu_gap_ns > 0 && t - last_imu_ns > options.max_imu_gap_ns) {
      throw std::runtime_error(Where(imu_topic, imu_messages) + "gap of " + std::to_string(gap) +
                               " s in the IMU (limit " +
                               std::to_string(1e-9 * double(options.max_imu_gap_ns)) + " s)");
    }
    if (warnings->Count("IMU gap",
                        Where(imu_topic, imu_messages) + "gap of " + std::to_string(gap) + " s")) {
      LOG(WARNING) << Where(imu_topic, imu_messages) << "gap of " << gap
                   << " s in the IMU; samples handed on";
    }
  }
  last_imu_ns = t;
  ImuSample s;
  s.t_ns = t;
  s.gyro = Vec3(m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z);
  s.accel = options.accel_scale *
            Vec3(m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z);
  // Plausibility (finiteness, physical range) is the odometry's input gate (ImuBuffer::AddImu),
  // one place for every reader: a non-finite sample is rejected and counted there.
  // sensor_msgs/Imu is m/s², but some drivers publish g (Livox's built-in IMU): a mean specific
  // force near 1 over the first samples is flagged once, with the remedy.
  if (imu_messages <= 200) {
    accel_norm_sum += s.accel.norm();
    if (imu_messages == 200 && accel_norm_sum / 200 > 0.5 && accel_norm_sum / 200 < 1.5) {
      LOG(WARNING) << path << ": " << imu_topic << ": mean |accelerometer| over the first 200 "
                   << "samples is " << accel_norm_sum / 200 << ": the IMU seems to report g, not "
                   << "m/s²; scale it with --imu_accel_scale=9.80665";
    }
  }
  imu.push_back(s);
}

void RosbagSource::Impl::AddScan(const sensor_msgs::PointCloud2& m) {
  const std::string where = Where(lidar_topic, lidar_messages);
  ScanFrame f;
  PointLayout layout;
  f.cloud = DecodePointCloud2(m, options.time, where, &layout);
  if (!layout.time) {
    if (!azimuth_logged) {
      LOG(INFO) << path << ": " << lidar_topic
                << " has no per-point time field (fields: " << DescribeFields(FieldsOf(m))
                << "): times recovered from the azimuth, stamp at "
                << "scan " << (layout.convention.stamp_at == StampAt::kScanStart ? "start" : "end");
      azimuth_logged = true;
    }
    FillTimesFromAzimuth(&f.cloud, layout.convention.stamp_at, options.time.scan_period_ns);
  } else if (lidar_messages == 1) {
    LOG(INFO) << path << ": per-point time " << DescribeConvention(layout.convention);
  }
  const int64_t stamp = f.cloud.stamp_ns;
  if (last_lidar_stamp_ns != INT64_MIN && stamp > last_lidar_stamp_ns) {
    last_lidar_spacing_ns = stamp - last_lidar_stamp_ns;  // no overflow: both are ≥ 0 (ros::Time)
  }
  last_lidar_stamp_ns = stamp;
  if (layout.time) {
    // The same per-point time rules as the folder readers (point_time_check.h, dataset.h). Before
    // the second stamp the period is unknown: twice the nominal one keeps a 5 Hz lidar's sweep.
    const int64_t period = last_lidar_spacing_ns > 0
                               ? last_lidar_spacing_ns
                               : 2 * std::max<int64_t>(options.time.scan_period_ns, 1);
    const PointTimeCheck check = CheckPointTimes(&f.cloud, period);
    if (check.verdict != PointTimeCheck::kSweep) {
      ++retimed_scans;
      const bool azimuth = check.verdict == PointTimeCheck::kNotASweep;
      if (warnings->Count(azimuth ? "per-point times not a sweep" : "per-point times rescaled",
                          where + check.reason)) {
        // An integer field of 8 or 16 bits cannot hold a sweep in ns (it wraps every 256 ns or
        // 65.5 µs): the width is the likely cause, said with the field's type.
        const size_t bytes = FieldDatatypeSize(layout.time->datatype);
        const std::string narrow =
            azimuth && bytes <= 2 && layout.time->datatype != kFloat32 &&
                    layout.time->datatype != kFloat64
                ? " (a " + FieldDatatypeName(layout.time->datatype) + " field holds at most " +
                      std::to_string((1u << (8 * bytes - (layout.time->datatype == kInt8 ||
                                                          layout.time->datatype == kInt16))) -
                                     1) +
                      " units: too narrow for a sweep)"
                : "";
        LOG(WARNING) << where << "time field " << DescribeConvention(layout.convention) << narrow
                     << ": " << check.reason
                     << (azimuth ? "; times recovered from the azimuth instead" : "");
      }
      if (azimuth) {
        FillTimesFromAzimuth(
            &f.cloud, layout.convention.stamp_at,
            last_lidar_spacing_ns > 0 ? last_lidar_spacing_ns : options.time.scan_period_ns);
      }
    }
    // A point timed more than a period (+10 %) from the stamp cannot belong to this sweep (either
    // stamp position, scan start or end); it would stretch the scan over seconds. Dropped and
    // counted, as in the folder readers.
    const int64_t reach = period + period / 10;
    int64_t lo = INT64_MIN, hi = INT64_MAX;
    if (__builtin_sub_overflow(stamp, reach, &lo)) lo = INT64_MIN;
    if (__builtin_add_overflow(stamp, reach, &hi)) hi = INT64_MAX;
    points_outside_sweep +=
        DropPointsOutside(where.substr(0, where.size() - 2), lo, hi, &f.cloud, warnings.get());
  }
  // A stamp at the scan start is the start (DataSource: start_ns = the scan stamp) even when the
  // first returns were dropped; otherwise the earliest point is.
  f.start_ns = f.end_ns = stamp;
  if (f.cloud.has_times() && !f.cloud.points.empty()) {
    const auto [lo, hi] = std::minmax_element(f.cloud.times_ns.begin(), f.cloud.times_ns.end());
    f.start_ns = layout.convention.stamp_at == StampAt::kScanStart ? std::min(stamp, *lo) : *lo;
    f.end_ns = *hi;
  }
  if (f.end_ns <= f.start_ns) {
    // Recovery, as in the folder readers (README "Bad input"): a cloud without usable points
    // (empty, all non-finite) or with every point at one instant gives no interval; it is handed on
    // with its nominal one (one scan period from the stamp, or up to it for a stamp at the scan
    // end; the period is the last stamp spacing, so that the interval ends before the next scan,
    // else scan_period_ns) and the odometry reports it degenerate when it has no points.
    const int64_t period = std::max<int64_t>(
        last_lidar_spacing_ns > 0 ? last_lidar_spacing_ns : options.time.scan_period_ns, 2);
    const bool at_end = layout.convention.stamp_at == StampAt::kScanEnd;
    int64_t lo = stamp, hi = stamp;
    const bool overflow = at_end ? __builtin_sub_overflow(stamp, period - 1, &lo)
                                 : __builtin_add_overflow(stamp, period - 1, &hi);
    if (overflow) {
      throw std::runtime_error(where + "stamp " + std::to_string(stamp) +
                               " ns leaves no room for a scan period");
    }
    ++unusable_scans;
    if (warnings->Count("unusable scan",
                        where + std::to_string(f.cloud.size()) + " usable points")) {
      LOG(WARNING) << where << f.cloud.size() << " usable points (" << f.cloud.dropped_non_finite
                   << " non-finite), " << (f.cloud.points.empty() ? "none" : "all at one instant")
                   << ": handed on with its nominal interval [" << FormatSecondsNs(lo) << ", "
                   << FormatSecondsNs(hi) << "] s (unusable scan " << unusable_scans << ")";
    }
    f.start_ns = lo;
    f.end_ns = hi;
  }
  f.cloud.stamp_ns = f.start_ns;
  if (f.start_ns < last_scan_start_ns) {
    throw std::runtime_error(where + "scan starts before the previous one (scans out of order)");
  }
  last_scan_start_ns = f.start_ns;
  pending.push_back(std::move(f));
}

void RosbagSource::Impl::ReadOne() {
  std::string where = path + ": ";
  try {
    const rosbag::MessageInstance& m = *it;
    bytes += m.size();
    // `where` names the message being read (AddImu advances the IMU count itself), so that a
    // library error names it too, never the one after it.
    if (m.getTopic() == imu_topic) {
      where = Where(imu_topic, imu_messages + 1);
      AddImu(ReadCheckedMessage<sensor_msgs::Imu>(m, where, nullptr));
    } else {
      where = Where(lidar_topic, ++lidar_messages);
      AddScan(livox::ReadLidarMessage(m, custom_msg, where));
    }
    ++it;
    exhausted = it == view->end();
  } catch (const ros::Exception& e) {
    throw std::runtime_error(where +
                             "cannot read the message (truncated or corrupted bag?): " + e.what());
  }
}

bool RosbagSource::Next(ScanFrame* frame) {
  Impl& s = *impl_;
  // A scan is complete once an IMU sample after its end has been read (the IMU between scans is
  // then all there), the bag is exhausted, or too many scans wait (IMU topic stopped).
  while (!s.exhausted && (s.pending.empty() || (s.last_imu_ns < s.pending.front().end_ns &&
                                                s.pending.size() < kMaxPendingScans))) {
    s.ReadOne();
  }
  if (s.pending.empty()) {
    s.warnings->LogTotals();
    if (s.duplicates > 0) {
      LOG(WARNING) << s.path << ": dropped " << s.duplicates << " duplicate IMU sample(s)";
    }
    if (s.retimed_scans > 0) {
      LOG(WARNING) << s.path << ": " << s.lidar_topic << ": " << s.retimed_scans
                   << " scan(s) whose per-point times were not a sweep (rescaled or recovered "
                   << "from the azimuth)";
    }
    if (s.points_outside_sweep > 0) {
      LOG(WARNING) << s.path << ": " << s.lidar_topic << ": dropped " << s.points_outside_sweep
                   << " point(s) timed more than a scan period from their scan's stamp";
    }
    if (s.unusable_scans > 0) {
      LOG(WARNING) << s.path << ": " << s.lidar_topic << ": " << s.unusable_scans
                   << " unusable scan(s) (empty, all non-finite or all at one instant) handed on "
                   << "with their nominal interval";
    }
    return false;
  }
  *frame = std::move(s.pending.front());
  s.pending.pop_front();
  frame->index = s.next_index++;
  frame->imu.clear();
  size_t used = 0;
  TakeImuUntil(s.imu, frame->end_ns, &used, &frame->imu);
  s.imu.erase(s.imu.begin(), s.imu.begin() + used);
  return true;
}

}  // namespace ctlio::io
