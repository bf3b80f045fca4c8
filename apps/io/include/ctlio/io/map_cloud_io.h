// Map files: a registered cloud in a map frame (ctlio_odometry --save_map), x y z float32 per
// point and nothing else (a map has no per-point time, ring or range: point_cloud_io.h's
// WritePcd writes the Ouster fields of a sensor sweep). Written by ctlio itself, every write
// checked (a full disk or an unwritable path is an error naming the file), and read back by
// ReadPcd / ReadPly / ReadPointCloud of point_cloud_io.h.
#pragma once

#include <string>
#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::io {

enum class MapFormat { kPcd, kPly };

// The format of `path` by its extension, .pcd or .ply (lower case, as ReadPointCloud reads
// them); throws std::invalid_argument naming the path and the two extensions otherwise.
MapFormat MapFormatOf(const std::string& path);

// Binary PCD v0.7 (FIELDS x y z, SIZE 4, TYPE F, WIDTH n, HEIGHT 1, VIEWPOINT identity) or
// binary little-endian PLY (one vertex element with float x y z), by the extension. Coordinates
// are rounded to float32: 0.1 mm or better up to 1 km from the origin.
void WriteMapCloud(const std::string& path, const std::vector<Vec3>& points);

}  // namespace ctlio::io
