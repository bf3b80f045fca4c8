#include "ctlio/solvers/lio/calibration_states.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <unordered_set>
#include <utility>

#include "ctlio/factors/priors/euclidean_prior.h"
#include "ctlio/factors/priors/pose_prior.h"
#include "ctlio/solvers/lio/degeneracy.h"
#include "ctlio/solvers/lio/state_keys.h"

namespace ctlio::lio {

namespace {

// How Ids() splits: the clock offsets, then the extrinsic when estimated.
struct Shape {
  int offsets = 0;
  bool extrinsic = false;
};
Shape ShapeOf(const std::vector<StateId>& states) {
  Shape shape;
  shape.extrinsic = !states.empty() && states.back() == kExtrinsicKey;
  shape.offsets = static_cast<int>(states.size()) - (shape.extrinsic ? 1 : 0);
  return shape;
}

}  // namespace

CalibrationStates::CalibrationStates(const CalibrationOptions& options, int num_imus)
    : options_(options), num_imus_(num_imus) {}

void CalibrationStates::HoldUntil(double t_s, std::vector<bool> mask) {
  hold_until_s_ = t_s;
  hold_mask_ = std::move(mask);
}

std::vector<StateId> CalibrationStates::Ids(const SlidingWindow& window) const {
  std::vector<StateId> states;
  for (int j = 0; j < num_imus_; ++j) {
    if (window.HasState(TimeOffsetKey(j))) states.push_back(TimeOffsetKey(j));
  }
  if (window.HasState(kExtrinsicKey)) states.push_back(kExtrinsicKey);
  return states;
}

bool CalibrationStates::StartObservability(const SlidingWindow& window) {
  if (observability_ != nullptr) return true;
  if (options_.observability_horizon_scans == 0) return false;
  const std::vector<StateId> states = Ids(window);
  if (states.empty()) return false;
  const Shape shape = ShapeOf(states);
  observability_ =
      std::make_unique<CalibrationObservability>(options_, shape.offsets, shape.extrinsic);
  return true;
}

void CalibrationStates::Hold(double t_end, SlidingWindow* window, ScanResult* result) {
  if (!options_.any()) return;
  std::vector<bool> hold;
  Eigen::VectorXd sigma;
  if (t_end <= hold_until_s_ + 1e-6) {
    const Shape shape = ShapeOf(Ids(*window));
    const std::vector<double> prior = options_.PriorSigmas(shape.offsets, shape.extrinsic);
    hold = hold_mask_.empty() ? std::vector<bool>(prior.size(), true) : hold_mask_;
    sigma =
        Eigen::Map<const Eigen::VectorXd>(prior.data(), static_cast<Eigen::Index>(prior.size()));
  } else if (options_.hold_unobservable && StartObservability(*window)) {
    // Before any assessment everything is unobservable (nothing measured yet): held too.
    hold = observability_->Unobservable();
    sigma = observability_->prior_sigma();
  } else {
    return;
  }
  result->calibration.held = hold;
  // A prior at the current value along each held coordinate, σ_hold = σ_prior/√w: the
  // solve moves it by a negligible amount; removed again before anything else reads the window.
  const double w = std::sqrt(options_.hold_information);
  int i = 0;
  for (const StateId id : Ids(*window)) {
    if (id == kExtrinsicKey) {
      Mat6 sqrt_information = Mat6::Zero();
      for (int a = 0; a < 6; ++a, ++i) {
        if (hold[static_cast<size_t>(i)]) sqrt_information(a, a) = w / sigma[i];
      }
      if (sqrt_information.isZero()) continue;
      holds_.push_back(window->AddResidualBlock(
          new PosePrior(window->Pose(kExtrinsicKey), sqrt_information), nullptr, {id}));
      continue;
    }
    if (hold[static_cast<size_t>(i)]) {
      holds_.push_back(window->AddResidualBlock(
          new EuclideanPrior<1>(Eigen::Matrix<double, 1, 1>(window->State(id)[0]),
                                Eigen::Matrix<double, 1, 1>(w / sigma[i])),
          nullptr, {id}));
    }
    ++i;
  }
}

void CalibrationStates::Release(SlidingWindow* window) {
  for (const ceres::ResidualBlockId r : holds_) window->RemoveResidualBlock(r);
  holds_.clear();
}

void CalibrationStates::Report(const std::vector<StateId>& newest_keys, SlidingWindow* window,
                               ScanResult* result) {
  if (!options_.any()) return;
  Assess(newest_keys, *window, result);
  ReportCovariance(window, result);
}

void CalibrationStates::Assess(const std::vector<StateId>& newest_keys, const SlidingWindow& window,
                               ScanResult* result) {
  if (!StartObservability(window)) return;
  // The newest interval's factors: every residual block on a state of the newest knot.
  std::vector<ceres::ResidualBlockId> newest;
  std::unordered_set<ceres::ResidualBlockId> seen;
  for (const StateId id : newest_keys) {
    for (const ceres::ResidualBlockId r : window.ResidualBlocksOf(id)) {
      if (seen.insert(r).second) newest.push_back(r);
    }
  }
  observability_->AddScan(MarginalInformation(window, newest, Ids(window)));
  const Eigen::VectorXd& nu = observability_->whitened_information();
  result->calibration.observability.assign(nu.data(), nu.data() + nu.size());
  result->calibration.unobservable = observability_->Unobservable();
}

void CalibrationStates::ReportCovariance(SlidingWindow* window, ScanResult* result) const {
  // The extrinsic's tangent is PoseManifold's left [ρ; φ].
  const std::vector<StateId> states = Ids(*window);
  if (states.empty()) return;
  const auto [offsets, extrinsic] = ShapeOf(states);
  // Their marginal covariance is the inverse of their marginal information: every residual of
  // the window linearised once, every other state marginalised by the Schur complement
  // (degeneracy.h, as for the observability check). Its pseudo-inverse drops the null direction
  // that C_mi has when it is refined with the extrinsic (the yaw about gravity): the value of
  // the window's pseudo-inverse (ceres::Covariance, dense SVD, null space dropped, which the
  // test compares with) at a quarter of the instructions, since that SVD is of the whole
  // ~1000-row Jacobian.
  std::vector<ceres::ResidualBlockId> residuals;
  window->problem().GetResidualBlocks(&residuals);
  const Eigen::MatrixXd information = MarginalInformation(*window, residuals, states);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(information);
  const bool ok = eig.info() == Eigen::Success && eig.eigenvalues().minCoeff() > 0.0;
  Eigen::MatrixXd covariance;
  if (ok) {
    covariance = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() *
                 eig.eigenvectors().transpose();
  }
  auto& cal = result->calibration;
  cal.time_offset_sigma_s.clear();
  for (int j = 0; j < offsets; ++j) {
    cal.time_offset_sigma_s.push_back(ok ? std::sqrt(covariance(j, j)) : std::nan(""));
  }
  if (extrinsic && ok) {
    cal.extrinsic_sigma = covariance.diagonal().tail<6>().cwiseMax(0.0).cwiseSqrt();
  }
}

}  // namespace ctlio::lio
