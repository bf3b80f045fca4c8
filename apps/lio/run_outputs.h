// Files a run writes for a person to read beside its trajectory: the per-scan log and the SVG top
// view used when matplotlib is missing.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "covariance_output.h"  // the pose covariance files
#include "ctlio/io/dataset.h"
#include "run_odometry.h"

namespace ctlio::lioapp {

// Per-scan log (the write is checked: an error names the path): t, status, keypoints,
// associations, imu residuals, rounds, solver iterations, final cost, ms (total and per stage),
// CPU ms, position, IMU samples rejected, points dropped, the degeneracy analysis (normalised
// smallest eigenvalue of the translation and rotation blocks, number of degenerate directions,
// the least constrained one "t:x,y,z"/"r:x,y,z" in the body frame, the lidar's and the prior's
// information along it; "-" where not analysed), message.
void WriteScanLog(const std::string& path, const RunSummary& run);

// Top view (x–y) of the ground truth (grey) and the aligned estimate (red) as an SVG file with
// axes in metres and the title wrapped: the fallback when matplotlib is missing.
void WriteTopViewSvg(const std::string& path, const std::vector<io::StampedPose>& estimate,
                     const std::vector<io::StampedPose>& truth, const Eigen::Matrix4d& alignment,
                     const std::string& title);

}  // namespace ctlio::lioapp
