#include "ctlio/solvers/lio/calibration_observability.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ctlio/solvers/schur_complement.h"

namespace ctlio::lio {

CalibrationObservability::CalibrationObservability(const CalibrationOptions& options,
                                                   int num_time_offsets, bool extrinsic)
    : options_(options) {
  const std::vector<double> sigma = options.PriorSigmas(num_time_offsets, extrinsic);
  for (int j = 0; j < num_time_offsets; ++j) {
    names_.push_back("time_offset_" + std::to_string(j));
    threshold_.push_back(options.time_offset_observability_threshold);
  }
  if (extrinsic) {
    for (const char* a : {"x", "y", "z"}) {
      names_.push_back(std::string("extrinsic_rho_") + a);
      threshold_.push_back(options.translation_observability_threshold);
    }
    for (const char* a : {"x", "y", "z"}) {
      names_.push_back(std::string("extrinsic_phi_") + a);
      threshold_.push_back(options.rotation_observability_threshold);
    }
  }
  prior_sigma_ =
      Eigen::Map<const Eigen::VectorXd>(sigma.data(), static_cast<Eigen::Index>(sigma.size()));
  sum_ = Eigen::MatrixXd::Zero(dimension(), dimension());
  nu_ = Eigen::VectorXd::Zero(dimension());
}

void CalibrationObservability::AddScan(const Eigen::MatrixXd& information) {
  const int n = dimension();
  if (information.rows() != n || information.cols() != n) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": CalibrationObservability::AddScan: information is " +
                                std::to_string(information.rows()) + "x" +
                                std::to_string(information.cols()) + ", expected " +
                                std::to_string(n) + "x" + std::to_string(n));
  }
  horizon_.push_back(prior_sigma_.asDiagonal() * information * prior_sigma_.asDiagonal());
  while (static_cast<int>(horizon_.size()) > std::max(1, options_.observability_horizon_scans)) {
    horizon_.pop_front();
  }
  // Summed afresh (N ≤ a few tens of 7×7 matrices): no round-off creeps in from subtracting the
  // scan that leaves.
  sum_.setZero();
  for (const Eigen::MatrixXd& W : horizon_) sum_ += W;
  // ν_i: the other coordinates free (Schur complement onto i), so that an axis only constrained
  // together with another one is not counted as observed.
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    std::vector<int> rest;
    for (int k = 0; k < n; ++k) {
      if (k != i) rest.push_back(k);
    }
    nu_[i] = std::max(0.0, SchurComplement(sum_, zero, {i}, rest).information(0, 0));
  }
}

std::vector<bool> CalibrationObservability::Unobservable() const {
  // Until the horizon is full the threshold is scaled by its filled fraction (the same
  // information per scan): holding a well-observed state for the first N scans, with a wrong
  // start, costs accuracy for the rest of the run (the map of those scans stays).
  const double filled =
      static_cast<double>(horizon_.size()) / std::max(1, options_.observability_horizon_scans);
  std::vector<bool> out(static_cast<size_t>(dimension()));
  for (int i = 0; i < dimension(); ++i) {
    out[static_cast<size_t>(i)] =
        horizon_.empty() || nu_[i] < std::min(filled, 1.0) * threshold_[static_cast<size_t>(i)];
  }
  return out;
}

}  // namespace ctlio::lio
