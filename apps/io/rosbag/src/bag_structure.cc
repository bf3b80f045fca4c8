#include "ctlio/io/bag_structure.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <vector>

namespace ctlio::io {
namespace {

// rosbag/constants.h (format 2.0).
constexpr uint8_t kOpMessage = 0x02, kOpFileHeader = 0x03, kOpIndexData = 0x04, kOpChunk = 0x05,
                  kOpChunkInfo = 0x06, kOpConnection = 0x07;
constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr uint64_t kMagicBytes = 13;
// A record header holds a few short fields, or a connection's message definition (tens of kB).
constexpr uint32_t kMaxHeaderBytes = 16u << 20;

struct Record {
  uint64_t pos = 0;  // of the header length
  uint8_t op = 0;
  std::map<std::string, std::string> fields;
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  uint64_t end() const { return data_pos + data_len; }
};

class Walker {
 public:
  explicit Walker(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw std::runtime_error(path + ": cannot open");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<uint64_t>(in_.tellg());
  }

  uint64_t size() const { return size_; }

  [[noreturn]] void Fail(uint64_t at, const std::string& what) const {
    throw std::runtime_error(path_ + ": not a valid ROS 1 bag (truncated or corrupted?): at byte " +
                             std::to_string(at) + ": " + what);
  }

  std::string Read(uint64_t pos, uint64_t n) {
    std::string bytes(n, '\0');
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(pos));
    in_.read(bytes.data(), static_cast<std::streamsize>(n));
    if (static_cast<uint64_t>(in_.gcount()) != n)
      Fail(pos, "cannot read " + std::to_string(n) + " bytes");
    return bytes;
  }

  uint32_t ReadU32(uint64_t pos) {
    const std::string b = Read(pos, 4);
    uint32_t v;
    std::memcpy(&v, b.data(), 4);  // little-endian on every platform ROS 1 supports
    return v;
  }

  // The record at `pos`, which must end by `limit`.
  Record ReadRecord(uint64_t pos, uint64_t limit) {
    Record r;
    r.pos = pos;
    if (pos + 4 > limit) Fail(pos, "record header length past the end");
    const uint32_t header_len = ReadU32(pos);
    if (header_len > kMaxHeaderBytes || pos + 4 + header_len + 4 > limit) {
      Fail(pos, "record header length " + std::to_string(header_len) + " does not fit");
    }
    const std::string header = Read(pos + 4, header_len);
    for (size_t i = 0; i < header.size();) {
      if (i + 4 > header.size()) Fail(pos, "truncated header field");
      uint32_t field_len;
      std::memcpy(&field_len, header.data() + i, 4);
      i += 4;
      if (field_len > header.size() - i) Fail(pos, "header field length past the header");
      const std::string field = header.substr(i, field_len);
      i += field_len;
      const size_t eq = field.find('=');
      if (eq == std::string::npos) Fail(pos, "header field without '='");
      r.fields[field.substr(0, eq)] = field.substr(eq + 1);
    }
    const auto op = r.fields.find("op");
    if (op == r.fields.end() || op->second.size() != 1) Fail(pos, "record without an op code");
    r.op = static_cast<uint8_t>(op->second[0]);
    r.data_len = ReadU32(pos + 4 + header_len);
    r.data_pos = pos + 4 + header_len + 4;
    if (r.data_len > limit - r.data_pos) {
      Fail(pos, "record data length " + std::to_string(r.data_len) + " does not fit");
    }
    return r;
  }

  // A fixed-size field (rosbag checks the size too; here it is needed to read it).
  template <class T>
  T Field(const Record& r, const std::string& name) const {
    const auto it = r.fields.find(name);
    if (it == r.fields.end() || it->second.size() != sizeof(T)) {
      Fail(r.pos, "field '" + name + "' missing or of the wrong size");
    }
    T v;
    std::memcpy(&v, it->second.data(), sizeof(T));
    return v;
  }

  std::string StringField(const Record& r, const std::string& name) const {
    const auto it = r.fields.find(name);
    if (it == r.fields.end()) Fail(r.pos, "field '" + name + "' missing");
    return it->second;
  }

 private:
  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
};

struct Chunk {
  uint32_t size = 0;  // uncompressed
  bool compressed = false;
  std::set<uint32_t> message_offsets;  // uncompressed chunks: offsets of message records
};

}  // namespace

void CheckBagStructure(const std::string& path) {
  Walker w(path);
  if (w.size() < kMagicBytes || w.Read(0, kMagicBytes) != std::string(kMagic, kMagicBytes)) {
    w.Fail(0, "no '#ROSBAG V2.0' magic");
  }
  const Record header = w.ReadRecord(kMagicBytes, w.size());
  if (header.op != kOpFileHeader) w.Fail(header.pos, "the first record is not the file header");
  const uint64_t index_pos = w.Field<uint64_t>(header, "index_pos");
  w.Field<uint32_t>(header, "conn_count");
  w.Field<uint32_t>(header, "chunk_count");
  if (const auto e = header.fields.find("encryptor");
      e != header.fields.end() && !e->second.empty() && e->second != "rosbag/NoEncryptor") {
    w.Fail(header.pos, "encrypted bag (" + e->second + "): not supported");
  }
  if (index_pos == 0) w.Fail(header.pos, "unindexed bag (not closed properly; run rosbag reindex)");

  std::set<uint64_t> boundaries;
  std::map<uint64_t, Chunk> chunks;  // by record position
  const Chunk* last_chunk = nullptr;
  for (uint64_t pos = header.end(); pos < w.size();) {
    const Record r = w.ReadRecord(pos, w.size());
    boundaries.insert(pos);
    switch (r.op) {
      case kOpChunk: {
        Chunk c;
        const std::string compression = w.StringField(r, "compression");
        c.size = w.Field<uint32_t>(r, "size");
        c.compressed = compression != "none";
        if (compression != "none" && compression != "lz4" && compression != "bz2") {
          w.Fail(pos, "unknown chunk compression '" + compression + "'");
        }
        if (!c.compressed && c.size != r.data_len) {
          w.Fail(pos, "uncompressed chunk of " + std::to_string(r.data_len) + " bytes declares " +
                          std::to_string(c.size));
        }
        if (c.size > kMaxChunkBytes || c.size > kMaxChunkExpansion * r.data_len + 4096) {
          w.Fail(pos, "chunk declares " + std::to_string(c.size) + " uncompressed bytes from " +
                          std::to_string(r.data_len));
        }
        if (!c.compressed) {
          for (uint64_t p = r.data_pos; p < r.end();) {
            const Record inner = w.ReadRecord(p, r.end());
            if (inner.op == kOpMessage) {
              w.Field<uint32_t>(inner, "conn");
              w.Field<uint64_t>(inner, "time");
              c.message_offsets.insert(static_cast<uint32_t>(p - r.data_pos));
            } else if (inner.op != kOpConnection) {
              w.Fail(p, "record of op " + std::to_string(inner.op) + " inside a chunk");
            }
            p = inner.end();
          }
        }
        last_chunk = &(chunks[pos] = std::move(c));
        break;
      }
      case kOpIndexData: {
        if (w.Field<uint32_t>(r, "ver") != 1) w.Fail(pos, "index data version is not 1");
        w.Field<uint32_t>(r, "conn");
        const uint32_t count = w.Field<uint32_t>(r, "count");
        if (uint64_t{count} * 12 != r.data_len) w.Fail(pos, "index data length != 12 × count");
        if (last_chunk == nullptr) w.Fail(pos, "index data before any chunk");
        const std::string entries = w.Read(r.data_pos, r.data_len);
        for (uint32_t i = 0; i < count; ++i) {
          uint32_t offset;
          std::memcpy(&offset, entries.data() + 12 * i + 8, 4);
          const bool ok = last_chunk->compressed ? offset < last_chunk->size
                                                 : last_chunk->message_offsets.count(offset) > 0;
          if (!ok) w.Fail(pos, "index entry " + std::to_string(i) + " points outside its chunk");
        }
        break;
      }
      case kOpConnection:
        w.Field<uint32_t>(r, "conn");
        w.StringField(r, "topic");
        break;
      case kOpChunkInfo: {
        if (w.Field<uint32_t>(r, "ver") != 1) w.Fail(pos, "chunk info version is not 1");
        const uint64_t chunk_pos = w.Field<uint64_t>(r, "chunk_pos");
        w.Field<uint64_t>(r, "start_time");
        w.Field<uint64_t>(r, "end_time");
        const uint32_t count = w.Field<uint32_t>(r, "count");
        if (uint64_t{count} * 8 != r.data_len) w.Fail(pos, "chunk info length != 8 × count");
        if (!chunks.count(chunk_pos)) w.Fail(pos, "chunk info pointing at no chunk");
        break;
      }
      default:
        w.Fail(pos, "unknown record op " + std::to_string(r.op));
    }
    pos = r.end();
  }
  if (!boundaries.count(index_pos)) w.Fail(header.pos, "index position is not a record");
}

}  // namespace ctlio::io
