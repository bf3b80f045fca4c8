#include "compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include <array>
#include <memory>
#include <stdexcept>

namespace ctlio::io::ros2 {
namespace {

std::vector<uint8_t> DecompressZstd(const uint8_t* in, size_t in_size, std::vector<uint8_t> out,
                                    const std::string& what) {
  // ZSTD_decompress fails (rather than writes past) when the frames hold more than the buffer.
  const size_t n = ZSTD_decompress(out.data(), out.size(), in, in_size);
  if (ZSTD_isError(n)) {
    throw std::runtime_error(what + ": zstd: " + ZSTD_getErrorName(n));
  }
  if (n != out.size()) {
    throw std::runtime_error(what + ": decompresses to " + std::to_string(n) +
                             " bytes, its header says " + std::to_string(out.size()));
  }
  return out;
}

std::vector<uint8_t> DecompressLz4(const uint8_t* in, size_t in_size, std::vector<uint8_t> out,
                                   const std::string& what) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
    throw std::runtime_error(what + ": cannot create an lz4 context");
  }
  std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> ctx(
      raw, &LZ4F_freeDecompressionContext);
  size_t in_pos = 0, out_pos = 0;
  size_t hint = 1;
  // One or more concatenated frames; each call consumes input and/or produces output, so the loop
  // ends (a call that does neither means the output is full while input remains).
  while (in_pos < in_size) {
    size_t dst = out.size() - out_pos, src = in_size - in_pos;
    hint = LZ4F_decompress(ctx.get(), out.data() + out_pos, &dst, in + in_pos, &src, nullptr);
    if (LZ4F_isError(hint)) {
      throw std::runtime_error(what + ": lz4: " + LZ4F_getErrorName(hint));
    }
    if (dst == 0 && src == 0) {
      throw std::runtime_error(what + ": decompresses to more than the " +
                               std::to_string(out.size()) + " bytes its header says");
    }
    in_pos += src;
    out_pos += dst;
  }
  if (hint != 0) throw std::runtime_error(what + ": lz4 frame is truncated");
  if (out_pos != out.size()) {
    throw std::runtime_error(what + ": decompresses to " + std::to_string(out_pos) +
                             " bytes, its header says " + std::to_string(out.size()));
  }
  return out;
}

}  // namespace

std::vector<uint8_t> Decompress(const std::string& codec, const uint8_t* in, size_t in_size,
                                uint64_t uncompressed_size, const std::string& what) {
  if (codec.empty()) {
    if (uncompressed_size != in_size) {
      throw std::runtime_error(what + ": uncompressed size " + std::to_string(uncompressed_size) +
                               " differs from its " + std::to_string(in_size) +
                               " bytes of records");
    }
    return std::vector<uint8_t>(in, in + in_size);
  }
  if (codec != "zstd" && codec != "lz4") {
    throw std::runtime_error(what + ": unsupported compression '" + codec +
                             "' (ctlio reads none, zstd and lz4)");
  }
  if (uncompressed_size > kMaxChunkBytes ||
      uncompressed_size > kMaxExpansion * static_cast<uint64_t>(in_size) + (1u << 20)) {
    throw std::runtime_error(what + ": uncompressed size " + std::to_string(uncompressed_size) +
                             " bytes from " + std::to_string(in_size) +
                             " compressed is beyond ctlio's limit (1 GiB, 1000x + 1 MiB)");
  }
  std::vector<uint8_t> out(static_cast<size_t>(uncompressed_size));
  if (codec == "zstd") return DecompressZstd(in, in_size, std::move(out), what);
  return DecompressLz4(in, in_size, std::move(out), what);
}

std::vector<uint8_t> Compress(const std::string& codec, const std::vector<uint8_t>& in) {
  if (codec.empty()) return in;
  if (codec == "zstd") {
    std::vector<uint8_t> out(ZSTD_compressBound(in.size()));
    const size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3);
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return out;
  }
  if (codec == "lz4") {
    LZ4F_preferences_t prefs{};
    prefs.frameInfo.contentSize = in.size();
    std::vector<uint8_t> out(LZ4F_compressFrameBound(in.size(), &prefs));
    const size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), &prefs);
    if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(n));
    out.resize(n);
    return out;
  }
  throw std::runtime_error("unsupported compression '" + codec + "'");
}

uint32_t Crc32(const uint8_t* data, size_t size, uint32_t crc) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

}  // namespace ctlio::io::ros2
