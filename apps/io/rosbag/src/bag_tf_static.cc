// BagSource: the extrinsic T_imu_lidar from the bag's /tf_static, else the preset's, else
// identity for a shared frame_id (the precedence of rosbag_source.h).
#include <glog/logging.h>

#include <map>
#include <queue>

#include "bag_source_impl.h"
#include "ctlio/io/extrinsic_check.h"

namespace ctlio::io {
namespace {

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

}  // namespace

void BagSource::Impl::ChooseExtrinsic() {
  std::vector<StaticEdge> edges;
  stream->Select({"/tf_static"});
  size_t tf_index = 0;
  while (stream->Next()) {
    ++tf_index;
    if (!stream->Holds("tf2_msgs/TFMessage")) continue;  // (a foreign type: not ours to read)
    const std::string where = Where("/tf_static", tf_index);
    tf2_msgs::TFMessage msg;
    stream->Read(where, &msg);
    for (const auto& t : msg.transforms) edges.push_back({t, where});
  }
  if (!lidar_frame.empty() && !imu_frame.empty() &&
      FindStaticTransform(edges, imu_frame, lidar_frame, &extrinsic)) {
    extrinsic_origin = "the bag's /tf_static (" + imu_frame + " → " + lidar_frame + ")";
  } else if (preset) {
    extrinsic = preset->imu_from_lidar;
    extrinsic_origin = "the " + preset->name + " preset";
    if (!edges.empty()) {
      // The bag carries a tree, but not between these frames: the preset (recognised from the
      // topic names unless --preset) is a guess that the bag is the preset's sensor (issue 40).
      auto frame = [](const std::string& f) { return f.empty() ? "(no frame_id)" : "'" + f + "'"; };
      std::string why = " — a guess: the bag's /tf_static does not connect the IMU frame " +
                        frame(imu_frame) + " and the lidar frame " + frame(lidar_frame);
      if (options.preset.empty()) why = " (recognised from the topic names)" + why;
      extrinsic_origin += why;
      LOG(WARNING) << path << ": T_imu_lidar from " << extrinsic_origin
                   << "; give `extrinsic:` in the config if the bag is another sensor's";
    }
  } else if (!lidar_frame.empty() && lidar_frame == imu_frame) {
    extrinsic_origin = "identity (lidar and IMU share frame_id '" + lidar_frame + "')";
  }
}

}  // namespace ctlio::io
