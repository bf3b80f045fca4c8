// The record structure of a ROS 1 bag (format 2.0), checked against the file before Debian's
// librosbag reads it: that library trusts the lengths, counts and offsets it finds (a corrupt
// length is a multi-GB allocation, an index offset outside its chunk a read out of bounds). The
// check walks the records by seeking (headers only, the bulk data is never read, so a bag of tens
// of GB costs milliseconds):
//   * every record's header and data lengths fit in the file (or in its chunk), header fields are
//     well-formed `len name=value` entries, each record has a known op code;
//   * the file header's index position is a record boundary; no encryption (ctlio reads none);
//   * chunks: compression none | lz4 | bz2; uncompressed size equal to the data length (none) or
//     at most kMaxChunkExpansion times it (lz4, bz2) and at most kMaxChunkBytes; in an
//     uncompressed chunk every inner record (connection, message) fits the chunk;
//   * index data: version 1, 12 bytes per entry, each entry's offset inside the chunk before it
//     (uncompressed chunks: at a message record of that chunk);
//   * chunk info: version 1, 8 bytes per connection count, its chunk position a chunk record.
// What it cannot see: the inside of compressed chunks (checked by their CRC/checksum in
// librosbag, not here), and messages whose bytes do not match their type (the deserialiser's
// errors are caught by RosbagSource).
#pragma once

#include <cstdint>
#include <string>

namespace ctlio::io {

// Chunk limits: real bags hold chunks of ~768 KiB (rosbag's default threshold) up to one large
// message (a 128-beam cloud is ~25 MB); lidar data compress by far less than 100×.
constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 30;  // 1 GiB uncompressed
constexpr uint64_t kMaxChunkExpansion = 1000;

// Throws std::runtime_error "<path>: not a valid ROS 1 bag (truncated or corrupted?): at byte N:
// <what>" on the first
// inconsistency; returns silently for a well-formed bag.
void CheckBagStructure(const std::string& path);

}  // namespace ctlio::io
