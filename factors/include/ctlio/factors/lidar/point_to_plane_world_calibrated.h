// Point-to-plane residual of one lidar point for the IMU-as-input baseline (point_to_plane_world.h)
// with the online calibration's states (SPEC §6; docs/user-guide/calibration.md): the lidar–IMU
// extrinsic T_rl and the IMU's clock offset δ.
//
//   e = w · nᵀ (p_ref − T_wb · Exp(ε·ξ) · D · T_rl · q_l),   ε = δ̄ − δ,
//
// q_l: the point in the lidar frame; D: the deskew, from the robot frame at the point's time to
// the body frame at the state, computed from the IMU at the offset δ̄ (held fixed during a solve,
// as the baseline's deskew is); ξ = [ρ; φ]: the point's rate of change of its deskew with the
// offset, Exp(ε·ξ)·D ≈ D(δ) to first order in ε (fixed like D). The IMU-as-input baseline
// (nav_state_estimator.h) integrates D = T(t_end − δ̄)⁻¹·T(τ − δ̄) on the IMU clock; a later
// δ = δ̄ − ε moves both ends, T(s − h) = T(s)·Exp(−h·ν(s)) with ν the body twist, so
//   D(δ) ≈ Exp(−ε·ν(t_end))·D·Exp(ε·ν(τ)) ≈ Exp(ε·(Ad(D)·ν(τ) − ν(t_end)))·D,
// i.e. ξ = Ad(D)·ν(τ) − ν(t_end): zero under a constant twist, where the offset does not change
// the deskew.
//
// Jacobians, left perturbations as PoseManifold, y = D·T_rl·q_l, z = Exp(ε·ξ)·y, p = T_wb·z:
//   de/dδ_wb = −w nᵀ [I, −p^]
//   de/dδ_rl = −w nᵀ C_wb C_E C_D [I, −(T_rl q_l)^]            (C_E: Exp(ε·ξ)'s rotation)
//   de/dδ    = +w nᵀ C_wb C_E (ρ + φ × y),   ξ = [ρ; φ]        (d/dε Exp(εξ) = Exp(εξ)·ξ^)
// Blocks: T_wb, then T_rl when estimated (else the given one is fixed), then δ when estimated
// (else ε = 0).
#pragma once

#include <ceres/cost_function.h>

#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/se3.h"

namespace ctlio {

class PointToPlaneWorldCalibrated final : public ceres::CostFunction {
 public:
  // `plane`: the association (its point_robot unused: the point is q_l through D and T_rl).
  struct Geometry {
    SE3 deskew;                  // D
    Vec6 twist = Vec6::Zero();   // ξ = [ρ; φ], body frame at the state (the header's)
    double offset_anchor = 0.0;  // δ̄ [s]
  };
  PointToPlaneWorldCalibrated(const PlaneAssociation& plane, const Vec3& q_lidar,
                              const Geometry& geometry, bool extrinsic_block, bool offset_block,
                              const SE3& fixed_T_rl = SE3())
      : m_(plane),
        q_l_(q_lidar),
        g_(geometry),
        extrinsic_(extrinsic_block),
        offset_(offset_block),
        fixed_T_rl_(fixed_T_rl) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(7);
    if (extrinsic_) mutable_parameter_block_sizes()->push_back(7);
    if (offset_) mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const SE3 T_wb = PoseManifold::Pose(parameters[0]);
    const SE3 T_rl = extrinsic_ ? PoseManifold::Pose(parameters[1]) : fixed_T_rl_;
    const double* delta = offset_ ? parameters[extrinsic_ ? 2 : 1] : nullptr;
    const double epsilon = delta != nullptr ? g_.offset_anchor - delta[0] : 0.0;
    const SE3 E = delta != nullptr ? SE3::Exp(epsilon * g_.twist) : SE3();
    const bool want = jacobians != nullptr;
    Row6 J_wb, J_rl;
    double J_delta = 0.0;
    residuals[0] = EvaluateTangent(m_, q_l_, g_.deskew, g_.twist, T_wb, T_rl, E,
                                   want && jacobians[0] != nullptr ? &J_wb : nullptr,
                                   want && extrinsic_ && jacobians[1] != nullptr ? &J_rl : nullptr,
                                   want && offset_ ? &J_delta : nullptr);
    if (!want) return true;
    if (jacobians[0] != nullptr) LiftPoseJacobian<1>(J_wb, parameters[0], jacobians[0]);
    if (extrinsic_ && jacobians[1] != nullptr) {
      LiftPoseJacobian<1>(J_rl, parameters[1], jacobians[1]);
    }
    if (offset_ && jacobians[extrinsic_ ? 2 : 1] != nullptr)
      jacobians[extrinsic_ ? 2 : 1][0] = J_delta;
    return true;
  }

  using Row6 = Eigen::Matrix<double, 1, 6>;
  // The residual at T_wb, T_rl and E = Exp(ε·ξ) and its Jacobians on the tangent spaces (the
  // header's; nullptr: not wanted), for one point: the one evaluation of this factor and of the
  // batch of a scan's points (point_to_plane_world_calibrated_batch.h).
  static double EvaluateTangent(const PlaneAssociation& m, const Vec3& q_l, const SE3& deskew,
                                const Vec6& twist, const SE3& T_wb, const SE3& T_rl, const SE3& E,
                                Row6* J_wb, Row6* J_rl, double* J_delta) {
    const Vec3 x = T_rl * q_l;
    const Vec3 y = deskew * x;
    const Vec3 p = T_wb * (E * y);
    const double e = m.weight * m.plane_normal.dot(m.plane_point - p);
    if (J_wb == nullptr && J_rl == nullptr && J_delta == nullptr) return e;
    const Eigen::Matrix<double, 1, 3> a = -m.weight * m.plane_normal.transpose();  // de/dp
    if (J_wb != nullptr) *J_wb = a * se3::PointJacobian(p);
    const Eigen::Matrix<double, 1, 3> a_body = a * T_wb.rotation() * E.rotation();  // de/dy
    if (J_rl != nullptr) *J_rl = a_body * deskew.rotation() * se3::PointJacobian(x);
    if (J_delta != nullptr) {
      const Vec3 dy = twist.head<3>() + twist.tail<3>().cross(y);  // dz/dε = C_E·dy
      *J_delta = -a_body.dot(dy);                                  // dε/dδ = −1
    }
    return e;
  }

  // The next association round of the same point, with that round's deskew and twist (between
  // solves only).
  void Update(const PlaneAssociation& plane, const Geometry& geometry) {
    m_ = plane;
    g_ = geometry;
  }

 private:
  PlaneAssociation m_;
  Vec3 q_l_;
  Geometry g_;
  bool extrinsic_, offset_;
  SE3 fixed_T_rl_;
};

}  // namespace ctlio
