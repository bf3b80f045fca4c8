// Trajectory files for evaluation (SPEC §6):
//   TUM:   one pose per line "t x y z qx qy qz qw" (t in seconds, Hamilton quaternion, w last);
//          '#' lines are comments. Times are parsed exactly to int64 ns.
//   KITTI: one pose per line, the first 3 rows of the 4×4 matrix, row-major (12 numbers). KITTI
//          poses carry no time: they come from a separate times file (one time in seconds per
//          line, as KITTI's times.txt) or, without one, t = index · 0.1 s.
#pragma once

#include <string>
#include <vector>

#include "ctlio/io/dataset.h"

namespace ctlio::io {

std::vector<StampedPose> ReadTum(const std::string& path);
void WriteTum(const std::string& path, const std::vector<StampedPose>& poses);

std::vector<StampedPose> ReadKittiPoses(const std::string& path,
                                        const std::string& times_path = "");
void WriteKittiPoses(const std::string& path, const std::vector<StampedPose>& poses);

// Reads either format: a line with 8 numbers is TUM, one with 12 is KITTI.
std::vector<StampedPose> ReadTrajectory(const std::string& path,
                                        const std::string& kitti_times_path = "");

}  // namespace ctlio::io
