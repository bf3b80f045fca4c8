#include "ctlio/study/motion.h"

#include <stdexcept>
#include <string>

#include "ctlio/factors/gp/motion_model.h"

namespace ctlio::study {

const DiscreteMotion& MotionModelCache::Get(int64_t dt_ns) {
  for (const auto& e : entries_) {
    if (e.dt_ns == dt_ns) return e;
  }
  if (dt_ns <= 0) {
    throw std::invalid_argument(std::string(__FILE__) +
                                ": MotionModelCache: time step must be > 0");
  }
  const double dt = 1e-9 * static_cast<double>(dt_ns);
  DiscreteMotion m;
  m.dt_ns = dt_ns;
  m.transition = gp::SingerTransition(prior_.alpha, dt);
  m.covariance = gp::SingerCovariance(prior_.alpha, prior_.qc, dt);
  Eigen::LLT<Eigen::Matrix3d> llt(m.covariance);
  if (llt.info() != Eigen::Success) {
    throw std::runtime_error(std::string(__FILE__) +
                             ": MotionModelCache: Q(dt) not positive definite");
  }
  m.sqrt_covariance = llt.matrixL();
  entries_.push_back(m);
  return entries_.back();
}

}  // namespace ctlio::study
