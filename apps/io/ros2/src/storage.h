// The storage files of a ROS 2 bag behind one interface (internal to ctlio::io_ros2): an MCAP or
// SQLite 3 file read message by message in log-time order, or written, and the bag folder's
// metadata.yaml.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/io/ros2_bag.h"

namespace ctlio::io::ros2 {

// One storage file being read. Topic indices are the file's own (Ros2BagReader maps them to the
// bag's, by name).
class StorageReader {
 public:
  virtual ~StorageReader() = default;
  virtual const std::vector<Ros2Topic>& topics() const = 0;
  // wanted[i]: topic i is returned by Next (default: all).
  virtual void SetFilter(const std::vector<bool>& wanted) = 0;
  // The next message in log-time order (ties in file order); `message->topic` is the file's index.
  virtual bool Next(Ros2Message* message) = 0;
  virtual std::string Where() const = 0;
  // What the reader recovered from when it opened the file ("" if nothing): a file cut short.
  virtual std::string Recovered() const { return ""; }
};

std::unique_ptr<StorageReader> OpenMcap(const std::string& path);
std::unique_ptr<StorageReader> OpenSqlite(const std::string& path);
// True if the file starts with the MCAP magic / the SQLite 3 header.
bool HasMcapMagic(const std::string& path);
bool HasSqliteHeader(const std::string& path);
// True if the SQLite file holds the `topics` and `messages` tables (false on any error).
bool IsRosbag2Sqlite(const std::string& path);

class StorageWriter {
 public:
  virtual ~StorageWriter() = default;
  virtual void AddTopic(size_t index, const std::string& name, const std::string& type) = 0;
  virtual void Write(size_t topic, int64_t log_time_ns, const std::vector<uint8_t>& data) = 0;
  virtual void Close() = 0;
};

struct McapWriteOptions {
  std::string compression;       // "", "zstd", "lz4"
  size_t chunk_bytes = 1 << 20;  // a chunk is closed when its records reach this size
  bool summary = true;           // false: no summary section (footer summary_start 0)
  bool chunked = true;           // false: messages in the data section, outside chunks
};
std::unique_ptr<StorageWriter> CreateMcap(const std::string& path, const McapWriteOptions& o);
std::unique_ptr<StorageWriter> CreateSqlite(const std::string& path);

// metadata.yaml (rosbag2_bagfile_information).
struct BagFileInfo {
  std::string path;  // relative to the bag folder
  int64_t start_ns = 0, end_ns = 0;
  uint64_t message_count = 0;
};
struct BagMetadata {
  int version = 0;
  std::string storage_identifier;  // "mcap" or "sqlite3"
  std::vector<std::string> relative_file_paths;
  std::vector<Ros2Topic> topics;  // with message_count when given
  std::vector<BagFileInfo> files;
  int64_t start_ns = 0, duration_ns = 0;
  uint64_t message_count = 0;
};
// Reads `folder`/metadata.yaml; throws naming the file when it is malformed or uses file or
// message compression (not supported: `ros2 bag convert` writes an uncompressed copy).
BagMetadata ReadBagMetadata(const std::string& folder);
void WriteBagMetadata(const std::string& folder, const BagMetadata& m);

}  // namespace ctlio::io::ros2
