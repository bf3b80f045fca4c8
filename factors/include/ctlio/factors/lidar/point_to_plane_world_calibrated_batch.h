// The IMU-as-input baseline's calibrated point-to-plane residuals of one scan as ONE residual block
// (the navigation state's counterpart of ContinuousPointToPlaneBatch, whose header gives the
// reasoning): row i is point i's PointToPlaneWorldCalibrated residual, evaluated by the same code
// (PointToPlaneWorldCalibrated::EvaluateTangent), on the blocks T_wb (7), then T_rl (7) when the
// extrinsic is estimated, then δ (1) when the clock offset is.
//
// Each row carries its own robust loss as Ceres' Corrector would for a one-point block
// (Triggs et al., "Bundle adjustment — a modern synthesis", §4.3; concave losses): row i is
// √ρ'(e_i²)·e_i with Jacobian √ρ'(e_i²)·∂e_i, and one constant row √(Σ_i ρ(e_i²) − ρ'(e_i²)·e_i²)
// makes ½‖r‖² the robust cost. So cost, gradient and Gauss–Newton Hessian equal those of the
// per-point blocks up to rounding (test lidar.PointToPlaneWorldCalibratedBatch.*).
//
// Square-root form (Form::kSquareRoot): the N point rows reach Ceres as W + 1 rows, W = 6 + 6 + 1
// tangent coordinates at most (R with RᵀR = JᵀJ, r₀ with Rᵀr₀ = Jᵀr, BatchSquareRoot, and the
// constant row √(‖r‖² − ‖r₀‖²)): Ceres' per-row work in the solve, the marginalisation's
// linearisation and the calibration covariance then no longer grow with the keypoints (~600 per
// scan: 93 ms per calibrating scan with one block per keypoint, docs/experiments/calibration.md).
// As there, the W + 1 rows mean something only with their Jacobians (a cost-only evaluation puts
// the whole cost in the last row), so the tests compare cost, gradient and JᵀJ with the point
// rows', and check the point rows' Jacobians against central differences.
//
// The anchor δ̄ is the scan's (one navigation state), the deskew D and the twist ξ per point.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <memory>
#include <vector>

#include "ctlio/factors/lidar/point_to_plane_world_calibrated.h"

namespace ctlio {

class PointToPlaneWorldCalibratedBatch final : public ceres::CostFunction {
 public:
  enum class Form { kPointRows, kSquareRoot };
  static constexpr double kPivotThreshold = 1e-12;  // of the Jacobi-scaled JᵀJ (unit diagonal)

  struct Point {
    PlaneAssociation association;  // its point_robot is not read
    Vec3 point_lidar = Vec3::Zero();
    SE3 deskew;                 // D
    Vec6 twist = Vec6::Zero();  // ξ (PointToPlaneWorldCalibrated::Geometry)
  };

  // At least one point. `loss` (nullable) is each point's robust loss, shared.
  // `offset_anchor` as PointToPlaneWorldCalibrated::Geometry's; `fixed_T_rl` is used when the
  // extrinsic is not a block.
  PointToPlaneWorldCalibratedBatch(std::vector<Point> points, double offset_anchor,
                                   std::shared_ptr<const ceres::LossFunction> loss,
                                   bool extrinsic_block, bool offset_block,
                                   const SE3& fixed_T_rl = SE3(), Form form = Form::kPointRows);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  size_t size() const { return points_.size(); }
  Form form() const { return form_; }
  // W: the tangent coordinates of the blocks (6, 7, 12 or 13).
  int tangent_size() const { return 6 + (extrinsic_ ? 6 : 0) + (offset_ ? 1 : 0); }

 private:
  std::vector<Point> points_;
  double offset_anchor_;
  std::shared_ptr<const ceres::LossFunction> loss_;
  bool extrinsic_, offset_;
  SE3 fixed_T_rl_;
  Form form_;
};

}  // namespace ctlio
