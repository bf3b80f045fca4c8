// Where an IMU sits on the robot: the rigid transform T_ri from the IMU frame i to the robot
// frame r of the GP state (SPEC §1), i.e. the rotation C_ri and the lever arm p = r_r^{ir} (the
// IMU origin in robot coordinates, metres). The default is the identity: the IMU frame is the
// robot frame, which is what a single-IMU estimator whose robot frame is the IMU uses.
//
// Rigid-body kinematics at the lever arm (ω, ω̇ the robot's angular rate and acceleration in
// the robot frame, f_r the specific force at the robot origin):
//   ω_i = C_ir ω,    f_i = C_ir (f_r + ω̇ × p + ω × (ω × p)).
// A continuous-time state that carries ω̇ (the ϖ̇_ω of the GP state) gives the ω̇ × p term
// directly; IMU-as-input would have to differentiate the gyro for it.
#pragma once

#include "ctlio/manifolds/se3.h"
#include "ctlio/manifolds/types.h"

namespace ctlio::imu {

struct ImuMounting {
  Mat3 C_ri = Mat3::Identity();   // IMU frame → robot frame
  Vec3 lever_arm = Vec3::Zero();  // IMU origin in the robot frame [m]

  // From T_ri (maps IMU coordinates into the robot frame).
  static ImuMounting FromPose(const SE3& T_robot_imu) {
    ImuMounting m;
    m.C_ri = T_robot_imu.rotation();
    m.lever_arm = T_robot_imu.translation();
    return m;
  }
  SE3 Pose() const { return SE3(C_ri, lever_arm); }
  bool HasRotation() const { return !C_ri.isIdentity(0.0); }
  bool HasLeverArm() const { return !lever_arm.isZero(0.0); }
};

}  // namespace ctlio::imu
