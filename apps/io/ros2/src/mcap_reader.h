// ctlio's MCAP reader (https://mcap.dev/spec), internal to ctlio::io_ros2.
//
// The data section is read as a list of blocks: each chunk, and each run (≤ 1 MiB) of messages
// outside chunks. A block's messages are decoded only when the merge reaches its start time:
// blocks are visited in start-time order and their messages merged by log time (ties in file
// order), so memory holds the blocks whose time ranges overlap the current message — one chunk
// for a recorder's file — never the file.
//
// The blocks come from the summary's chunk indexes when the file has them (with the channels and
// the statistics' message counts); otherwise from one pass over the data section at open, which
// decompresses each chunk once (one at a time) to find its channels, message counts and times.
// A file without its end magic (recording interrupted) is read up to its last complete record,
// with a warning.
#pragma once

#include <cstdio>
#include <map>
#include <memory>
#include <queue>
#include <string>
#include <unordered_map>
#include <vector>

#include "byte_cursor.h"
#include "storage.h"

namespace ctlio::io::ros2 {

class McapReader : public StorageReader {
 public:
  explicit McapReader(const std::string& path);
  ~McapReader() override;

  const std::vector<Ros2Topic>& topics() const override { return topics_; }
  void SetFilter(const std::vector<bool>& wanted) override { wanted_ = wanted; }
  bool Next(Ros2Message* message) override;
  std::string Where() const override { return where_; }
  std::string Recovered() const override {
    return truncated_ ? path_ +
                            ": does not end with the MCAP magic (recording interrupted?): "
                            "read up to its last complete record"
                      : "";
  }

 private:
  struct Block {
    int64_t start_ns = 0, end_ns = 0;
    uint64_t offset = 0;  // of the chunk record, or of the first loose record
    uint64_t length = 0;  // the chunk record's, or the run's bytes
    bool chunk = false;
    std::vector<uint16_t> channels;  // channels with messages in it (empty: not known)
  };
  struct Pending {
    int64_t log_time_ns;
    uint64_t block_offset;
    uint64_t seq;  // record order inside the block
    bool chunk;
    size_t topic;
    std::vector<uint8_t> data;
  };
  struct Later {
    bool operator()(const Pending& a, const Pending& b) const {
      if (a.log_time_ns != b.log_time_ns) return a.log_time_ns > b.log_time_ns;
      if (a.block_offset != b.block_offset) return a.block_offset > b.block_offset;
      return a.seq > b.seq;
    }
  };
  // What a record callback sees of one message.
  struct MessageView {
    uint16_t channel;
    int64_t log_time_ns;
    const uint8_t* data;
    size_t size;
  };

  std::vector<uint8_t> ReadAt(uint64_t offset, uint64_t size) const;
  ByteCursor RecordAt(uint64_t offset, uint64_t end, std::vector<uint8_t>* storage,
                      uint8_t* opcode) const;
  void ReadSummary(uint64_t summary_start, uint64_t summary_end);
  void CheckSummaryCrc(uint64_t summary_start, uint64_t footer, uint32_t expected) const;
  void ScanDataSection();
  void AddSchema(ByteCursor c);
  void AddChannel(ByteCursor c);
  // Builds topics_ from the channels (one topic per name; its type the schema's name).
  void FinishTopics();
  [[noreturn]] void Fail(uint64_t offset, const std::string& what) const;
  // Decodes the records of a block (decompressing a chunk), calling `on_message` for each message
  // and registering schemas and channels when `register_channels`.
  template <typename F>
  void ForEachMessage(const Block& block, bool register_channels, F&& on_message);
  template <typename F>
  void ParseRecords(ByteCursor c, bool register_channels, F&& on_message);
  void LoadBlock(const Block& block);
  size_t TopicOfChannel(uint16_t channel, const ByteCursor& c) const;

  std::string path_;
  struct Close {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Close> file_;
  uint64_t file_size_ = 0;
  uint64_t data_start_ = 0, data_end_ = 0;
  bool truncated_ = false;  // no end magic: the data section ends at its last complete record
  struct Channel {
    uint16_t schema_id = 0;
    std::string topic, encoding;
  };
  std::unordered_map<uint16_t, std::string> schema_names_;
  std::map<uint16_t, Channel> channels_;
  std::map<uint16_t, uint64_t> channel_counts_;
  std::unordered_map<uint16_t, size_t> channel_topic_;
  std::vector<Ros2Topic> topics_;
  std::vector<bool> wanted_;
  std::vector<Block> blocks_;
  size_t next_block_ = 0;
  std::priority_queue<Pending, std::vector<Pending>, Later> pending_;
  uint64_t returned_ = 0;
  std::string where_;
};

}  // namespace ctlio::io::ros2
