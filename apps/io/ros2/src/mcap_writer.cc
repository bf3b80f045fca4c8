// MCAP writer (https://mcap.dev/spec) with the "ros2" profile as rosbag2 writes it: a schema per
// message type (encoding "ros2msg", name the type; the definition is left empty, the type name is
// what readers use), a channel per topic (message encoding "cdr"), messages in chunks of about
// 1 MiB each followed by its message indexes, and a summary (schemas, channels, statistics, chunk
// indexes and the summary offsets). Only the current chunk is held in memory; the summary keeps
// one chunk index per chunk (about 100 bytes per MiB of bag).
#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "byte_cursor.h"
#include "compression.h"
#include "mcap_format.h"
#include "storage.h"

namespace ctlio::io::ros2 {
namespace {

class McapWriter : public StorageWriter {
 public:
  McapWriter(const std::string& path, const McapWriteOptions& o) : path_(path), options_(o) {
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) throw std::runtime_error(path + ": cannot create");
    Put(mcap::kMagic, 8);
    ByteWriter h;
    h.String("ros2");
    h.String("ctlio");
    PutRecord(mcap::kHeader, h.bytes());
  }
  ~McapWriter() override {
    if (file_) std::fclose(file_);
  }

  void AddTopic(size_t index, const std::string& name, const std::string& type) override {
    if (index > 0xFFFF) throw std::runtime_error(path_ + ": more than 65536 topics");
    auto [schema, added] = schema_ids_.emplace(type, static_cast<uint16_t>(schema_ids_.size() + 1));
    if (added) {
      ByteWriter s;
      s.U16(schema->second);
      s.String(type);
      s.String("ros2msg");
      s.U32(0);  // an empty definition
      schemas_.push_back(s.bytes());
      PutRecord(mcap::kSchema, s.bytes());
    }
    ByteWriter c;
    c.U16(static_cast<uint16_t>(index));
    c.U16(schema->second);
    c.String(name);
    c.String("cdr");
    ByteWriter meta;
    meta.String("offered_qos_profiles");
    meta.String("");
    c.U32(static_cast<uint32_t>(meta.bytes().size()));
    c.Bytes(meta.bytes());
    channels_.push_back(c.bytes());
    PutRecord(mcap::kChannel, c.bytes());
    sequence_.resize(std::max(sequence_.size(), index + 1), 0);
  }

  void Write(size_t topic, int64_t log_time_ns, const std::vector<uint8_t>& data) override {
    if (log_time_ns < 0) throw std::runtime_error(path_ + ": negative time (MCAP times are >= 0)");
    const uint16_t channel = static_cast<uint16_t>(topic);
    ++counts_[channel];
    ++message_count_;
    start_ = message_count_ == 1 ? log_time_ns : std::min(start_, log_time_ns);
    end_ = std::max(end_, log_time_ns);
    if (!options_.chunked) {
      ByteWriter m;
      MessageContent(&m, channel, sequence_[topic]++, log_time_ns, data);
      PutRecord(mcap::kMessage, m.bytes());
      return;
    }
    if (chunk_.bytes().empty()) chunk_start_ = chunk_end_ = log_time_ns;
    chunk_start_ = std::min(chunk_start_, log_time_ns);
    chunk_end_ = std::max(chunk_end_, log_time_ns);
    index_[channel].push_back({static_cast<uint64_t>(log_time_ns), chunk_.bytes().size()});
    chunk_.U8(mcap::kMessage);
    chunk_.U64(2 + 4 + 8 + 8 + data.size());
    MessageContent(&chunk_, channel, sequence_[topic]++, log_time_ns, data);
    if (chunk_.bytes().size() >= options_.chunk_bytes) FlushChunk();
  }

  void Close() override {
    FlushChunk();
    ByteWriter data_end;
    data_end.U32(0);  // the data section's CRC: not computed
    PutRecord(mcap::kDataEnd, data_end.bytes());
    uint64_t summary_start = 0, summary_offset_start = 0;
    if (options_.summary) {
      summary_start = offset_;
      std::vector<std::vector<uint8_t>> offsets;
      auto group = [&](uint8_t op, const std::vector<std::vector<uint8_t>>& records) {
        if (records.empty()) return;
        const uint64_t start = offset_;
        for (const auto& r : records) PutRecord(op, r);
        ByteWriter o;
        o.U8(op);
        o.U64(start);
        o.U64(offset_ - start);
        offsets.push_back(o.bytes());
      };
      group(mcap::kSchema, schemas_);
      group(mcap::kChannel, channels_);
      group(mcap::kStatistics, {Statistics()});
      group(mcap::kChunkIndex, chunk_indexes_);
      summary_offset_start = offset_;
      for (const auto& o : offsets) PutRecord(mcap::kSummaryOffset, o);
    }
    ByteWriter footer;
    footer.U64(summary_start);
    footer.U64(summary_offset_start);
    footer.U32(0);  // the summary's CRC: not computed
    PutRecord(mcap::kFooter, footer.bytes());
    Put(mcap::kMagic, 8);
    const bool ok = std::fflush(file_) == 0 && std::ferror(file_) == 0;
    std::fclose(file_);
    file_ = nullptr;
    if (!ok) throw std::runtime_error(path_ + ": write error (disk full?)");
  }

 private:
  void Put(const uint8_t* p, size_t n) {
    if (std::fwrite(p, 1, n, file_) != n) throw std::runtime_error(path_ + ": write error");
    offset_ += n;
  }
  void PutRecord(uint8_t op, const std::vector<uint8_t>& content) {
    ByteWriter prefix;
    prefix.U8(op);
    prefix.U64(content.size());
    Put(prefix.bytes().data(), prefix.bytes().size());
    Put(content.data(), content.size());
  }

  // publish_time: the log time (ctlio knows no other).
  static void MessageContent(ByteWriter* w, uint16_t channel, uint32_t sequence, int64_t t,
                             const std::vector<uint8_t>& data) {
    w->U16(channel);
    w->U32(sequence);
    w->U64(static_cast<uint64_t>(t));
    w->U64(static_cast<uint64_t>(t));
    w->Bytes(data);
  }

  std::vector<uint8_t> Statistics() const {
    ByteWriter s;
    s.U64(message_count_);
    s.U16(static_cast<uint16_t>(schemas_.size()));
    s.U32(static_cast<uint32_t>(channels_.size()));
    s.U32(0);  // attachments
    s.U32(0);  // metadata
    s.U32(static_cast<uint32_t>(chunk_indexes_.size()));
    s.U64(static_cast<uint64_t>(start_));
    s.U64(static_cast<uint64_t>(end_));
    s.U32(static_cast<uint32_t>(counts_.size() * 10));
    for (const auto& [channel, n] : counts_) {
      s.U16(channel);
      s.U64(n);
    }
    return s.bytes();
  }

  void FlushChunk() {
    if (chunk_.bytes().empty()) return;
    const std::vector<uint8_t>& raw = chunk_.bytes();
    const std::vector<uint8_t> compressed = Compress(options_.compression, raw);
    ByteWriter c;
    c.U64(static_cast<uint64_t>(chunk_start_));
    c.U64(static_cast<uint64_t>(chunk_end_));
    c.U64(raw.size());
    c.U32(Crc32(raw.data(), raw.size()));
    c.String(options_.compression);
    c.U64(compressed.size());
    c.Bytes(compressed);
    const uint64_t chunk_offset = offset_;
    PutRecord(mcap::kChunk, c.bytes());
    const uint64_t chunk_length = offset_ - chunk_offset;
    // One message index per channel, entries in log-time order (offsets into the records).
    ByteWriter offsets;
    const uint64_t index_start = offset_;
    for (auto& [channel, entries] : index_) {
      std::stable_sort(entries.begin(), entries.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      offsets.U16(channel);
      offsets.U64(offset_);
      ByteWriter m;
      m.U16(channel);
      m.U32(static_cast<uint32_t>(entries.size() * 16));
      for (const auto& [t, at] : entries) {
        m.U64(t);
        m.U64(at);
      }
      PutRecord(mcap::kMessageIndex, m.bytes());
    }
    ByteWriter ci;
    ci.U64(static_cast<uint64_t>(chunk_start_));
    ci.U64(static_cast<uint64_t>(chunk_end_));
    ci.U64(chunk_offset);
    ci.U64(chunk_length);
    ci.U32(static_cast<uint32_t>(offsets.bytes().size()));
    ci.Bytes(offsets.bytes());
    ci.U64(offset_ - index_start);
    ci.String(options_.compression);
    ci.U64(compressed.size());
    ci.U64(raw.size());
    chunk_indexes_.push_back(ci.bytes());
    chunk_ = ByteWriter();
    index_.clear();
  }

  std::string path_;
  McapWriteOptions options_;
  std::FILE* file_ = nullptr;
  uint64_t offset_ = 0;
  std::map<std::string, uint16_t> schema_ids_;
  std::vector<std::vector<uint8_t>> schemas_, channels_, chunk_indexes_;
  std::vector<uint32_t> sequence_;
  std::map<uint16_t, uint64_t> counts_;
  uint64_t message_count_ = 0;
  int64_t start_ = 0, end_ = 0;
  ByteWriter chunk_;
  int64_t chunk_start_ = 0, chunk_end_ = 0;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> index_;
};

}  // namespace

std::unique_ptr<StorageWriter> CreateMcap(const std::string& path, const McapWriteOptions& o) {
  return std::make_unique<McapWriter>(path, o);
}

}  // namespace ctlio::io::ros2
