// Writes the seed corpora of the fuzz targets from the simulator: a 0.15 s sequence (two scans of
// 24 points, 30 IMU samples) in every layout, each target's files joined by "%%" lines as the
// target splits them. Usage: fuzz_make_seeds <corpus_dir> <source_dir> (data/*.yaml are the YAML
// seeds).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "ctlio/io/bag_writer.h"
#include "ctlio/io/cdr_livox.h"
#include "ctlio/io/cdr_messages.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/point_cloud_io.h"
#include "ctlio/io/ros2_bag.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/io/trajectory_io.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "fuzz_common.h"
#include "storage.h"  // apps/io/ros2/src: the MCAP writer's options

namespace fs = std::filesystem;
using namespace ctlio;

namespace {

std::string Read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string Join(const std::vector<std::string>& parts) {
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) out += (i ? "\n%%\n" : "") + parts[i];
  return out;
}

void Seed(const fs::path& corpus, const std::string& target, const std::string& name,
          const std::string& bytes) {
  fs::create_directories(corpus / target);
  std::ofstream(corpus / target / name, std::ios::binary) << bytes;
}

sim::SimConfig Tiny() {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 0);
  c.duration_s = 0.15;
  c.lidar.beams = 4;
  c.lidar.firing_decimation = 300;
  c.start_ns = 1583836591LL * 1000000000LL + 182590000LL;
  c.imu_from_lidar = io::NewerCollegeImuFromLidar();
  return c;
}

// ROS 2 bag seeds: the simulated scans' and IMU samples' times on the topics of an Ouster bag,
// each message its time's bytes (the containers do not look inside messages), in MCAP (three
// chunk codecs with 2 KiB chunks, no summary, no chunks) and rosbag2's SQLite.
void SeedRos2(const fs::path& corpus, const fs::path& work, sim::SimulatedSource* source) {
  std::vector<std::pair<size_t, int64_t>> messages;
  io::ScanFrame frame;
  while (source->Next(&frame)) {
    messages.push_back({0, frame.start_ns});
    for (const auto& s : frame.imu) messages.push_back({1, s.t_ns});
  }
  messages.push_back({2, messages.front().second});
  const std::vector<std::pair<std::string, std::string>> topics = {
      {"/os_cloud_node/points", "sensor_msgs/msg/PointCloud2"},
      {"/os_cloud_node/imu", "sensor_msgs/msg/Imu"},
      {"/tf_static", "tf2_msgs/msg/TFMessage"}};
  auto bytes = [](int64_t t, size_t topic) {
    std::vector<uint8_t> b(topic == 0 ? 400 : 40);
    for (size_t i = 0; i < b.size(); ++i) b[i] = static_cast<uint8_t>(t >> (8 * (i % 8)));
    return b;
  };
  struct Variant {
    const char* name;
    const char* compression;
    bool summary, chunked;
  };
  for (const Variant& v :
       {Variant{"none", "", true, true}, Variant{"zstd", "zstd", true, true},
        Variant{"lz4", "lz4", true, true}, Variant{"no_summary", "", false, true},
        Variant{"no_chunks", "", true, false}}) {
    io::ros2::McapWriteOptions o;
    o.compression = v.compression;
    o.chunk_bytes = 2048;
    o.summary = v.summary;
    o.chunked = v.chunked;
    const fs::path file = work / (std::string(v.name) + ".mcap");
    auto w = io::ros2::CreateMcap(file.string(), o);
    for (size_t i = 0; i < topics.size(); ++i) w->AddTopic(i, topics[i].first, topics[i].second);
    for (const auto& [topic, t] : messages) w->Write(topic, t, bytes(t, topic));
    w->Close();
    Seed(corpus, "mcap", v.name, Read(file));
  }
  io::ros2::Ros2BagWriter w((work / "sqlite").string(), io::ros2::Ros2Storage::kSqlite3);
  for (const auto& [name, type] : topics) w.AddTopic(name, type);
  for (const auto& [topic, t] : messages) w.Write(topic, t, bytes(t, topic));
  w.Close();
  Seed(corpus, "ros2_sqlite", "bag", Read(work / "sqlite/sqlite_0.db3"));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: fuzz_make_seeds <corpus_dir> <source_dir>\n";
    return 2;
  }
  fuzz::QuietLogging();
  const fs::path corpus(argv[1]), source_dir(argv[2]);
  const fs::path work =
      fs::temp_directory_path() / ("ctlio_fuzz_seeds_" + std::to_string(getpid()));
  fs::remove_all(work);
  try {
    sim::SimulatedSource a(Tiny()), b(Tiny());
    io::WriteSimFolder(a, (work / "ctlio").string());
    io::WriteNewerCollege(b, (work / "nc").string());
    const fs::path c = work / "ctlio", n = work / "nc";
    Seed(corpus, "sim_folder", "sim",
         Join({Read(c / "ctlio_sim.yaml"), Read(c / "imu.csv"), Read(c / "scans.csv"),
               Read(c / "scans/000000.bin"), Read(c / "scans/000001.bin"),
               Read(c / "ground_truth.csv")}));
    const fs::path scans = n / "raw_format/ouster_zip_files/ouster_scan";
    const std::string pcd0 = Read(scans / "cloud_1583836591_182590000.pcd");
    const std::string pcd1 = Read(scans / "cloud_1583836591_282590000.pcd");
    Seed(corpus, "newer_college", "sim",
         Join({Read(n / "raw_format/ouster_imu/data.csv"),
               Read(n / "ground_truth/registered_poses.csv"), pcd0, pcd1}));
    Seed(corpus, "pcd", "binary", pcd0);
    const io::PointCloud cloud =
        io::ReadPcd((scans / "cloud_1583836591_182590000.pcd").string(), {Tiny().start_ns, true});
    std::ostringstream ascii;
    ascii << "VERSION .7\nFIELDS x y z intensity t ring\nSIZE 4 4 4 4 4 2\nTYPE F F F F U U\n"
          << "COUNT 1 1 1 1 1 1\nWIDTH " << cloud.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
          << "POINTS " << cloud.size() << "\nDATA ascii\n";
    for (size_t i = 0; i < cloud.size(); ++i) {
      ascii << cloud.points[i].x() << ' ' << cloud.points[i].y() << ' ' << cloud.points[i].z()
            << " 1 " << cloud.times_ns[i] - cloud.stamp_ns << ' ' << cloud.ring[i] << '\n';
    }
    Seed(corpus, "pcd", "ascii", ascii.str());
    io::WritePly((work / "s.ply").string(), cloud);
    Seed(corpus, "ply", "binary", Read(work / "s.ply"));
    io::WriteKittiBin((work / "s.bin").string(), cloud, (work / "s_times.bin").string());
    Seed(corpus, "kitti_bin", "scan", Join({Read(work / "s.bin"), Read(work / "s_times.bin")}));
    Seed(corpus, "table", "imu", Read(c / "imu.csv"));
    Seed(corpus, "table", "scans", Read(c / "scans.csv"));
    const auto gt = *a.GroundTruth();
    io::WriteKittiPoses((work / "poses.txt").string(), gt);
    std::string times;
    for (const auto& p : gt) times += io::FormatSecondsNs(p.t_ns) + "\n";
    Seed(corpus, "trajectory", "tum", Read(c / "ground_truth_tum.txt"));
    Seed(corpus, "trajectory", "kitti", Join({Read(work / "poses.txt"), times}));
    Seed(corpus, "kitti_folder", "sim",
         Join({"0.0\n0.1\n", Read(work / "s.bin"), Read(work / "s.bin"), Read(work / "s_times.bin"),
               Read(work / "poses.txt"), "Tr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n"}));
    for (const std::string compression : {"none", "lz4", "bz2"}) {
      sim::SimulatedSource bag_source(Tiny());
      io::RosbagWriteOptions o;
      o.compression = compression;
      io::WriteRosbag(bag_source, (work / "s.bag").string(), o);
      Seed(corpus, "rosbag", compression, Read(work / "s.bag"));
    }
    {
      // fuzz_cdr_messages: the first message of each type as WriteRos2Bag encodes it, after the
      // byte that picks the type (fuzz_cdr_messages.cc); PoseStamped from the first pose.
      struct FirstOfEach : io::Ros2ContainerWriter {
        std::vector<std::string> types;
        std::map<std::string, std::string> first;
        size_t AddTopic(const std::string&, const std::string& type) override {
          types.push_back(type);
          return types.size() - 1;
        }
        void Write(size_t topic, int64_t, const std::vector<uint8_t>& data) override {
          first.emplace(types[topic], std::string(data.begin(), data.end()));
        }
        void Close() override {}
      } messages;
      sim::SimulatedSource bag_source(Tiny());
      io::WriteRos2Bag(bag_source, messages);
      const char* kTypes[] = {"sensor_msgs/msg/PointCloud2", "sensor_msgs/msg/Imu",
                              "tf2_msgs/msg/TFMessage", "nav_msgs/msg/Odometry"};
      for (char k = 0; k < 4; ++k) {
        Seed(corpus, "cdr_messages", std::to_string(int(k)), k + messages.first.at(kTypes[int(k)]));
      }
      const std::string& odometry = messages.first.at(kTypes[3]);
      nav_msgs::Odometry o;
      io::ros2::DecodeCdr(reinterpret_cast<const uint8_t*>(odometry.data()), odometry.size(), "",
                          &o);
      geometry_msgs::PoseStamped p;
      p.header = o.header;
      p.pose = o.pose.pose;
      for (const auto e : {io::ros2::CdrEndian::kLittle, io::ros2::CdrEndian::kBig}) {
        const std::vector<uint8_t> b = io::ros2::EncodeCdr(p, e);
        Seed(corpus, "cdr_messages", e == io::ros2::CdrEndian::kBig ? "4_be" : "4",
             char(4) + std::string(b.begin(), b.end()));
      }
      // A Livox CustomMsg: the first scan's first 16 points, offsets from the scan start.
      sim::SimulatedSource livox_source(Tiny());
      io::ScanFrame f;
      livox_source.Next(&f);
      io::livox::CustomMsg livox;
      livox.header.stamp.fromNSec(uint64_t(f.start_ns));
      livox.header.frame_id = "livox_frame";
      livox.timebase = uint64_t(f.start_ns);
      for (size_t i = 0; i < f.cloud.size() && i < 16; ++i) {
        const Vec3& q = f.cloud.points[i];
        livox.points.push_back({uint32_t(f.cloud.times_ns[i] - f.start_ns), float(q.x()),
                                float(q.y()), float(q.z()), 100, 16, uint8_t(i % 4)});
      }
      livox.point_num = uint32_t(livox.points.size());
      const std::vector<uint8_t> lb = io::ros2::EncodeCdr(livox);
      Seed(corpus, "cdr_messages", "5", char(5) + std::string(lb.begin(), lb.end()));
    }
    sim::SimulatedSource ros2_source(Tiny());
    SeedRos2(corpus, work, &ros2_source);
    // The structure-aware target builds its valid message itself; its inputs are edit recipes,
    // and the empty one (no edit) is the valid message.
    Seed(corpus, "pointcloud2", "unchanged", "");
    for (const auto& e : fs::directory_iterator(source_dir / "data")) {
      if (e.path().extension() == ".yaml") {
        Seed(corpus, "yaml_config", e.path().filename().string(), Read(e.path()));
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "fuzz_make_seeds: " << e.what() << "\n";
    return 1;
  }
  fs::remove_all(work);
  return 0;
}
