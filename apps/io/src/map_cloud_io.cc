#include "ctlio/io/map_cloud_io.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "ctlio/io/checked_output.h"

namespace ctlio::io {

namespace {

// The points as little-endian float32 triples (PCD binary and PLY binary_little_endian both),
// written in blocks so that a map of millions of points needs no second copy of itself.
void WriteXyz(std::ofstream& out, const std::vector<Vec3>& points) {
  static_assert(sizeof(float) == 4, "float32 expected");
  constexpr size_t kBlock = 4096;
  std::vector<unsigned char> buffer(kBlock * 12);
  for (size_t begin = 0; begin < points.size(); begin += kBlock) {
    const size_t n = std::min(kBlock, points.size() - begin);
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        const float v = static_cast<float>(points[begin + i][k]);
        uint32_t bits;
        std::memcpy(&bits, &v, 4);
        for (int b = 0; b < 4; ++b) {
          buffer[12 * i + 4 * k + b] = (bits >> (8 * b)) & 0xFF;
        }
      }
    }
    out.write(reinterpret_cast<const char*>(buffer.data()), static_cast<std::streamsize>(12 * n));
  }
}

}  // namespace

MapFormat MapFormatOf(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".pcd") {
    return MapFormat::kPcd;
  }
  if (ext == ".ply") {
    return MapFormat::kPly;
  }
  throw std::invalid_argument(path + ": a map file must end in .pcd or .ply");
}

void WriteMapCloud(const std::string& path, const std::vector<Vec3>& points) {
  const MapFormat format = MapFormatOf(path);
  std::ofstream out = OpenForWriting(path, std::ios::out | std::ios::binary | std::ios::trunc);
  const size_t n = points.size();
  if (format == MapFormat::kPcd) {
    out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
        << "TYPE F F F\nCOUNT 1 1 1\nWIDTH " << n << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS "
        << n << "\nDATA binary\n";
  } else {
    out << "ply\nformat binary_little_endian 1.0\ncomment ctlio map\nelement vertex " << n
        << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  }
  WriteXyz(out, points);
  CloseChecked(out, path);
}

}  // namespace ctlio::io
