// MCAP reader: the records of a block (a chunk, decompressed; or a run of records outside
// chunks), the pass over the data section of a file without a usable summary, and the loading of
// a block's messages into the merge (mcap_reader.h).
#include <algorithm>
#include <stdexcept>

#include "compression.h"
#include "mcap_format.h"
#include "mcap_reader.h"

namespace ctlio::io::ros2 {
namespace {
// A run of messages outside chunks is cut into blocks of about this size (memory per block).
constexpr uint64_t kLooseBlockBytes = 1 << 20;
}  // namespace

template <typename F>
void McapReader::ParseRecords(ByteCursor c, bool register_channels, F&& on_message) {
  uint64_t seq = 0;
  while (!c.empty()) {
    const uint8_t op = c.U8("opcode");
    ByteCursor rec = c.Sub(c.U64("record length"), "record");
    if (op == mcap::kMessage) {
      MessageView v;
      v.channel = rec.U16("message channel id");
      rec.U32("message sequence");
      v.log_time_ns = rec.Time("message log_time");
      rec.U64("message publish_time");
      v.data = rec.here();
      v.size = rec.left();
      on_message(v, seq++, rec);
    } else if (op == mcap::kSchema && register_channels) {
      AddSchema(rec);
    } else if (op == mcap::kChannel && register_channels) {
      AddChannel(rec);
    } else if (op == mcap::kChunk || op == mcap::kHeader || op == mcap::kFooter) {
      rec.Fail("record of opcode " + std::to_string(op) + " where it cannot be");
    }
  }
}

template <typename F>
void McapReader::ForEachMessage(const Block& block, bool register_channels, F&& on_message) {
  std::vector<uint8_t> storage;
  if (!block.chunk) {
    storage = ReadAt(block.offset, block.length);
    ParseRecords(ByteCursor(storage.data(), storage.size(), path_, block.offset), register_channels,
                 on_message);
    return;
  }
  uint8_t op = 0;
  ByteCursor c = RecordAt(block.offset, data_end_, &storage, &op);
  if (op != mcap::kChunk || mcap::kRecordPrefix + storage.size() != block.length) {
    Fail(block.offset, "no chunk record of " + std::to_string(block.length) +
                           " bytes where the chunk index points");
  }
  c.Time("chunk message_start_time");
  c.Time("chunk message_end_time");
  const uint64_t uncompressed_size = c.U64("chunk uncompressed_size");
  const uint32_t crc = c.U32("chunk uncompressed_crc");
  const std::string compression = c.String("chunk compression");
  ByteCursor records = c.Sub(c.U64("chunk records length"), "chunk records");
  const std::string what = path_ + ": chunk at byte " + std::to_string(block.offset);
  const std::vector<uint8_t> raw =
      Decompress(compression, records.here(), records.left(), uncompressed_size, what);
  if (crc != 0 && Crc32(raw.data(), raw.size()) != crc) {
    throw std::runtime_error(what + ": CRC of its records does not match (corrupted)");
  }
  ParseRecords(ByteCursor(raw.data(), raw.size(), path_, 0,
                          " of the decompressed chunk at byte " + std::to_string(block.offset)),
               register_channels, on_message);
}

void McapReader::ScanDataSection() {
  Block loose;
  auto close_loose = [&] {
    if (loose.length > 0) blocks_.push_back(loose);
    loose = Block();
  };
  std::vector<uint8_t> storage;
  for (uint64_t off = data_start_; off < data_end_;) {
    if (data_end_ - off < mcap::kRecordPrefix) Fail(off, "truncated record");
    const std::vector<uint8_t> prefix = ReadAt(off, mcap::kRecordPrefix);
    ByteCursor p(prefix.data(), prefix.size(), path_, off);
    const uint8_t op = p.U8("opcode");
    const uint64_t length = p.U64("record length");
    if (length > data_end_ - off - mcap::kRecordPrefix) {
      Fail(off, "record (opcode " + std::to_string(op) + ") of " + std::to_string(length) +
                    " bytes where " + std::to_string(data_end_ - off - mcap::kRecordPrefix) +
                    " remain");
    }
    const uint64_t next = off + mcap::kRecordPrefix + length;
    if (op == mcap::kDataEnd) break;
    if (op == mcap::kChunk) {
      close_loose();
      Block b;
      b.chunk = true;
      b.offset = off;
      b.length = next - off;
      bool any = false;
      ForEachMessage(b, true, [&](const MessageView& v, uint64_t, const ByteCursor& rec) {
        if (!channels_.count(v.channel)) {
          rec.Fail("message on channel " + std::to_string(v.channel) + " before its definition");
        }
        ++channel_counts_[v.channel];
        if (std::find(b.channels.begin(), b.channels.end(), v.channel) == b.channels.end()) {
          b.channels.push_back(v.channel);
        }
        b.start_ns = any ? std::min(b.start_ns, v.log_time_ns) : v.log_time_ns;
        b.end_ns = any ? std::max(b.end_ns, v.log_time_ns) : v.log_time_ns;
        any = true;
      });
      if (any) blocks_.push_back(std::move(b));
    } else if (op == mcap::kMessage || op == mcap::kSchema || op == mcap::kChannel) {
      const Block one{0, 0, off, next - off, false, {}};
      bool message = false;
      int64_t t = 0;
      ForEachMessage(one, true, [&](const MessageView& v, uint64_t, const ByteCursor& rec) {
        if (!channels_.count(v.channel)) {
          rec.Fail("message on channel " + std::to_string(v.channel) + " before its definition");
        }
        ++channel_counts_[v.channel];
        message = true;
        t = v.log_time_ns;
      });
      if (message) {
        if (loose.length == 0) {
          loose.offset = off;
          loose.start_ns = loose.end_ns = t;
        }
        loose.start_ns = std::min(loose.start_ns, t);
        loose.end_ns = std::max(loose.end_ns, t);
      }
      if (loose.length > 0 || message) loose.length = next - loose.offset;
      if (loose.length >= kLooseBlockBytes) close_loose();
    } else {
      close_loose();  // attachments, metadata, indexes: not read
    }
    off = next;
  }
  close_loose();
}

void McapReader::LoadBlock(const Block& block) {
  ForEachMessage(block, false, [&](const MessageView& v, uint64_t seq, const ByteCursor& rec) {
    const size_t topic = TopicOfChannel(v.channel, rec);
    if (!wanted_[topic]) return;
    if (v.log_time_ns < block.start_ns || v.log_time_ns > block.end_ns) {
      rec.Fail("message log_time " + std::to_string(v.log_time_ns) +
               " outside its chunk's time range [" + std::to_string(block.start_ns) + ", " +
               std::to_string(block.end_ns) + "]");
    }
    pending_.push(Pending{v.log_time_ns, block.offset, seq, block.chunk, topic,
                          std::vector<uint8_t>(v.data, v.data + v.size)});
  });
}

}  // namespace ctlio::io::ros2
