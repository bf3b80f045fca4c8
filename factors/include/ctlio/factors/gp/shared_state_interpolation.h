// The GP state x(τ) = (T(τ), ϖ(τ), ϖ̇(τ)) and the rows of its Jacobians onto both knots
// (gp::GpInterpolator::StateRows) at one IMU sample's time τ, shared by the residuals that read
// it — the gyro and the accelerometer residual of the sample (imu/imu_measurement.h), which each
// interpolated on their own before. Each reader adds the row blocks it needs (AddRows); a
// preparation forms their union once. Prepared or computed on demand, with identical values:
// gp/shared_interpolation.h.
#pragma once

#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/knot_state.h"
#include "ctlio/factors/gp/shared_interpolation.h"

namespace ctlio::gp {

class SharedStateInterpolation final : public SharedInterpolation {
 public:
  // x(τ) and the Jacobians ∂x(τ)/∂(knot k), ∂x(τ)/∂(knot k+1); only the requested rows of the
  // Jacobians are written.
  struct Result {
    KnotState x;
    StateJacobian J_k, J_k1;
  };

  // The state at tau between knots at t_k and t_k1 (GpInterpolator's requirements; throws
  // otherwise); `knots` as in SharedInterpolation.
  SharedStateInterpolation(const SingerModel<6>& model, double t_k, double t_k1, double tau,
                           const KnotBlocks& knots = {})
      : SharedInterpolation(knots),
        interpolator_(model, t_k, t_k1, tau),
        fraction_((tau - t_k) / (t_k1 - t_k)) {}

  // s = (τ − t_k)/(t_{k+1} − t_k), the weight of knot k+1 in a linear interpolation (biases).
  double fraction() const { return fraction_; }

  // Adds StateRowBlock flags to what a preparation forms.
  void AddRows(unsigned rows) {
    if ((rows & ~rows_) == 0) return;
    rows_ |= rows;
    Invalidate();
  }
  unsigned rows() const { return rows_; }

  // x(τ) and (with `jacobians`) the Jacobian rows `rows` at `parameters` (the six knot blocks'
  // values, in the KnotBlocks order): the prepared result if it was prepared at exactly these
  // values with these rows, otherwise interpolated into *scratch, which is returned.
  const Result& State(double const* const* parameters, unsigned rows, bool jacobians,
                      Result* scratch) const {
    if ((rows & ~rows_) == 0 && PreparedAt(parameters)) return prepared_;
    CountComputed();
    interpolator_.StateRows(ReadKnotState(parameters[0], parameters[1], parameters[2]),
                            ReadKnotState(parameters[3], parameters[4], parameters[5]), rows,
                            &scratch->x, jacobians ? &scratch->J_k : nullptr,
                            jacobians ? &scratch->J_k1 : nullptr);
    return *scratch;
  }

  const GpInterpolator& interpolator() const { return interpolator_; }

 private:
  void Interpolate(const KnotValues& values, const LocalVariables* local) override {
    if (local != nullptr) {
      interpolator_.StateRows(values.Knot(0), *local, rows_, &prepared_.x, &prepared_.J_k,
                              &prepared_.J_k1);
    } else {
      interpolator_.StateRows(values.Knot(0), values.Knot(1), rows_, &prepared_.x, &prepared_.J_k,
                              &prepared_.J_k1);
    }
  }

  GpInterpolator interpolator_;
  double fraction_;
  unsigned rows_ = 0;
  Result prepared_;
};

}  // namespace ctlio::gp
