// The interpolated pose T_rm(τ) (gp::GpInterpolator, SPEC §2), shared by all residuals whose
// points were measured at the same time τ (the points of one lidar firing). SPEC §4 keeps one
// residual per point, each with its own robust loss; only the interpolation is shared. Prepared
// or computed on demand, with identical values: gp/shared_interpolation.h.
//
// What is prepared is T(τ) and the τ-dependent factors of its Jacobian (J(ξ), Ad(Exp ξ):
// GpInterpolator::PoseAt); each residual chains its own row ∂e/∂δT(τ) onto the knots
// (GpInterpolator::ChainPose) with the knot interval's local variables, which the window forms
// once for all firings on the interval (gp/shared_knot_interval.h). A scan's ~600 keypoints fall
// on ~600 different firings, so a residual rarely shares its firing: a few row-vector products
// per residual cost less than the firing's full 6×18 Jacobians would.
#pragma once

#include <memory>
#include <optional>
#include <utility>

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/shared_interpolation.h"

namespace ctlio {

class SharedPoseInterpolation final : public gp::SharedInterpolation {
 public:
  using KnotBlocks = gp::KnotBlocks;

  explicit SharedPoseInterpolation(std::shared_ptr<const gp::GpInterpolator> interpolator,
                                   const KnotBlocks& knots = {})
      : SharedInterpolation(knots), interpolator_(std::move(interpolator)) {}

  // What a read returns: T(τ) with the factors of its Jacobian, and the interval's local
  // variables they chain with.
  struct Result {
    gp::GpInterpolator::PoseAtTau at;
    const gp::LocalVariables* local = nullptr;
  };
  // Storage for a read that interpolates on its own.
  struct Scratch {
    Result result;
    std::optional<gp::LocalVariables> local;
  };

  // T(τ) of the last Prepare().
  const SE3& pose() const { return prepared_.at.T; }

  // T(τ) at `parameters` (the six knot blocks' values, in the KnotBlocks order), ready for
  // Chain() when `jacobians`: the prepared result if it was prepared at exactly these values (and
  // its interval still holds them), otherwise interpolated into *scratch.
  const Result& Pose(double const* const* parameters, bool jacobians, Scratch* scratch) const {
    if (PreparedAt(parameters)) {
      const gp::LocalVariables* local = own_local_ ? &*own_local_ : IntervalLocal();
      if (local != nullptr && local == prepared_.local) return prepared_;
    }
    CountComputed();
    const gp::KnotState k = gp::ReadKnotState(parameters[0], parameters[1], parameters[2]);
    const gp::KnotState k1 = gp::ReadKnotState(parameters[3], parameters[4], parameters[5]);
    scratch->local.emplace(k, k1, jacobians);
    if (jacobians) scratch->local->AddChainProducts();
    interpolator_->PoseAt(k, *scratch->local, &scratch->result.at);
    scratch->result.local = &*scratch->local;
    return scratch->result;
  }

  // u·∂δT(τ)/∂(knot k) and u·∂δT(τ)/∂(knot k+1) (1×18 each, [δT, δϖ, δϖ̇]; either may be null)
  // for u = ∂e/∂δT(τ), at a result of Pose(…, jacobians = true, …).
  void Chain(const Result& at, const Eigen::Matrix<double, 1, 6>& u,
             Eigen::Matrix<double, 1, 18>* J_k, Eigen::Matrix<double, 1, 18>* J_k1) const {
    interpolator_->ChainPose(at.at, *at.local, u, J_k, J_k1);
  }

  const gp::GpInterpolator& interpolator() const { return *interpolator_; }

 private:
  void Interpolate(const gp::KnotValues& values, const gp::LocalVariables* local) override {
    if (local == nullptr) {  // no interval to share: the firing's own local variables
      own_local_.emplace(values.Knot(0), values.Knot(1), /*with_jacobians=*/true);
      own_local_->AddChainProducts();
      local = &*own_local_;
    } else {
      own_local_.reset();
    }
    interpolator_->PoseAt(values.Knot(0), *local, &prepared_.at);
    prepared_.local = local;
  }

  std::shared_ptr<const gp::GpInterpolator> interpolator_;
  Result prepared_;
  std::optional<gp::LocalVariables> own_local_;
};

}  // namespace ctlio
