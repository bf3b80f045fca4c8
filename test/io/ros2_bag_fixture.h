// Shared by the ROS 2 bag container tests: deterministic messages, writing them into bags and
// reading them back.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "ctlio/io/ros2_bag.h"
#include "storage.h"  // apps/io/ros2/src: the MCAP writer's test options

namespace ctlio::io::ros2::testing {

namespace fs = std::filesystem;

struct Msg {
  std::string topic;
  int64_t t;
  std::vector<uint8_t> data;
};

const std::vector<std::pair<std::string, std::string>> kTopics = {
    {"/os_cloud_node/points", "sensor_msgs/msg/PointCloud2"},
    {"/os_cloud_node/imu", "sensor_msgs/msg/Imu"},
    {"/tf_static", "tf2_msgs/msg/TFMessage"}};

// Messages as a recorder writes them: interleaved topics, log times jittered so that they are
// not monotonic (also across chunks), equal times, empty messages, one message larger than a
// chunk, and one written last with the earliest time.
inline std::vector<Msg> Messages(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Msg> out;
  const int64_t t0 = 1700000000000000000LL;
  for (size_t i = 0; i < n; ++i) {
    Msg m;
    m.topic = kTopics[rng() % kTopics.size()].first;
    m.t = t0 + static_cast<int64_t>(i) * 1000000 + static_cast<int64_t>(rng() % 5000000);
    if (i % 17 == 0 && i > 0) m.t = out.back().t;  // ties: file order
    m.data.resize(i % 23 == 0 ? 0 : rng() % 3000);
    for (auto& b : m.data) b = static_cast<uint8_t>(rng());
    out.push_back(std::move(m));
  }
  if (n > 10) {
    out[n / 2].data.assign(1536 * 1024, 0);
    for (size_t k = 0; k < out[n / 2].data.size(); k += 7) out[n / 2].data[k] = uint8_t(k);
    out.push_back({kTopics[1].first, t0 - 5, {1, 2, 3}});
  }
  return out;
}

// What a reader must return: by log time, ties in writing order.
inline std::vector<Msg> Sorted(std::vector<Msg> m) {
  std::stable_sort(m.begin(), m.end(), [](const Msg& a, const Msg& b) { return a.t < b.t; });
  return m;
}

inline std::vector<Msg> ReadAll(Ros2BagReader& r) {
  std::vector<Msg> out;
  Ros2Message m;
  while (r.Next(&m)) out.push_back({r.topics().at(m.topic).name, m.log_time_ns, m.data});
  return out;
}

inline void ExpectSame(const std::vector<Msg>& expected, const std::vector<Msg>& got) {
  ASSERT_EQ(expected.size(), got.size());
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(expected[i].topic, got[i].topic) << "message " << i;
    ASSERT_EQ(expected[i].t, got[i].t) << "message " << i;
    ASSERT_EQ(expected[i].data, got[i].data) << "message " << i;
  }
}

class Ros2BagTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // In memory where available: the bad-input tests write a file per cut point.
    std::error_code ec;
    const fs::path base =
        fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::temp_directory_path();
    dir_ = base / ("ctlio_ros2_test_" + std::to_string(::getpid()) + "_" +
                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Writes `messages` into bag folder `name`; returns its path.
  std::string Write(const std::string& name, Ros2Storage storage, Ros2Compression c,
                    const std::vector<Msg>& messages) {
    const std::string path = (dir_ / name).string();
    Ros2BagWriter w(path, storage, c);
    std::map<std::string, size_t> index;
    for (const auto& [topic, type] : kTopics) index[topic] = w.AddTopic(topic, type);
    for (const Msg& m : messages) w.Write(index.at(m.topic), m.t, m.data);
    w.Close();
    return path;
  }
  // A bare MCAP file written with the test options (small chunks, no summary, ...).
  std::string WriteMcap(const std::string& name, const McapWriteOptions& o,
                        const std::vector<Msg>& messages) {
    const std::string path = (dir_ / name).string();
    auto w = CreateMcap(path, o);
    for (size_t i = 0; i < kTopics.size(); ++i) w->AddTopic(i, kTopics[i].first, kTopics[i].second);
    for (const Msg& m : messages) {
      size_t t = 0;
      while (kTopics[t].first != m.topic) ++t;
      w->Write(t, m.t, m.data);
    }
    w->Close();
    return path;
  }
  static std::string Bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  static void Put(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  }
  // Opens and drains `path`; returns the error (empty if none).
  static std::string ReadError(const std::string& path) {
    try {
      Ros2BagReader r(path);
      ReadAll(r);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

}  // namespace ctlio::io::ros2::testing
