#include "ctlio/solvers/lio/continuous_lidar_term.h"

#include <algorithm>
#include <functional>
#include <map>
#include <stdexcept>
#include <vector>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/factors/lidar/continuous_point_to_plane_batch.h"
#include "ctlio/factors/lidar/continuous_point_to_plane_extrinsic.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/solvers/parallel_for.h"

namespace ctlio::lio {

ContinuousLidarTerm::ContinuousLidarTerm(const gp::SingerModel<6>& model,
                                         const std::vector<TimedKnot>& knots,
                                         const std::vector<TimedPoint>& keypoints,
                                         SlidingWindow* window)
    : keypoints_(keypoints) {
  if (knots.size() < 2) throw std::invalid_argument("ContinuousLidarTerm: need two knots or more");
  for (size_t j = 0; j + 1 < knots.size(); ++j) {
    if (!(knots[j].t < knots[j + 1].t)) {
      throw std::invalid_argument("ContinuousLidarTerm: knot times must increase");
    }
    states_.push_back(KnotPair(knots[j].keys, knots[j + 1].keys));
    SharedPoseInterpolation::KnotBlocks blocks;
    for (int b = 0; b < 6; ++b) blocks[b] = window->State(states_.back()[b]);
    blocks_.push_back(blocks);
  }
  newest_pose_ = blocks_.back()[3];
  const double t_first = knots.front().t, t_last = knots.back().t;
  firing_.resize(keypoints.size());
  std::map<double, int> by_time;
  std::vector<double> taus;  // per firing
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const double tau = std::clamp(keypoints[i].time, t_first, t_last);
    const auto [it, inserted] = by_time.try_emplace(tau, static_cast<int>(taus.size()));
    if (inserted) {
      // The interval that holds τ: the first whose end is not before it.
      size_t j = 0;
      while (j + 2 < knots.size() && tau > knots[j + 1].t) ++j;
      interval_.push_back(static_cast<int>(j));
      taus.push_back(tau);
    }
    firing_[i] = it->second;
  }
  // The firings' interpolators (~5k instructions each, ~600 per scan) on the window's threads;
  // registered with the window in firing order.
  firings_.resize(taus.size());
  ParallelFor(window->options().threads, taus.size(), [&](size_t, size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      const size_t j = static_cast<size_t>(interval_[f]);
      firings_[f] = std::make_shared<SharedPoseInterpolation>(
          std::make_shared<const gp::GpInterpolator>(model, knots[j].t, knots[j + 1].t, taus[f]),
          blocks_[j]);
    }
  });
  for (const auto& firing : firings_) window->shared_interpolations().Add(firing);
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
    std::vector<StateId> states = states_[static_cast<size_t>(interval_of(i))];
    states.push_back(kExtrinsicKey);
    costs_[i] = new ContinuousPointToPlaneExtrinsic(firing, association, points_lidar_[i]);
    return window->AddResidualBlock(costs_[i], loss, states);
  }
  costs_[i] = new ContinuousPointToPlane(firing, association);
  return window->AddResidualBlock(costs_[i], loss, states_[static_cast<size_t>(interval_of(i))]);
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

void ContinuousLidarTerm::SetBatchResiduals(const std::vector<uint8_t>& associated,
                                            const std::vector<PlaneAssociation>& planes,
                                            const std::shared_ptr<const ceres::LossFunction>& loss,
                                            SlidingWindow* window,
                                            std::vector<ceres::ResidualBlockId>* blocks) {
  if (!batched()) throw std::logic_error("ContinuousLidarTerm::SetBatchResiduals: not batched");
  for (ceres::ResidualBlockId id : *blocks) window->RemoveResidualBlock(id);
  blocks->clear();
  // Per interval, its keypoints in keypoint order.
  std::vector<std::vector<ContinuousPointToPlaneBatch::Point>> points(states_.size());
  for (size_t i = 0; i < keypoints_.size(); ++i) {
    if (!associated[i]) continue;
    const std::shared_ptr<SharedPoseInterpolation>& firing = firings_[firing_[i]];
    firing->set_active(true);  // a residual reads it in this round's solve
    // With the extrinsic the row is ContinuousPointToPlaneExtrinsic's, of the lidar-frame point.
    points[static_cast<size_t>(interval_of(i))].push_back(
        {firing, planes[i], extrinsic_ != nullptr ? points_lidar_[i] : Vec3::Zero()});
  }
  for (size_t j = 0; j < points.size(); ++j) {
    if (points[j].empty()) continue;
    using Form = ContinuousPointToPlaneBatch::Form;
    // The square-root form has W + 1 = 37 rows: fewer only for more points than that.
    const Form form = batch_form_ == Form::kSquareRoot && points[j].size() > 37 ? Form::kSquareRoot
                                                                                : Form::kPointRows;
    // A few hundred rows are worth a second thread (~0.1 ms each per evaluation); a handful not.
    const bool worth_threads = points[j].size() >= 128;
    auto* batch =
        new ContinuousPointToPlaneBatch(std::move(points[j]), loss, extrinsic_ != nullptr, form);
    if (const int threads = window->options().threads; threads > 1 && worth_threads) {
      // In the window's solve only (SlidingWindow::solving).
      batch->set_row_runner(
          [threads, window](size_t n, const std::function<void(size_t, size_t)>& rows) {
            ParallelFor(window->solving() ? threads : 1, n,
                        [&](size_t, size_t begin, size_t end) { rows(begin, end); });
          });
    }
    std::vector<StateId> states = states_[j];
    if (extrinsic_ != nullptr) states.push_back(kExtrinsicKey);
    blocks->push_back(window->AddResidualBlock(batch, nullptr, states));
  }
}

ContinuousLidarTerm::ContinuousLidarTerm(const gp::SingerModel<6>& model,
                                         const std::vector<TimedKnot>& knots,
                                         const std::vector<TimedPoint>& keypoints,
                                         const SE3& T_robot_lidar, SlidingWindow* window)
    : ContinuousLidarTerm(model, knots, keypoints, window) {
  extrinsic_ = window->State(kExtrinsicKey);
  const SE3 T_lidar_robot = T_robot_lidar.Inverse();
  points_lidar_.reserve(keypoints.size());
  for (const TimedPoint& p : keypoints) points_lidar_.push_back(T_lidar_robot * p.point);
}

SE3 ContinuousLidarTerm::NewestPose() const { return PoseManifold::Pose(newest_pose_); }

}  // namespace ctlio::lio
