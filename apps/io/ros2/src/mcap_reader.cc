// MCAP reader: opening (magic, header, footer, summary) and the merge of blocks by log time
// (mcap_reader.h). Decoding the records of a block is in mcap_blocks.cc.
#include "mcap_reader.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "mcap_format.h"

namespace ctlio::io::ros2 {

std::unique_ptr<StorageReader> OpenMcap(const std::string& path) {
  return std::make_unique<McapReader>(path);
}

bool HasMcapMagic(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  uint8_t head[8];
  const bool ok = std::fread(head, 1, 8, f) == 8 && std::memcmp(head, mcap::kMagic, 8) == 0;
  std::fclose(f);
  return ok;
}

McapReader::McapReader(const std::string& path) : path_(path) {
  file_.reset(std::fopen(path.c_str(), "rb"));
  if (!file_) throw std::runtime_error(path + ": cannot open");
  if (fseeko(file_.get(), 0, SEEK_END) != 0) throw std::runtime_error(path + ": cannot seek");
  file_size_ = static_cast<uint64_t>(ftello(file_.get()));
  // Magic, Header record, ..., Footer record, Magic.
  const uint64_t min_size = 8 + mcap::kRecordPrefix + mcap::kFooterRecord + 8;
  if (file_size_ < 8 || std::memcmp(ReadAt(0, 8).data(), mcap::kMagic, 8) != 0) {
    throw std::runtime_error(path + ": not an MCAP file (no MCAP magic at its start)");
  }
  if (file_size_ < min_size) Fail(file_size_, "file of " + std::to_string(file_size_) + " bytes");
  if (std::memcmp(ReadAt(file_size_ - 8, 8).data(), mcap::kMagic, 8) != 0) {
    throw std::runtime_error(path +
                             ": does not end with the MCAP magic: truncated, or still being "
                             "recorded (`mcap recover` can rebuild its end)");
  }
  const uint64_t footer = file_size_ - 8 - mcap::kFooterRecord;
  std::vector<uint8_t> storage;
  uint8_t op = 0;
  ByteCursor header = RecordAt(8, footer, &storage, &op);
  if (op != mcap::kHeader)
    Fail(8, "first record is not a Header (opcode " + std::to_string(op) + ")");
  header.String("profile");
  header.String("library");
  data_start_ = 8 + mcap::kRecordPrefix + (storage.size());
  ByteCursor f = RecordAt(footer, file_size_ - 8, &storage, &op);
  if (op != mcap::kFooter || storage.size() != mcap::kFooterContent) {
    Fail(footer, "no Footer record before the end magic");
  }
  const uint64_t summary_start = f.U64("summary_start");
  const uint64_t summary_offset_start = f.U64("summary_offset_start");
  data_end_ = footer;
  if (summary_start != 0) {
    if (summary_start < data_start_ || summary_start > footer) {
      Fail(footer,
           "summary_start " + std::to_string(summary_start) + " outside the file's records");
    }
    uint64_t summary_end = footer;
    if (summary_offset_start != 0) {
      if (summary_offset_start < summary_start || summary_offset_start > footer) {
        Fail(footer, "summary_offset_start " + std::to_string(summary_offset_start) +
                         " outside the summary");
      }
      summary_end = summary_offset_start;
    }
    data_end_ = summary_start;
    ReadSummary(summary_start, summary_end);
  }
  if (blocks_.empty() || channels_.empty()) {
    // No summary, or one without chunk indexes and channels: one pass over the data section.
    blocks_.clear();
    channels_.clear();
    schema_names_.clear();
    channel_counts_.clear();
    ScanDataSection();
  }
  FinishTopics();
  std::sort(blocks_.begin(), blocks_.end(), [](const Block& a, const Block& b) {
    return a.start_ns != b.start_ns ? a.start_ns < b.start_ns : a.offset < b.offset;
  });
  wanted_.assign(topics_.size(), true);
}

McapReader::~McapReader() = default;

void McapReader::Fail(uint64_t offset, const std::string& what) const {
  throw std::runtime_error(path_ + ": not a valid MCAP file (truncated or corrupted?): " + what +
                           " at byte " + std::to_string(offset));
}

std::vector<uint8_t> McapReader::ReadAt(uint64_t offset, uint64_t size) const {
  if (offset > file_size_ || size > file_size_ - offset) {
    Fail(offset, "read of " + std::to_string(size) + " bytes past the end of the file");
  }
  std::vector<uint8_t> out(static_cast<size_t>(size));
  if (fseeko(file_.get(), static_cast<off_t>(offset), SEEK_SET) != 0 ||
      std::fread(out.data(), 1, out.size(), file_.get()) != out.size()) {
    throw std::runtime_error(path_ + ": read error at byte " + std::to_string(offset));
  }
  return out;
}

ByteCursor McapReader::RecordAt(uint64_t offset, uint64_t end, std::vector<uint8_t>* storage,
                                uint8_t* opcode) const {
  if (offset > end || end - offset < mcap::kRecordPrefix) Fail(offset, "truncated record");
  const std::vector<uint8_t> prefix = ReadAt(offset, mcap::kRecordPrefix);
  ByteCursor p(prefix.data(), prefix.size(), path_, offset);
  *opcode = p.U8("opcode");
  const uint64_t length = p.U64("record length");
  if (length > end - offset - mcap::kRecordPrefix) {
    Fail(offset, "record (opcode " + std::to_string(*opcode) + ") of " + std::to_string(length) +
                     " bytes where " + std::to_string(end - offset - mcap::kRecordPrefix) +
                     " remain");
  }
  *storage = ReadAt(offset + mcap::kRecordPrefix, length);
  return ByteCursor(storage->data(), storage->size(), path_, offset + mcap::kRecordPrefix);
}

void McapReader::AddSchema(ByteCursor c) {
  const uint16_t id = c.U16("schema id");
  const std::string name = c.String("schema name");
  c.String("schema encoding");
  c.Skip(c.U32("schema data length"), "schema data");
  if (id == 0) c.Fail("schema id 0 (reserved)");
  schema_names_[id] = name;
}

void McapReader::AddChannel(ByteCursor c) {
  const uint16_t id = c.U16("channel id");
  Channel ch;
  ch.schema_id = c.U16("channel schema id");
  ch.topic = c.String("channel topic");
  ch.encoding = c.String("channel message encoding");
  c.Skip(c.U32("channel metadata length"), "channel metadata");
  const auto it = channels_.find(id);
  if (it != channels_.end() && it->second.topic != ch.topic) {
    c.Fail("channel " + std::to_string(id) + " redefined from '" + it->second.topic + "' to '" +
           ch.topic + "'");
  }
  channels_[id] = ch;
}

void McapReader::ReadSummary(uint64_t start, uint64_t end) {
  std::vector<uint8_t> storage;
  for (uint64_t off = start; off < end;) {
    uint8_t op = 0;
    ByteCursor c = RecordAt(off, end, &storage, &op);
    off += mcap::kRecordPrefix + storage.size();
    if (op == mcap::kSchema) {
      AddSchema(c);
    } else if (op == mcap::kChannel) {
      AddChannel(c);
    } else if (op == mcap::kChunkIndex) {
      Block b;
      b.chunk = true;
      b.start_ns = c.Time("chunk message_start_time");
      b.end_ns = c.Time("chunk message_end_time");
      b.offset = c.U64("chunk_start_offset");
      b.length = c.U64("chunk_length");
      ByteCursor index = c.Sub(c.U32("message_index_offsets length"), "message_index_offsets");
      while (!index.empty()) {
        b.channels.push_back(index.U16("channel id"));
        index.U64("message index offset");
      }
      if (b.offset < data_start_ || b.offset > data_end_ || b.length > data_end_ - b.offset ||
          b.length < mcap::kRecordPrefix) {
        c.Fail("chunk index pointing outside the data section (chunk at " +
               std::to_string(b.offset) + ", " + std::to_string(b.length) + " bytes)");
      }
      if (b.start_ns > b.end_ns) c.Fail("chunk index whose start time is after its end time");
      blocks_.push_back(std::move(b));
    } else if (op == mcap::kStatistics) {
      c.U64("message_count");
      c.U16("schema_count");
      for (const char* what :
           {"channel_count", "attachment_count", "metadata_count", "chunk_count"}) {
        c.U32(what);
      }
      c.U64("message_start_time");
      c.U64("message_end_time");
      ByteCursor counts = c.Sub(c.U32("channel_message_counts length"), "channel_message_counts");
      while (!counts.empty()) {
        const uint16_t id = counts.U16("channel id");
        channel_counts_[id] = counts.U64("message count");
      }
    }
  }
}

void McapReader::FinishTopics() {
  for (const auto& [id, ch] : channels_) {
    std::string type;
    if (ch.schema_id != 0) {
      const auto s = schema_names_.find(ch.schema_id);
      if (s == schema_names_.end()) {
        throw std::runtime_error(path_ + ": channel " + std::to_string(id) + " ('" + ch.topic +
                                 "') names schema " + std::to_string(ch.schema_id) +
                                 ", which the file does not define");
      }
      type = s->second;
    }
    size_t t = 0;
    while (t < topics_.size() && topics_[t].name != ch.topic) ++t;
    if (t == topics_.size()) {
      topics_.push_back({ch.topic, type, ch.encoding, 0});
    } else if (topics_[t].type != type || topics_[t].serialization_format != ch.encoding) {
      throw std::runtime_error(path_ + ": topic '" + ch.topic + "' has channels of types '" +
                               topics_[t].type + "' and '" + type + "'");
    }
    channel_topic_[id] = t;
    const auto n = channel_counts_.find(id);
    if (n != channel_counts_.end()) topics_[t].message_count += n->second;
  }
}

size_t McapReader::TopicOfChannel(uint16_t channel, const ByteCursor& c) const {
  const auto it = channel_topic_.find(channel);
  if (it == channel_topic_.end()) {
    c.Fail("message on channel " + std::to_string(channel) + ", which the file does not define");
  }
  return it->second;
}

bool McapReader::Next(Ros2Message* message) {
  while (next_block_ < blocks_.size() &&
         (pending_.empty() || blocks_[next_block_].start_ns <= pending_.top().log_time_ns)) {
    const Block& b = blocks_[next_block_++];
    // A chunk index lists the channels of its chunk: skip chunks without a wanted topic.
    bool wanted = b.channels.empty();
    for (uint16_t ch : b.channels) {
      const auto it = channel_topic_.find(ch);
      wanted = wanted || it == channel_topic_.end() || wanted_[it->second];
    }
    if (wanted) LoadBlock(b);
  }
  if (pending_.empty()) return false;
  Pending& top = const_cast<Pending&>(pending_.top());
  message->topic = top.topic;
  message->log_time_ns = top.log_time_ns;
  message->data = std::move(top.data);
  ++returned_;
  where_ = path_ + ": message " + std::to_string(returned_) + " (" +
           (top.chunk ? "chunk" : "record") + " at byte " + std::to_string(top.block_offset) + ")";
  pending_.pop();
  return true;
}

}  // namespace ctlio::io::ros2
