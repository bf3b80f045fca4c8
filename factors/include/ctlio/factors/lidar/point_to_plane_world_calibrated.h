// Point-to-plane residual of one lidar point for the IMU-as-input baseline (point_to_plane_world.h)
// with the online calibration's states (SPEC §6; docs/user-guide/calibration.md): the lidar–IMU
// extrinsic T_rl and the IMU's clock offset δ.
//
//   e = w · nᵀ (p_ref − T_wb · Exp(ε·ξ) · D · T_rl · q_l),   ε = δ̄ − δ,
//
// q_l: the point in the lidar frame; D: the deskew, from the robot frame at the point's time to
// the body frame at the state (the IMU integrated from the previous state, held fixed during a
// solve as the baseline's deskew is); the state sits at IMU-clock time t_end − δ̄ (δ̄: the
// offset its IMU samples were chosen with), and the scan end t_end on the lidar clock is IMU
// time t_end − δ, ε = δ̄ − δ later; ξ = [v; ω]: the body twist at the state (fixed like D), so
// Exp(ε·ξ) carries the state to the scan end (to first order in ε: δ̄ follows δ between scans).
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
    Vec6 twist = Vec6::Zero();   // ξ = [ρ; φ], body frame at the state
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
    const Vec3 x = T_rl * q_l_;
    const Vec3 y = g_.deskew * x;
    const SE3 E = SE3::Exp(epsilon * g_.twist);
    const Vec3 p = T_wb * (E * y);
    residuals[0] = m_.weight * m_.plane_normal.dot(m_.plane_point - p);
    if (jacobians == nullptr) return true;
    const Eigen::Matrix<double, 1, 3> a = -m_.weight * m_.plane_normal.transpose();  // de/dp
    if (jacobians[0] != nullptr) {
      LiftPoseJacobian<1>(a * se3::PointJacobian(p), parameters[0], jacobians[0]);
    }
    const Eigen::Matrix<double, 1, 3> a_body = a * T_wb.rotation() * E.rotation();  // de/dy
    if (extrinsic_ && jacobians[1] != nullptr) {
      const Eigen::Matrix<double, 1, 6> J = a_body * g_.deskew.rotation() * se3::PointJacobian(x);
      LiftPoseJacobian<1>(J, parameters[1], jacobians[1]);
    }
    if (offset_) {
      double* J = jacobians[extrinsic_ ? 2 : 1];
      if (J != nullptr) {
        const Vec3 dy = g_.twist.head<3>() + g_.twist.tail<3>().cross(y);  // dz/dε = C_E·dy
        J[0] = -a_body.dot(dy);                                            // dε/dδ = −1
      }
    }
    return true;
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
