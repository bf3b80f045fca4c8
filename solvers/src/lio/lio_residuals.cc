#include "ctlio/solvers/lio/lio_residuals.h"

#include <algorithm>
#include <cmath>

namespace ctlio::lio {

namespace {

class BiasWalk final : public ceres::SizedCostFunction<6, 6, 6> {
 public:
  explicit BiasWalk(const Vec6& sqrt_information) : s_(sqrt_information) {}
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    Eigen::Map<Vec6> residual(r);
    residual = s_.cwiseProduct(Eigen::Map<const Vec6>(p[1]) - Eigen::Map<const Vec6>(p[0]));
    for (int k = 0; k < 2; ++k) {
      if (J != nullptr && J[k] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> Jk(J[k]);
        Jk = (k == 0 ? -1.0 : 1.0) * Mat6(s_.asDiagonal());
      }
    }
    return true;
  }

 private:
  Vec6 s_;
};

}  // namespace

std::unique_ptr<ceres::LossFunction> MakeLidarLoss(const OdometryConfig& config) {
  const double scale = config.frontend.loss_scale / config.point_to_plane_std;
  if (config.frontend.loss == "cauchy") return std::make_unique<ceres::CauchyLoss>(scale);
  if (config.frontend.loss == "huber") return std::make_unique<ceres::HuberLoss>(scale);
  return nullptr;
}

ceres::Solver::Options WindowSolverOptions(const OdometryConfig& config) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  o.max_num_iterations = config.frontend.solver_iterations;
  o.num_threads = config.solver_threads;
  o.minimizer_progress_to_stdout = false;
  o.logging_type = ceres::SILENT;
  return o;
}

ceres::CostFunction* MakeBiasRandomWalk(const OdometryConfig& config, double dt) {
  const double scale = std::max(dt, 1e-6) / config.bias_walk_period;
  Vec6 s;
  s.head<3>().setConstant(1.0 / std::sqrt(config.bias_accel_walk * scale));
  s.tail<3>().setConstant(1.0 / std::sqrt(config.bias_gyro_walk * scale));
  return new BiasWalk(s);
}

}  // namespace ctlio::lio
