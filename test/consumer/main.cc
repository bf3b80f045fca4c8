// Uses the installed ctlio package from another project: one pose on the
// PoseManifold, fitted in a Ceres problem; exits non-zero on failure.
#include <ceres/ceres.h>

#include <cstdio>

#include "ctlio/manifolds/pose_manifold.h"

namespace {
// r = Log(T · T_target⁻¹), analytic Jacobian 𝒥⁻¹(r) lifted to the ambient block.
class PoseError final : public ceres::SizedCostFunction<6, 7> {
 public:
  explicit PoseError(const ctlio::SE3& target) : target_inverse_(target.Inverse()) {}
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const ctlio::Vec6 r = (ctlio::PoseManifold::Pose(p[0]) * target_inverse_).Log();
    Eigen::Map<ctlio::Vec6>{residuals} = r;
    if (jacobians && jacobians[0]) {
      ctlio::LiftPoseJacobian<6>(ctlio::se3::LeftJacobianInverse(r), p[0], jacobians[0]);
    }
    return true;
  }

 private:
  ctlio::SE3 target_inverse_;
};
}  // namespace

int main() {
  ctlio::Vec6 xi;
  xi << 1.0, -2.0, 0.5, 0.3, -0.2, 2.5;
  const ctlio::SE3 target = ctlio::SE3::Exp(xi);
  double x[7] = {0, 0, 0, 0, 0, 0, 1};
  ceres::Problem problem;
  problem.AddResidualBlock(new PoseError(target), nullptr, x);
  problem.SetManifold(x, new ctlio::PoseManifold);
  ceres::Solver::Options options;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  const double err = (ctlio::PoseManifold::Pose(x) * target.Inverse()).Log().norm();
  std::printf("consumer: pose error after solve %.3e (%d iterations)\n", err,
              static_cast<int>(summary.iterations.size()));
  return err < 1e-9 ? 0 : 1;
}
