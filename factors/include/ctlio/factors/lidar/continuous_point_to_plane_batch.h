// The continuous-time point-to-plane residuals of all keypoints on one knot interval as ONE
// residual block (SPEC §4): row i is keypoint i's ContinuousPointToPlane residual, evaluated by
// the same code (ContinuousPointToPlane::EvaluateAtKnots, the one GP interpolation), with its
// robust loss applied inside the block. Still one residual per point (SPEC §4: points are not
// summed before squaring); what is batched is Ceres' per-block machinery — the evaluation call,
// the invalidation and validity check, the loss correction and the manifold product, ~2/3 of the
// instructions of a per-point block's evaluation (docs/experiments/latency.md) — which runs once
// per interval instead of once per keypoint.
//
// Why the loss goes inside, and how: Ceres robustifies a residual BLOCK by ρ(‖r‖²), so a block
// of N points with a Ceres loss would be one robust term, not N. The block therefore applies
// each row's loss itself, exactly as Ceres' Corrector would to a one-point block (Triggs et al.,
// "Bundle adjustment — a modern synthesis", §4.3, in the form Ceres uses for ρ'' ≤ 0, which holds
// for Cauchy, Huber, SoftL1 and Arctan): row i is √ρ'(e_i²)·e_i with Jacobian √ρ'(e_i²)·∂e_i.
// Those rows carry the gradient Σρ'e_i∂e_i and the Gauss–Newton Hessian Σρ'∂e_iᵀ∂e_i of N
// per-point blocks, but their squares sum to Σρ'e_i², not to the robust cost Σρ(e_i²); one more
// row, constant (zero Jacobian), holds the difference,
//
//   r_N = √(Σ_i ρ(e_i²) − ρ'(e_i²)·e_i²)   (≥ 0: a concave ρ with ρ(0) = 0 has ρ(s) ≥ ρ'(s)·s),
//
// so ½‖r‖² is the robust cost Ceres would report. Cost, gradient and Gauss–Newton Hessian — the
// whole Levenberg–Marquardt step and its acceptance test — and the marginalisation's
// linearisation (SlidingWindow::Linearize, which applies no loss to this block) are those of the
// per-point blocks up to rounding (test lidar.ContinuousPointToPlaneBatch.*). As with Ceres'
// corrected Jacobian, the rows' Jacobian is the Gauss–Newton one, not the derivative of the
// scaled rows: without a loss there is no extra row and the block is an ordinary cost function
// (its Jacobians are checked numerically). A loss with ρ'' > 0 somewhere (convex, e.g. Tolerant)
// has no such constant row: Evaluate returns false there.
//
// With the extrinsic (online calibration) each row is instead the ContinuousPointToPlaneExtrinsic
// residual of the point's lidar-frame coordinates, T_rl read once per evaluation.
//
// Square-root form (Form::kSquareRoot). Those rows reach Ceres only through JᵀJ, Jᵀr and ‖r‖²:
// the Levenberg–Marquardt step, its model cost change and acceptance test, the Jacobi scaling and
// the marginalisation's linearisation are functions of these three alone. N rows on the W = 36
// tangent coordinates of the interval's knots (42 with T_rl) can therefore reach Ceres as W + 1
// equivalent rows (the square-root information form of the batch):
//
//   R (W×W) with RᵀR = JᵀJ,   r₀ with Rᵀr₀ = Jᵀr,   and the constant row √(‖r‖² − ‖r₀‖²),
//
// so cost, gradient and Gauss–Newton Hessian are those of the N rows up to rounding. What it saves
// is Ceres' serial per-row work, which grows with N: zeroing, filling and checking its dense
// Jacobian and the JᵀJ of its normal equations (a Singer-LIO scan's solve, N ≈ 600: 0.81× the
// instructions, docs/experiments/latency.md). JᵀJ is formed here instead, per chunk of kChunkRows
// rows on the row runner (the chunks' sums added in chunk order: the same values for any split). R
// is the Cholesky factor with complete pivoting of the Jacobi-scaled JᵀJ (unit diagonal),
// rank-revealing: it stops where the largest remaining Schur-complement pivot is at most
// kPivotThreshold, and the rows left zero carry no information above rounding: ~W³/3 flops, 5–9 µs
// per evaluation at W = 36, where an eigendecomposition (InformationSquareRoot's, for the marginal
// prior) takes ~95 µs; Eigen's LDLT pivots on the original diagonal and is not rank-revealing.
// Evaluated without Jacobians the block returns r₀ = 0 and the whole cost in the last row: such an
// evaluation serves the cost, and the W + 1 values mean something only together with their
// Jacobians, which are not the derivative of the residuals — numeric differentiation does not
// apply; the tests compare cost, gradient and JᵀJ with the point rows'.
//
// Parameter blocks: pose_k (7, PoseManifold), ϖ_k (6), ϖ̇_k (6), pose_k+1, ϖ_k+1, ϖ̇_k+1 — those of
// every point's interpolation (each SharedPoseInterpolation must interpolate on this interval) —
// and, with the extrinsic, T_rl (7, PoseManifold).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace ctlio {

class ContinuousPointToPlaneBatch final : public ceres::CostFunction {
 public:
  // kPointRows: one row per point (and the constant row with a loss). kSquareRoot: W + 1 rows
  // carrying the same cost, gradient and Gauss–Newton Hessian (above).
  enum class Form { kPointRows, kSquareRoot };
  static constexpr size_t kChunkRows = 64;          // rows per chunk of the square-root form
  static constexpr double kPivotThreshold = 1e-12;  // of the Jacobi-scaled JᵀJ (unit diagonal)

  struct Point {
    std::shared_ptr<const SharedPoseInterpolation> pose;  // at the point's τ, on this interval
    PlaneAssociation association;     // with the extrinsic its point_robot is not read
    Vec3 point_lidar = Vec3::Zero();  // q_l, with the extrinsic only
  };

  // At least one point. `loss` (nullable) is each point's robust loss; it is shared, not copied.
  // `with_extrinsic`: a seventh block T_rl, each point entering as T_rl·point_lidar.
  ContinuousPointToPlaneBatch(std::vector<Point> points,
                              std::shared_ptr<const ceres::LossFunction> loss,
                              bool with_extrinsic = false, Form form = Form::kPointRows)
      : points_(std::move(points)),
        loss_(std::move(loss)),
        blocks_(with_extrinsic ? 7 : 6),
        form_(form) {
    if (points_.empty()) throw std::invalid_argument("ContinuousPointToPlaneBatch: no points");
    set_num_residuals(form_ == Form::kSquareRoot
                          ? tangent_size() + 1
                          : static_cast<int>(points_.size()) + (loss_ != nullptr ? 1 : 0));
    for (int b = 0; b < blocks_; ++b) mutable_parameter_block_sizes()->push_back(kBlockSizes[b]);
  }

  // Runs rows(begin, end) over a split of [0, n) into contiguous ranges, possibly concurrently,
  // and returns when all have run (e.g. ctlio::ParallelFor's chunks). n counts the rows of the
  // point-row form and the chunks of kChunkRows rows of the square-root form (work_items()).
  using RowRunner =
      std::function<void(size_t n, const std::function<void(size_t begin, size_t end)>& rows)>;

  // Optional: the rows are independent, so a runner may evaluate them on several threads. Each
  // row writes only its own residual and Jacobian rows, and the constant row sums the rows' terms
  // in row order afterwards: the same values, bit for bit, for any split.
  void set_row_runner(RowRunner runner) { row_runner_ = std::move(runner); }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (form_ == Form::kSquareRoot) return EvaluateSquareRoot(parameters, residuals, jacobians);
    const size_t n = points_.size();
    const bool extrinsic = blocks_ == 7;
    const SE3 T_rl = extrinsic ? PoseManifold::Pose(parameters[6]) : SE3();
    std::vector<double> gaps(loss_ != nullptr ? n : 0);  // per row ρ(e²) − ρ'(e²)·e²
    std::atomic<bool> concave{true};
    const auto evaluate_rows = [&](size_t begin, size_t end) {
      double* rows[7] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
      PlaneAssociation m;
      Eigen::Matrix<double, 1, 6> J_tau;
      for (size_t i = begin; i < end; ++i) {
        bool any = false;
        if (jacobians != nullptr) {
          for (int b = 0; b < blocks_; ++b) {
            rows[b] = jacobians[b] != nullptr ? jacobians[b] + i * kBlockSizes[b] : nullptr;
            any = any || rows[b] != nullptr;
          }
        }
        const Point& p = points_[i];
        const PlaneAssociation* association = &p.association;
        if (extrinsic) {  // as ContinuousPointToPlaneExtrinsic: q = T_rl·q_l, de/dδ_rl = −de/dδT(τ)
          m = p.association;
          m.point_robot = T_rl * p.point_lidar;
          association = &m;
        }
        const bool want_rl = extrinsic && rows[6] != nullptr;
        const double e = ContinuousPointToPlane::EvaluateAtKnots(
            *p.pose, *association, parameters, any ? rows : nullptr, want_rl ? &J_tau : nullptr);
        if (want_rl) {
          LiftPoseJacobian<1>(Eigen::Matrix<double, 1, 6>(-J_tau), parameters[6], rows[6]);
        }
        if (loss_ == nullptr) {
          residuals[i] = e;
          continue;
        }
        double rho[3];
        loss_->Evaluate(e * e, rho);
        if (rho[2] > 0.0) {  // not concave here: no exact constant row (above)
          concave.store(false, std::memory_order_relaxed);
          return;
        }
        const double scale = std::sqrt(rho[1]);
        residuals[i] = scale * e;
        gaps[i] = rho[0] - rho[1] * e * e;
        if (!any) continue;
        for (int b = 0; b < blocks_; ++b) {
          if (rows[b] == nullptr) continue;
          for (int c = 0; c < kBlockSizes[b]; ++c) rows[b][c] *= scale;
        }
      }
    };
    if (row_runner_) {
      row_runner_(n, evaluate_rows);
    } else {
      evaluate_rows(0, n);
    }
    if (!concave.load(std::memory_order_relaxed)) return false;
    if (loss_ == nullptr) return true;
    double cost_gap = 0.0;  // Σ ρ(e²) − ρ'(e²)·e², in row order
    for (const double gap : gaps) cost_gap += gap;
    residuals[n] = std::sqrt(std::max(cost_gap, 0.0));  // clamps rounding below 0 only
    if (jacobians != nullptr) {
      for (int b = 0; b < blocks_; ++b) {
        if (jacobians[b] == nullptr) continue;
        std::fill_n(jacobians[b] + n * kBlockSizes[b], kBlockSizes[b], 0.0);
      }
    }
    return true;
  }

  size_t size() const { return points_.size(); }
  const Point& point(size_t i) const { return points_[i]; }
  const ceres::LossFunction* loss() const { return loss_.get(); }
  Form form() const { return form_; }
  // W: the tangent coordinates of the blocks, 36 (42 with T_rl).
  int tangent_size() const { return 6 * blocks_; }
  // The n a row runner is called with.
  size_t work_items() const {
    return form_ == Form::kSquareRoot ? (points_.size() + kChunkRows - 1) / kChunkRows
                                      : points_.size();
  }

 private:
  static constexpr int kBlockSizes[7] = {7, 6, 6, 7, 6, 6, 7};

  // The square-root form (continuous_point_to_plane_batch.cc).
  bool EvaluateSquareRoot(double const* const* parameters, double* residuals,
                          double** jacobians) const;

  std::vector<Point> points_;
  std::shared_ptr<const ceres::LossFunction> loss_;
  int blocks_;
  Form form_;
  RowRunner row_runner_;
};

}  // namespace ctlio
