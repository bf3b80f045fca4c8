#include "ctlio/solvers/sliding_window.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "ctlio/factors/priors/marginalization_prior.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"
#include "sliding_window_internal.h"

namespace ctlio {

using sliding_window_internal::IdList;
using sliding_window_internal::RowMajorMatrix;
using sliding_window_internal::Throw;

SlidingWindowOptions::SlidingWindowOptions() {
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  solver.minimizer_type = ceres::TRUST_REGION;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver.max_num_iterations = 50;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  solver.minimizer_progress_to_stdout = false;
}

SlidingWindow::SlidingWindow(const SlidingWindowOptions& options)
    : options_(options), shared_interpolations_(std::make_unique<SharedInterpolationCallback>()) {
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = shared_interpolations_.get();
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // states hold shared_ptrs
  problem_options.enable_fast_removal = true;
  problem_ = std::make_unique<ceres::Problem>(problem_options);
}

// The problem (which references the manifolds) goes before the states that own them.
SlidingWindow::~SlidingWindow() { problem_.reset(); }

const SlidingWindow::StateBlock& SlidingWindow::Get(StateId id, int line) const {
  const auto it = states_.find(id);
  if (it == states_.end()) Throw(line, "unknown state id " + std::to_string(id));
  return it->second;
}

SlidingWindow::StateBlock& SlidingWindow::Get(StateId id, int line) {
  const auto it = states_.find(id);
  if (it == states_.end()) Throw(line, "unknown state id " + std::to_string(id));
  return it->second;
}

double* SlidingWindow::AddState(StateId id, const double* initial, int ambient_size,
                                std::shared_ptr<const ceres::Manifold> manifold) {
  if (states_.count(id) != 0) Throw(__LINE__, "state id " + std::to_string(id) + " exists");
  if (initial == nullptr || ambient_size <= 0) {
    Throw(__LINE__, "state " + std::to_string(id) + " needs initial values and a size > 0");
  }
  MarginalizationPrior::TypeOf(manifold.get());  // throws for manifolds the prior cannot handle
  if (manifold != nullptr && manifold->AmbientSize() != ambient_size) {
    Throw(__LINE__, "state " + std::to_string(id) + ": size " + std::to_string(ambient_size) +
                        " does not match its manifold's ambient size " +
                        std::to_string(manifold->AmbientSize()));
  }
  for (int i = 0; i < ambient_size; ++i) {
    if (!std::isfinite(initial[i])) {
      Throw(__LINE__, "state " + std::to_string(id) + " has NaN/Inf initial values");
    }
  }
  StateBlock block;
  block.values.reset(new double[ambient_size]);
  std::copy(initial, initial + ambient_size, block.values.get());
  block.ambient_size = ambient_size;
  block.tangent_size = manifold == nullptr ? ambient_size : manifold->TangentSize();
  block.manifold = std::move(manifold);
  double* values = block.values.get();
  problem_->AddParameterBlock(values, ambient_size,
                              const_cast<ceres::Manifold*>(block.manifold.get()));
  states_.emplace(id, std::move(block));
  return values;
}

double* SlidingWindow::AddPoseState(StateId id, const SE3& T) {
  static const auto manifold = std::make_shared<const PoseManifold>();
  double x[7];
  PoseManifold::Store(T, x);
  return AddState(id, x, 7, manifold);
}

double* SlidingWindow::AddRotationState(StateId id, const Mat3& C) {
  static const auto manifold = std::make_shared<const RotationManifold>();
  double q[4];
  RotationManifold::Store(C, q);
  return AddState(id, q, 4, manifold);
}

double* SlidingWindow::AddVectorState(StateId id, const Eigen::VectorXd& v) {
  return AddState(id, v.data(), static_cast<int>(v.size()), nullptr);
}

void SlidingWindow::RemoveState(StateId id) {
  StateBlock& block = Get(id, __LINE__);
  for (ceres::ResidualBlockId r : InAddedOrder(block.residuals)) RemoveResidualBlock(r);
  problem_->RemoveParameterBlock(block.values.get());
  states_.erase(id);
}

double* SlidingWindow::State(StateId id) { return Get(id, __LINE__).values.get(); }
const double* SlidingWindow::State(StateId id) const { return Get(id, __LINE__).values.get(); }

SE3 SlidingWindow::Pose(StateId id) const {
  const StateBlock& block = Get(id, __LINE__);
  if (dynamic_cast<const PoseManifold*>(block.manifold.get()) == nullptr) {
    Throw(__LINE__, "state " + std::to_string(id) + " is not a pose");
  }
  return PoseManifold::Pose(block.values.get());
}

Eigen::VectorXd SlidingWindow::Vector(StateId id) const {
  const StateBlock& block = Get(id, __LINE__);
  return Eigen::Map<const Eigen::VectorXd>(block.values.get(), block.ambient_size);
}

int SlidingWindow::AmbientSize(StateId id) const { return Get(id, __LINE__).ambient_size; }
int SlidingWindow::TangentSize(StateId id) const { return Get(id, __LINE__).tangent_size; }
const ceres::Manifold* SlidingWindow::Manifold(StateId id) const {
  return Get(id, __LINE__).manifold.get();
}

std::vector<StateId> SlidingWindow::StateIds() const {
  std::vector<StateId> ids;
  ids.reserve(states_.size());
  for (const auto& [id, block] : states_) ids.push_back(id);
  return ids;
}

void SlidingWindow::SetStateConstant(StateId id, bool constant) {
  double* values = Get(id, __LINE__).values.get();
  if (constant) {
    problem_->SetParameterBlockConstant(values);
  } else {
    problem_->SetParameterBlockVariable(values);
  }
}

bool SlidingWindow::IsStateConstant(StateId id) const {
  return problem_->IsParameterBlockConstant(Get(id, __LINE__).values.get());
}

ceres::ResidualBlockId SlidingWindow::AddResidualBlock(ceres::CostFunction* cost,
                                                       ceres::LossFunction* loss,
                                                       const std::vector<StateId>& states) {
  if (cost == nullptr) Throw(__LINE__, "null cost function");
  const std::vector<int32_t>& sizes = cost->parameter_block_sizes();
  if (sizes.size() != states.size()) {
    Throw(__LINE__, "cost function has " + std::to_string(sizes.size()) + " parameter blocks but " +
                        std::to_string(states.size()) + " states were given (" + IdList(states) +
                        ")");
  }
  std::vector<double*> blocks;
  blocks.reserve(states.size());
  for (size_t i = 0; i < states.size(); ++i) {
    const StateBlock& block = Get(states[i], __LINE__);
    if (block.ambient_size != sizes[i]) {
      Throw(__LINE__, "parameter block " + std::to_string(i) + " of the cost function has size " +
                          std::to_string(sizes[i]) + " but state " + std::to_string(states[i]) +
                          " has " + std::to_string(block.ambient_size));
    }
    if (std::count(states.begin(), states.end(), states[i]) > 1) {
      Throw(__LINE__, "state " + std::to_string(states[i]) + " listed twice");
    }
    blocks.push_back(block.values.get());
  }
  const ceres::ResidualBlockId id = problem_->AddResidualBlock(cost, loss, blocks);
  residuals_.emplace(id, states);
  residual_serial_.emplace(id, next_residual_serial_++);
  for (StateId s : states) states_.at(s).residuals.insert(id);
  return id;
}

void SlidingWindow::RemoveResidualBlock(ceres::ResidualBlockId id) {
  const auto it = residuals_.find(id);
  if (it == residuals_.end()) Throw(__LINE__, "unknown residual block");
  for (StateId s : it->second) states_.at(s).residuals.erase(id);
  residuals_.erase(it);
  residual_serial_.erase(id);
  marginal_priors_.erase(id);
  problem_->RemoveResidualBlock(id);
}

std::vector<ceres::ResidualBlockId> SlidingWindow::ResidualBlocksOf(StateId id) const {
  const StateBlock& block = Get(id, __LINE__);
  return {block.residuals.begin(), block.residuals.end()};
}

const std::vector<StateId>& SlidingWindow::StatesOf(ceres::ResidualBlockId id) const {
  const auto it = residuals_.find(id);
  if (it == residuals_.end()) Throw(__LINE__, "unknown residual block");
  return it->second;
}

ceres::Solver::Summary SlidingWindow::Solve() {
  if (states_.empty()) Throw<std::logic_error>(__LINE__, "Solve() on an empty window");
  ceres::Solver::Summary summary;
  // options_.threads serve the solve (solving()); the linearisations outside it keep one thread.
  struct Solving {
    SlidingWindow* w;
    explicit Solving(SlidingWindow* window) : w(window) {
      w->solving_ = true;
      w->shared_interpolations_->set_threads(w->options_.threads);
    }
    ~Solving() {
      w->solving_ = false;
      w->shared_interpolations_->set_threads(1);
    }
  } solving(this);
  ceres::Solve(options_.solver, problem_.get(), &summary);
  return summary;
}

MarginalizationReport SlidingWindow::Marginalize(const std::vector<StateId>& ids) {
  if (states_.empty()) Throw<std::logic_error>(__LINE__, "Marginalize() on an empty window");
  if (ids.empty()) Throw(__LINE__, "Marginalize() needs at least one state id");
  std::set<StateId> leaving;
  for (StateId id : ids) {
    if (states_.count(id) == 0) {
      Throw(__LINE__, "cannot marginalise unknown state id " + std::to_string(id));
    }
    if (!leaving.insert(id).second) Throw(__LINE__, "state id " + std::to_string(id) + " twice");
  }

  MarginalizationReport report;
  report.marginalized.assign(leaving.begin(), leaving.end());
  std::set<ceres::ResidualBlockId> residual_set;
  std::set<StateId> kept;
  for (StateId id : leaving) {
    const StateBlock& block = states_.at(id);
    report.marginalized_dimension += block.tangent_size;
    for (ceres::ResidualBlockId r : block.residuals) {
      residual_set.insert(r);
      for (StateId s : residuals_.at(r)) {
        if (leaving.count(s) == 0) kept.insert(s);
      }
    }
  }
  report.kept.assign(kept.begin(), kept.end());
  report.removed_residual_blocks = static_cast<int>(residual_set.size());
  const std::vector<ceres::ResidualBlockId> residuals = InAddedOrder(residual_set);
  // Everything that can throw happens before the window changes.
  std::unique_ptr<MarginalizationPrior> prior;
  if (!residual_set.empty()) prior = SchurPrior(residuals, &report);

  for (ceres::ResidualBlockId r : residuals) RemoveResidualBlock(r);
  for (StateId id : leaving) {
    problem_->RemoveParameterBlock(states_.at(id).values.get());
    states_.erase(id);
  }
  if (prior != nullptr) {
    report.prior = AddResidualBlock(prior.release(), nullptr, report.kept);
    marginal_priors_.insert(report.prior);
  }
  return report;
}

std::vector<ceres::ResidualBlockId> SlidingWindow::InAddedOrder(
    const std::set<ceres::ResidualBlockId>& residuals) const {
  std::vector<ceres::ResidualBlockId> ordered(residuals.begin(), residuals.end());
  std::sort(ordered.begin(), ordered.end(),
            [this](ceres::ResidualBlockId a, ceres::ResidualBlockId b) {
              return residual_serial_.at(a) < residual_serial_.at(b);
            });
  return ordered;
}

std::unique_ptr<MarginalizationPrior> SlidingWindow::SchurPrior(
    const std::vector<ceres::ResidualBlockId>& residuals, MarginalizationReport* report) const {
  std::vector<StateId> ordering(report->marginalized);
  ordering.insert(ordering.end(), report->kept.begin(), report->kept.end());
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  Linearize(residuals, ordering, &H, &b);
  const SchurComplementResult schur = SchurComplementLeading(
      H, b, report->marginalized_dimension, options_.relative_eigenvalue_threshold);
  report->marginalized_rank = schur.marginalized_rank;
  if (report->kept.empty()) return nullptr;
  Eigen::MatrixXd sqrt_information;
  Eigen::VectorXd r0;
  report->prior_rank = InformationSquareRoot(schur.information, schur.vector, &sqrt_information,
                                             &r0, options_.relative_eigenvalue_threshold);
  if (report->prior_rank == 0) return nullptr;
  std::vector<const ceres::Manifold*> manifolds;
  std::vector<int> sizes;
  std::vector<const double*> points;
  for (StateId id : report->kept) {
    const StateBlock& block = states_.at(id);
    manifolds.push_back(block.manifold.get());
    sizes.push_back(block.ambient_size);
    points.push_back(block.values.get());
  }
  return std::make_unique<MarginalizationPrior>(manifolds, sizes, points, sqrt_information, r0);
}

MarginalizationReport SlidingWindow::ForgetInformation(const std::vector<StateId>& ids) {
  if (ids.empty()) Throw(__LINE__, "ForgetInformation() needs at least one state id");
  std::set<StateId> forgotten;
  for (StateId id : ids) {
    Get(id, __LINE__);
    if (!forgotten.insert(id).second) Throw(__LINE__, "state id " + std::to_string(id) + " twice");
  }
  // The marginal priors on those states; live residual blocks are re-linearised at every solve
  // and keep what they say.
  std::set<ceres::ResidualBlockId> prior_set;
  for (StateId id : forgotten) {
    for (ceres::ResidualBlockId r : states_.at(id).residuals) {
      if (marginal_priors_.count(r)) prior_set.insert(r);
    }
  }
  MarginalizationReport report;
  if (prior_set.empty()) return report;
  std::set<StateId> touched, kept;
  for (ceres::ResidualBlockId r : prior_set) {
    for (StateId s : residuals_.at(r)) (forgotten.count(s) ? touched : kept).insert(s);
  }
  report.marginalized.assign(touched.begin(), touched.end());
  report.kept.assign(kept.begin(), kept.end());
  report.removed_residual_blocks = static_cast<int>(prior_set.size());
  for (StateId id : touched) report.marginalized_dimension += states_.at(id).tangent_size;
  const std::vector<ceres::ResidualBlockId> priors = InAddedOrder(prior_set);
  // The priors' joint Gaussian, linearised at the current estimate as Marginalize linearises an
  // older prior, integrated over the forgotten states: the Schur complement onto the others
  // is their marginal, so they keep exactly what the priors said about them.
  std::unique_ptr<MarginalizationPrior> prior = SchurPrior(priors, &report);
  for (ceres::ResidualBlockId r : priors) RemoveResidualBlock(r);
  if (prior != nullptr) {
    report.prior = AddResidualBlock(prior.release(), nullptr, report.kept);
    marginal_priors_.insert(report.prior);
  }
  return report;
}

Eigen::MatrixXd SlidingWindow::Covariance(const std::vector<StateId>& ids) const {
  if (ids.empty()) Throw(__LINE__, "Covariance() needs at least one state id");
  std::vector<StateId> ordering;
  std::unordered_map<StateId, int> offset;
  int n = 0;
  for (const auto& [id, block] : states_) {
    if (problem_->IsParameterBlockConstant(block.values.get())) continue;
    ordering.push_back(id);
    offset[id] = n;
    n += block.tangent_size;
  }
  std::vector<int> index;
  for (StateId id : ids) {
    const StateBlock& block = Get(id, __LINE__);
    const auto it = offset.find(id);
    if (it == offset.end()) Throw(__LINE__, "state " + std::to_string(id) + " is constant");
    for (int k = 0; k < block.tangent_size; ++k) index.push_back(it->second + k);
  }
  std::vector<ceres::ResidualBlockId> all;
  for (const auto& [rid, states] : residuals_) all.push_back(rid);
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  Linearize(all, ordering, &H, &b);
  const Eigen::MatrixXd P = PseudoInverse(H, options_.relative_eigenvalue_threshold);
  const int k = static_cast<int>(index.size());
  Eigen::MatrixXd out(k, k);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) out(i, j) = P(index[i], index[j]);
  return out;
}

}  // namespace ctlio
