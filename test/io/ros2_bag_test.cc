// ROS 2 bag containers (apps/io/ros2): what the writer writes the reader returns, byte for byte
// and in log-time order, for MCAP (none/zstd/lz4, with and without summary, chunked or not) and
// SQLite; split bags; folders without metadata.yaml.
#include "ros2_bag_fixture.h"

namespace ctlio::io::ros2::testing {
namespace {

struct Case {
  Ros2Storage storage;
  Ros2Compression compression;
  const char* name;
};

class Ros2BagRoundTrip : public Ros2BagTest, public ::testing::WithParamInterface<Case> {};

TEST_P(Ros2BagRoundTrip, ReturnsEveryMessageInLogTimeOrderByteForByte) {
  const std::vector<Msg> messages = Messages(3000, 7);
  const std::string bag = Write("bag", GetParam().storage, GetParam().compression, messages);
  ASSERT_TRUE(IsRos2Bag(bag));
  Ros2BagReader r(bag);
  ASSERT_EQ(r.topics().size(), kTopics.size());
  for (size_t i = 0; i < kTopics.size(); ++i) {
    EXPECT_EQ(r.topics()[i].name, kTopics[i].first);
    EXPECT_EQ(r.topics()[i].type, kTopics[i].second);
    EXPECT_EQ(r.topics()[i].serialization_format, "cdr");
    EXPECT_EQ(r.topics()[i].message_count,
              std::count_if(messages.begin(), messages.end(),
                            [&](const Msg& m) { return m.topic == kTopics[i].first; }));
  }
  const std::vector<Msg> expected = Sorted(messages);
  ExpectSame(expected, ReadAll(r));
  uint64_t bytes = 0;
  for (const Msg& m : messages) bytes += m.data.size();
  EXPECT_EQ(r.bytes_read(), bytes);
  EXPECT_NE(r.Where().find("bag_0."), std::string::npos) << r.Where();

  // The storage file by itself is a bag too.
  const std::string file =
      bag + (GetParam().storage == Ros2Storage::kMcap ? "/bag_0.mcap" : "/bag_0.db3");
  ASSERT_TRUE(IsRos2Bag(file));
  Ros2BagReader single(file);
  ExpectSame(expected, ReadAll(single));

  // A topic filter returns that topic's messages only, in the same order.
  Ros2BagReader filtered(bag);
  filtered.SetTopicFilter({1});
  std::vector<Msg> imu;
  for (const Msg& m : expected) {
    if (m.topic == kTopics[1].first) imu.push_back(m);
  }
  ExpectSame(imu, ReadAll(filtered));
}

TEST_P(Ros2BagRoundTrip, EmptyBagHasItsTopicsAndNoMessage) {
  const std::string bag = Write("empty", GetParam().storage, GetParam().compression, {});
  Ros2BagReader r(bag);
  ASSERT_EQ(r.topics().size(), kTopics.size());
  EXPECT_EQ(r.topics()[0].message_count, 0u);
  Ros2Message m;
  EXPECT_FALSE(r.Next(&m));
  const std::string yaml = Bytes(bag + "/metadata.yaml");
  EXPECT_NE(yaml.find("message_count: 0"), std::string::npos) << yaml;
}

INSTANTIATE_TEST_SUITE_P(
    Storages, Ros2BagRoundTrip,
    ::testing::Values(Case{Ros2Storage::kMcap, Ros2Compression::kNone, "mcap"},
                      Case{Ros2Storage::kMcap, Ros2Compression::kZstd, "mcap_zstd"},
                      Case{Ros2Storage::kMcap, Ros2Compression::kLz4, "mcap_lz4"},
                      Case{Ros2Storage::kSqlite3, Ros2Compression::kNone, "sqlite3"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST_F(Ros2BagTest, MetadataYamlIsWhatRosbag2Writes) {
  const std::string bag = Write(
      "meta", Ros2Storage::kMcap, Ros2Compression::kZstd,
      {{kTopics[0].first, 1000, {1}}, {kTopics[1].first, 3000, {2}}, {kTopics[1].first, 2000, {}}});
  const std::string yaml = Bytes(bag + "/metadata.yaml");
  for (const char* line :
       {"rosbag2_bagfile_information:", "version: 5", "storage_identifier: mcap",
        "nanoseconds: 2000", "nanoseconds_since_epoch: 1000", "message_count: 3",
        "name: /os_cloud_node/imu", "type: sensor_msgs/msg/Imu", "serialization_format: cdr",
        "message_count: 2", "- meta_0.mcap", "path: meta_0.mcap"}) {
    EXPECT_NE(yaml.find(line), std::string::npos) << line << "\n" << yaml;
  }
}

// Small chunks (many per bag, overlapping in time), without summary (a pass over the data
// section), and messages outside chunks: the same messages in the same order.
TEST_F(Ros2BagTest, McapWithoutSummaryOrChunksIsScanned) {
  const std::vector<Msg> messages = Messages(600, 11);
  const std::vector<Msg> expected = Sorted(messages);
  for (const bool summary : {true, false}) {
    for (const bool chunked : {true, false}) {
      for (const char* compression : {"", "zstd", "lz4"}) {
        McapWriteOptions o;
        o.compression = chunked ? compression : "";
        o.chunk_bytes = 20000;
        o.summary = summary;
        o.chunked = chunked;
        const std::string file = WriteMcap("f.mcap", o, messages);
        SCOPED_TRACE(std::string("summary ") + (summary ? "yes" : "no") + ", chunked " +
                     (chunked ? "yes" : "no") + ", compression '" + compression + "'");
        Ros2BagReader r(file);
        ASSERT_EQ(r.topics().size(), kTopics.size());
        // Counts come from the statistics or from the scan.
        EXPECT_EQ(r.topics()[2].message_count,
                  std::count_if(messages.begin(), messages.end(),
                                [](const Msg& m) { return m.topic == kTopics[2].first; }));
        ExpectSame(expected, ReadAll(r));
      }
    }
  }
}

TEST_F(Ros2BagTest, SplitBagReadsItsFilesInOrderWithTopicsMergedByName) {
  const std::vector<Msg> first = Messages(200, 1), second = Messages(150, 2);
  std::vector<Msg> later = second;
  for (Msg& m : later) m.t += 1000000000000LL;
  const std::string a = Write("a", Ros2Storage::kMcap, Ros2Compression::kLz4, first);
  const std::string b = Write("b", Ros2Storage::kMcap, Ros2Compression::kNone, later);
  const fs::path split = dir_ / "split";
  fs::create_directories(split);
  fs::copy_file(a + "/a_0.mcap", split / "split_0.mcap");
  fs::copy_file(b + "/b_0.mcap", split / "split_1.mcap");
  Put((split / "metadata.yaml").string(),
      "rosbag2_bagfile_information:\n  version: 8\n  storage_identifier: mcap\n"
      "  relative_file_paths:\n    - split_0.mcap\n    - split_1.mcap\n"
      "  compression_format: \"\"\n  compression_mode: \"\"\n");
  Ros2BagReader r(split.string());
  ASSERT_EQ(r.topics().size(), kTopics.size());
  EXPECT_EQ(r.topics()[0].message_count,
            std::count_if(first.begin(), first.end(), [](const Msg& m) {
              return m.topic == kTopics[0].first;
            }) + std::count_if(later.begin(), later.end(), [](const Msg& m) {
              return m.topic == kTopics[0].first;
            }));
  std::vector<Msg> expected = Sorted(first);
  for (const Msg& m : Sorted(later)) expected.push_back(m);
  ExpectSame(expected, ReadAll(r));

  // A mixed split bag: the second file SQLite, a topic with another type.
  const std::string c = (dir_ / "c").string();
  {
    Ros2BagWriter w(c, Ros2Storage::kSqlite3);
    w.Write(w.AddTopic(kTopics[0].first, "sensor_msgs/msg/LaserScan"), 5, {1});
  }
  fs::remove(split / "split_1.mcap");
  fs::copy_file(c + "/c_0.db3", split / "split_1.mcap");
  const std::string error = ReadError(split.string());
  EXPECT_NE(error.find("LaserScan"), std::string::npos) << error;
  EXPECT_NE(error.find("split_1.mcap"), std::string::npos) << error;
}

TEST_F(Ros2BagTest, FolderWithoutMetadataReadsItsFilesInNameOrder) {
  const std::vector<Msg> messages = Messages(50, 3);
  const std::string a = Write("a", Ros2Storage::kSqlite3, Ros2Compression::kNone, messages);
  fs::remove(a + "/metadata.yaml");
  EXPECT_FALSE(IsRos2Bag(a));
  Ros2BagReader r(a);
  ExpectSame(Sorted(messages), ReadAll(r));
  EXPECT_NE(ReadError(dir_.string()).find("not a ROS 2 bag folder"), std::string::npos);
}

}  // namespace
}  // namespace ctlio::io::ros2::testing
