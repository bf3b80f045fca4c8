// The chunk codecs of MCAP (https://mcap.dev/spec, "Chunk": "", "zstd", "lz4" — the LZ4 *frame*
// format) over Debian's libzstd and liblz4, and the CRC-32 its records carry.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ctlio::io::ros2 {

// A decompressed chunk may be at most this large, and at most kMaxExpansion times its compressed
// size plus 1 MiB: a corrupt size cannot allocate gigabytes, and a real chunk (rosbag2 writes
// ~1 MiB chunks; sensor data compresses 2–10×) is far inside both.
constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 30;
constexpr uint64_t kMaxExpansion = 1000;

// Decompresses `in` (codec "zstd" or "lz4"; "" copies) into exactly `uncompressed_size` bytes.
// Throws std::runtime_error starting with `what` ("<file>: chunk at byte N") when the size is
// beyond the limits above, the data is corrupt, or it decompresses to another size.
std::vector<uint8_t> Decompress(const std::string& codec, const uint8_t* in, size_t in_size,
                                uint64_t uncompressed_size, const std::string& what);

// Compresses `in` with "zstd" or "lz4" (frame format); "" copies.
std::vector<uint8_t> Compress(const std::string& codec, const std::vector<uint8_t>& in);

// CRC-32 (ISO-HDLC, as zlib's crc32), continuing from `crc` (0 to start).
uint32_t Crc32(const uint8_t* data, size_t size, uint32_t crc = 0);

}  // namespace ctlio::io::ros2
