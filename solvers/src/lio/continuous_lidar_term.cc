#include "ctlio/solvers/lio/continuous_lidar_term.h"

#include <algorithm>
#include <map>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/factors/lidar/continuous_point_to_plane_extrinsic.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio::lio {

ContinuousLidarTerm::ContinuousLidarTerm(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                         const KnotKeys& k, const KnotKeys& k1,
                                         const std::vector<TimedPoint>& keypoints,
                                         SlidingWindow* window)
    : keypoints_(keypoints), states_(KnotPair(k, k1)) {
  for (int b = 0; b < 6; ++b) blocks_[b] = window->State(states_[b]);
  firing_.resize(keypoints.size());
  std::map<double, int> by_time;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const double tau = std::clamp(keypoints[i].time, t_k, t_k1);
    const auto [it, inserted] = by_time.try_emplace(tau, static_cast<int>(firings_.size()));
    if (inserted) {
      firings_.push_back(std::make_shared<SharedPoseInterpolation>(
          std::make_shared<const gp::GpInterpolator>(model, t_k, t_k1, tau), blocks_));
      window->shared_interpolations().Add(firings_.back());
    }
    firing_[i] = it->second;
  }
}

void ContinuousLidarTerm::BeginRound() {
  T_mr_.assign(firings_.size(), SE3());
  located_.assign(firings_.size(), false);
  // Until a residual of this round reads it, the callback need not prepare a firing.
  for (const auto& f : firings_) f->set_active(false);
  if (extrinsic_ != nullptr) T_rl_ = PoseManifold::Pose(extrinsic_);
}

void ContinuousLidarTerm::Locate(size_t i, Vec3* q, Vec3* p_map) {
  const int f = firing_[i];
  if (!located_[f]) {
    // The interpolation at the current estimate, which the solve then starts from.
    firings_[f]->Prepare();
    T_mr_[f] = firings_[f]->pose().Inverse();
    located_[f] = true;
  }
  // With calibration the robot-frame point follows the extrinsic's current estimate.
  *q = extrinsic_ != nullptr ? T_rl_ * points_lidar_[i] : keypoints_[i].point;
  *p_map = T_mr_[f] * *q;
}

ceres::ResidualBlockId ContinuousLidarTerm::AddResidual(size_t i,
                                                        const PlaneAssociation& association,
                                                        ceres::LossFunction* loss,
                                                        SlidingWindow* window) {
  const std::shared_ptr<SharedPoseInterpolation>& firing = firings_[firing_[i]];
  firing->set_active(true);
  if (costs_.empty()) costs_.resize(keypoints_.size(), nullptr);
  if (extrinsic_ != nullptr) {
    std::vector<StateId> states = states_;
    states.push_back(kExtrinsicKey);
    costs_[i] = new ContinuousPointToPlaneExtrinsic(firing, association, points_lidar_[i]);
    return window->AddResidualBlock(costs_[i], loss, states);
  }
  costs_[i] = new ContinuousPointToPlane(firing, association);
  return window->AddResidualBlock(costs_[i], loss, states_);
}

void ContinuousLidarTerm::UpdateResidual(size_t i, const PlaneAssociation& association) {
  // The residual reads its firing's interpolation in this round's solve.
  firings_[firing_[i]]->set_active(true);
  if (extrinsic_ != nullptr) {
    static_cast<ContinuousPointToPlaneExtrinsic*>(costs_[i])->set_association(association);
  } else {
    static_cast<ContinuousPointToPlane*>(costs_[i])->set_association(association);
  }
}

ContinuousLidarTerm::ContinuousLidarTerm(const gp::SingerModel<6>& model, double t_k, double t_k1,
                                         const KnotKeys& k, const KnotKeys& k1,
                                         const std::vector<TimedPoint>& keypoints,
                                         const SE3& T_robot_lidar, SlidingWindow* window)
    : ContinuousLidarTerm(model, t_k, t_k1, k, k1, keypoints, window) {
  extrinsic_ = window->State(kExtrinsicKey);
  const SE3 T_lidar_robot = T_robot_lidar.Inverse();
  points_lidar_.reserve(keypoints.size());
  for (const TimedPoint& p : keypoints) points_lidar_.push_back(T_lidar_robot * p.point);
}

SE3 ContinuousLidarTerm::NewestPose() const { return PoseManifold::Pose(blocks_[3]); }

}  // namespace ctlio::lio
