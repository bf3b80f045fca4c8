// Observability of the online calibration states (calibration_options.h) from the measurements
// alone, so that an unobservable clock offset or extrinsic axis is detected and held instead of
// drifting (docs/experiments/calibration.md, issue: "the slow regime leaves parts unobservable:
// detect and report that").
//
// Why not the window's σ: the marginal priors, linearised once and never revisited, keep adding
// information about a static state on every slide, so the window's σ shrinks even when no
// measurement constrains the state (slow regime: δ's σ 1 ms while the estimate is 8–29 ms off).
//
// The measure. After each scan's solve, the factors of the newest interval only (every residual
// block on a state of the newest knot: the scan's lidar residuals, the IMU samples of the
// interval, the motion prior and bias random walk between the two newest knots) are linearised
// at the current estimate, and every state they touch other than the calibration states (the two
// knots, the biases, C_mi when refined) is marginalised by Schur complement (degeneracy.h,
// MarginalInformation): I_k, the information of scan k's measurements on the calibration
// coordinates c = [δ_0 … δ_{J−1}, ρ_x, ρ_y, ρ_z, φ_x, φ_y, φ_z] (PoseManifold's left
// perturbation of T_rl) with the rest of the motion free. It is whitened by the calibration
// prior's σ, W_k = D I_k D with D = diag(σ_prior), and summed over the last N scans (the
// horizon, information adds: independent measurements). For each coordinate i, the other
// calibration coordinates are marginalised as well (Schur complement of the sum onto i), giving
//   ν_i = σ_prior,i² · (information on c_i from the horizon's measurements, everything else free),
// i.e. how many priors' worth of information the last N scans carry about c_i (ν = 1: the
// measurements alone would halve its variance). ν_i below its kind's threshold (clock offset,
// extrinsic rotation, extrinsic translation: calibration_options.h) ⇒ c_i is unobservable; while
// the horizon holds n < N scans the threshold is scaled by n/N (the same information per scan).
#pragma once

#include <Eigen/Core>
#include <deque>
#include <string>
#include <vector>

#include "ctlio/solvers/lio/calibration_options.h"

namespace ctlio::lio {

class CalibrationObservability {
 public:
  // `num_time_offsets` clock offsets (0 when not estimated), then the extrinsic's six axes when
  // `extrinsic` is estimated.
  CalibrationObservability(const CalibrationOptions& options, int num_time_offsets, bool extrinsic);

  int dimension() const { return static_cast<int>(prior_sigma_.size()); }
  // Coordinate names as in calibration.csv: time_offset_<j>, extrinsic_rho_<x|y|z>,
  // extrinsic_phi_<x|y|z>.
  const std::vector<std::string>& names() const { return names_; }
  // σ of the calibration prior per coordinate [s, m, rad].
  const Eigen::VectorXd& prior_sigma() const { return prior_sigma_; }

  // Adds one scan's information on the coordinates (dimension() × dimension(), tangent units);
  // the oldest scan beyond the horizon leaves the sum.
  void AddScan(const Eigen::MatrixXd& information);
  // ν per coordinate over the horizon (zero before the first scan).
  const Eigen::VectorXd& whitened_information() const { return nu_; }
  // ν_i below its kind's threshold (× n/N while the horizon holds n < N scans; all true before
  // the first scan: nothing has been measured).
  std::vector<bool> Unobservable() const;

 private:
  CalibrationOptions options_;
  std::vector<std::string> names_;
  Eigen::VectorXd prior_sigma_;
  std::vector<double> threshold_;        // per coordinate, of its kind
  std::deque<Eigen::MatrixXd> horizon_;  // whitened W_k, oldest first
  Eigen::MatrixXd sum_;                  // Σ of horizon_
  Eigen::VectorXd nu_;
};

}  // namespace ctlio::lio
