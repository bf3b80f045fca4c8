// ROS 2 bags as containers of serialized messages, read and written against the published formats
// (there is no ROS 2 in Debian 12, and none is vendored):
//   * a bag folder: metadata.yaml (rosbag2's bag metadata, `rosbag2_bagfile_information`) naming
//     its storage (`mcap` or `sqlite3`) and its relative file paths, read in that order (split
//     bags);
//   * MCAP (https://mcap.dev/spec): records, chunks with zstd or lz4 compression, the summary and
//     chunk indexes when present and a linear scan of the data section when not;
//   * SQLite 3 (rosbag2_storage_default_plugins' schema: tables `topics` and `messages`).
// A single `.mcap` or `.db3` file is a bag by itself.
//
// This layer knows containers only: a message is the raw bytes of its serialization (for
// `cdr`: the 4-byte encapsulation header followed by the XCDR1 body), decoded by cdr_messages.h.
// Reading streams message by message: memory is bounded by one chunk (MCAP) or one row (SQLite),
// never the bag.
//
// Bad input: std::runtime_error naming the file (and byte offset, record or row where it
// applies); every length or count read from a file is bounded by the bytes the file (or chunk)
// can hold before anything is allocated.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ctlio::io::ros2 {

struct Ros2Topic {
  std::string name;                  // "/os_cloud_node/points"
  std::string type;                  // ROS 2 type name: "sensor_msgs/msg/PointCloud2"
  std::string serialization_format;  // "cdr"
  uint64_t message_count = 0;        // 0 when the container does not say
};

struct Ros2Message {
  size_t topic = 0;           // index into Ros2BagReader::topics()
  int64_t log_time_ns = 0;    // the recorder's receive time (MCAP log_time, SQLite timestamp)
  std::vector<uint8_t> data;  // serialized bytes
};

// True if `path` is a ROS 2 bag: a folder holding metadata.yaml, or a file starting with the MCAP
// magic, or an SQLite 3 file holding rosbag2's `messages` and `topics` tables.
bool IsRos2Bag(const std::string& path);

class Ros2BagReader {
 public:
  // `path`: a bag folder, a .mcap file or a .db3 file. Throws naming the path when it is none.
  explicit Ros2BagReader(const std::string& path);
  ~Ros2BagReader();
  Ros2BagReader(const Ros2BagReader&) = delete;
  Ros2BagReader& operator=(const Ros2BagReader&) = delete;

  const std::string& path() const;
  const std::vector<Ros2Topic>& topics() const;
  // Only messages of these topic indices are returned by Next (default: every topic).
  void SetTopicFilter(const std::vector<size_t>& topics);
  // The next message in log-time order (ties: file order); false at the end of the bag.
  bool Next(Ros2Message* message);
  // Bytes of message data returned so far.
  uint64_t bytes_read() const;
  // Where the last message returned came from ("<file>: message 12 (chunk at byte 4096)"), for
  // errors raised by the decoders.
  std::string Where() const;
  // What was recovered from when the files were opened, one line each (a file cut short).
  const std::vector<std::string>& recovered() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

enum class Ros2Storage { kMcap, kSqlite3 };
enum class Ros2Compression { kNone, kZstd, kLz4 };  // MCAP chunk compression

// Writes a bag folder `path` (created; an existing non-empty folder is an error) with
// metadata.yaml and one storage file, as `ros2 bag record` does.
class Ros2BagWriter {
 public:
  Ros2BagWriter(const std::string& path, Ros2Storage storage,
                Ros2Compression compression = Ros2Compression::kNone);
  ~Ros2BagWriter();  // Close()s if not closed yet (errors are logged, not thrown)
  Ros2BagWriter(const Ros2BagWriter&) = delete;
  Ros2BagWriter& operator=(const Ros2BagWriter&) = delete;

  // Returns the topic's index. `type` as in Ros2Topic; serialization format "cdr".
  size_t AddTopic(const std::string& name, const std::string& type);
  void Write(size_t topic, int64_t log_time_ns, const std::vector<uint8_t>& data);
  // Finishes the storage file (MCAP: the summary section and footer) and writes metadata.yaml.
  void Close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ctlio::io::ros2
