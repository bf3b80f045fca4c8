// Helpers of the icp_pairs experiment (icp_pairs.cc, icp_replay.cc): not a library.
#pragma once

#include <string>
#include <vector>

#include "ctlio/io/point_cloud_io.h"
#include "ctlio/manifolds/se3.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "loam_features.h"

namespace ctlio::icp_pairs {

// float32 x y z files; "a+b" joins two.
std::vector<Vec3> ReadSweep(const std::string& spec);
// LOAM features of a sweep (indices kept; loam_features.h), or with ICP_PROPORTIONAL_FEATURES=1
// the flattest 31 % and sharpest 2 % per ring.
std::vector<size_t> LoamLikeFeatures(const io::PointCloud& c);
// The LOAM selection's options with ICP_LOAM_LESS_SHARP applied.
LoamFeatureOptions LoamOptionsFromEnvironment();
// ICP_SHAKE_SCALE, ICP_RELIEF, ICP_GRASS_RELIEF.
void ApplyWorldOverrides(sim::SimConfig* c);
// ICP_EFFECT_ONLY, ICP_EFFECT_DROP.
void ApplyEffectOverrides(sim::SimConfig* c);
// Registers source to target from `truth` perturbed; prints and returns the translation error [m].
double Pair(const std::string& label, const std::vector<Vec3>& target,
            const std::vector<Vec3>& source, const SE3& truth);
// The keyframe poses of a gtsam_points graph.txt ("id x y z qx qy qz qw" per line).
std::vector<SE3> ReadGraph(const std::string& path);
// `icp_pairs replay ...`; returns the exit code.
int Replay(int argc, char** argv);

}  // namespace ctlio::icp_pairs
