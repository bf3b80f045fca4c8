#include "ctlio/solvers/lio/continuous_lidar_term.h"

#include <algorithm>
#include <map>

#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::lio {

ContinuousLidarTerm::ContinuousLidarTerm(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                         const KnotKeys& k, const KnotKeys& k1,
                                         const std::vector<TimedPoint>& keypoints,
                                         const SlidingWindow& window)
    : keypoints_(keypoints), states_(KnotPair(k, k1)) {
  for (int b = 0; b < 6; ++b) blocks_[b] = window.State(states_[b]);
  firing_.resize(keypoints.size());
  std::map<double, int> by_time;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const double tau = std::clamp(keypoints[i].time, t_k, t_k1);
    const auto [it, inserted] = by_time.try_emplace(tau, static_cast<int>(interpolators_.size()));
    if (inserted) {
      interpolators_.push_back(std::make_shared<const gp::GpInterpolator>(model, t_k, t_k1, tau));
    }
    firing_[i] = it->second;
  }
}

void ContinuousLidarTerm::BeginRound() {
  T_mr_.assign(interpolators_.size(), SE3());
  located_.assign(interpolators_.size(), false);
  // The previous round's residuals are gone; their firings expire with the last reference.
  shared_.assign(interpolators_.size(), nullptr);
}

void ContinuousLidarTerm::Locate(size_t i, Vec3* q, Vec3* p_map) {
  const int f = firing_[i];
  if (!located_[f]) {
    SE3 T_rm;
    interpolators_[f]->Pose(gp::ReadKnotState(blocks_[0], blocks_[1], blocks_[2]),
                            gp::ReadKnotState(blocks_[3], blocks_[4], blocks_[5]), &T_rm, nullptr,
                            nullptr);
    T_mr_[f] = T_rm.Inverse();
    located_[f] = true;
  }
  *q = keypoints_[i].point;
  *p_map = T_mr_[f] * keypoints_[i].point;
}

ceres::ResidualBlockId ContinuousLidarTerm::AddResidual(size_t i,
                                                        const PlaneAssociation& association,
                                                        ceres::LossFunction* loss,
                                                        SlidingWindow* window) {
  std::shared_ptr<SharedPoseInterpolation>& shared = shared_[firing_[i]];
  if (shared == nullptr) {
    shared = std::make_shared<SharedPoseInterpolation>(interpolators_[firing_[i]], blocks_);
    window->shared_interpolations().Add(shared);
  }
  return window->AddResidualBlock(new ContinuousPointToPlane(shared, association), loss, states_);
}

SE3 ContinuousLidarTerm::NewestPose() const { return PoseManifold::Pose(blocks_[3]); }

}  // namespace ctlio::lio
