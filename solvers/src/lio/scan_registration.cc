#include "ctlio/solvers/lio/scan_registration.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/parallel_for.h"

namespace ctlio::lio {

namespace {
double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

double PointNoiseSigma(const LidarFrontendOptions& o, const Vec3& q_robot, double plane_thickness) {
  const double scatter = o.plane_thickness_noise * plane_thickness;
  if (!(o.point_noise_angle > 0.0) && !(scatter > 0.0)) return o.point_noise_sigma;
  const double angular = o.point_noise_angle * q_robot.norm();
  return std::sqrt(o.point_noise_sigma * o.point_noise_sigma + angular * angular +
                   scatter * scatter);
}

std::unique_ptr<ceres::LossFunction> MakeLidarLoss(const LidarFrontendOptions& o) {
  const double scale = o.loss_scale / o.point_noise_sigma;
  if (o.loss == "cauchy") return std::make_unique<ceres::CauchyLoss>(scale);
  if (o.loss == "huber") return std::make_unique<ceres::HuberLoss>(scale);
  return nullptr;
}

ScanRegistration::ScanRegistration(const LidarFrontendOptions& options, int min_associations)
    : options_(options), min_associations_(min_associations) {
  options_.Validate();
}

void LidarTerm::SetBatchResiduals(const std::vector<uint8_t>& /*associated*/,
                                  const std::vector<PlaneAssociation>& /*planes*/,
                                  const std::shared_ptr<const ceres::LossFunction>& /*loss*/,
                                  SlidingWindow* /*window*/,
                                  std::vector<ceres::ResidualBlockId>* /*blocks*/) {
  throw std::logic_error("LidarTerm::SetBatchResiduals: this lidar term has no batched residuals");
}

RegistrationSummary ScanRegistration::Register(const VoxelMap& map, LidarTerm* term,
                                               SlidingWindow* window, int max_rounds) const {
  using Clock = std::chrono::steady_clock;
  RegistrationSummary summary;
  // One associator (neighbour buffer) per thread; the keypoints are placed in the map first
  // (the term's interpolation is not thread-safe), associated in parallel chunks, and their
  // residuals added in keypoint order: the window is the same for any number of threads.
  const int threads = options_.threads;
  std::vector<PlaneAssociator> associators(static_cast<size_t>(threads),
                                           PlaneAssociator(map, options_));
  const size_t n = term->num_keypoints();
  std::vector<Vec3> q(n), p_map(n);
  // Per keypoint: the plane of its last search (weight not whitened), whether that search found
  // one, and where the keypoint was in the map then.
  std::vector<PlaneAssociation> planes(n);
  std::vector<double> thickness(n, 0.0);
  std::vector<uint8_t> associated(n, 0);
  std::vector<Vec3> searched_at(n);
  // Per keypoint: its residual in the window (nullptr: none).
  std::vector<ceres::ResidualBlockId> block(n, nullptr);
  // Batched terms: one robust loss for the whole registration (the term's blocks share it),
  // this round's whitened planes, and the term's blocks in the window.
  const bool batched = term->batched();
  const std::shared_ptr<const ceres::LossFunction> batch_loss =
      batched ? std::shared_ptr<const ceres::LossFunction>(MakeLidarLoss(options_)) : nullptr;
  std::vector<PlaneAssociation> whitened(batched ? n : 0);
  std::vector<ceres::ResidualBlockId> batch_blocks;
  auto remove_all = [&] {
    if (batched) {
      term->SetBatchResiduals(std::vector<uint8_t>(n, 0), whitened, batch_loss, window,
                              &batch_blocks);
      return;
    }
    for (ceres::ResidualBlockId& id : block) {
      if (id != nullptr) window->RemoveResidualBlock(id);
      id = nullptr;
    }
  };
  const double reuse_squared = options_.reassociation_distance * options_.reassociation_distance;
  SE3 last_pose = term->NewestPose();
  const int rounds = max_rounds > 0 ? max_rounds : options_.max_iterations;
  for (int round = 0; round < rounds; ++round) {
    // Associate at the current estimate.
    auto t0 = Clock::now();
    term->BeginRound();
    for (size_t i = 0; i < n; ++i) term->Locate(i, &q[i], &p_map[i]);
    ParallelFor(threads, n, [&](size_t chunk, size_t begin, size_t end) {
      PlaneAssociator& associator = associators[chunk];
      for (size_t i = begin; i < end; ++i) {
        // A keypoint that moved less than reassociation_distance in the map since its plane
        // was searched keeps that plane (0: search every round); the distance gate stays that
        // of the search.
        if (associated[i] && (p_map[i] - searched_at[i]).squaredNorm() < reuse_squared) {
          planes[i].point_robot = q[i];
          continue;
        }
        searched_at[i] = p_map[i];
        associated[i] = associator.Associate(q[i], p_map[i], &planes[i], &thickness[i]) ? 1 : 0;
      }
    });
    // This round's residuals replace the previous round's, on the whitened planes.
    const auto whiten = [&](size_t i) {
      PlaneAssociation a = planes[i];
      a.weight /= PointNoiseSigma(options_, a.point_robot, thickness[i]);
      return a;
    };
    int associations = 0;
    if (batched) {  // the term replaces its per-interval blocks at once
      for (size_t i = 0; i < n; ++i) {
        if (!associated[i]) continue;
        whitened[i] = whiten(i);
        ++associations;
      }
      if (associations >= min_associations_) {
        term->SetBatchResiduals(associated, whitened, batch_loss, window, &batch_blocks);
      }
    } else {
      // A keypoint associated again keeps its residual block with the new plane written into it
      // (the same residual as a new block on that plane), one that lost its plane loses its
      // block, a new one gets a block. One loss for the new blocks of the round, shared by them;
      // once a residual uses it the window owns it (ref-counted by Ceres, deleted with the last
      // such residual).
      std::unique_ptr<ceres::LossFunction> loss = MakeLidarLoss(options_);
      bool loss_used = false;
      for (size_t i = 0; i < n; ++i) {
        if (!associated[i]) {
          if (block[i] != nullptr) window->RemoveResidualBlock(block[i]);
          block[i] = nullptr;
          continue;
        }
        if (block[i] != nullptr) {
          term->UpdateResidual(i, whiten(i));
        } else {
          block[i] = term->AddResidual(i, whiten(i), loss.get(), window);
          loss_used = true;
        }
        ++associations;
      }
      if (loss_used) loss.release();
    }
    summary.associations = associations;
    if (summary.associations < min_associations_) {
      remove_all();
      summary.degenerate = true;
    }
    summary.ms_associate += MsSince(t0);

    // Solve.
    t0 = Clock::now();
    const ceres::Solver::Summary solved = window->Solve();
    summary.ms_solve += MsSince(t0);
    summary.rounds = round + 1;
    summary.solver_iterations += static_cast<int>(solved.iterations.size());
    if (round == 0) summary.initial_cost = solved.initial_cost;
    summary.final_cost = solved.final_cost;

    // Converged?
    const SE3 pose = term->NewestPose();
    const Vec6 step = (pose * last_pose.Inverse()).Log();
    last_pose = pose;
    if (summary.degenerate) break;
    if (step.head<3>().norm() < options_.convergence_translation &&
        step.tail<3>().norm() < options_.convergence_rotation) {
      summary.converged = true;
      break;
    }
  }
  if (!summary.degenerate) {
    summary.noise_sigma.assign(n, 0.0);
    for (size_t i = 0; i < n; ++i) {
      if (!associated[i]) continue;
      summary.noise_sigma[i] = PointNoiseSigma(options_, planes[i].point_robot, thickness[i]);
    }
    summary.planes = std::move(planes);
    summary.associated = std::move(associated);
  }
  if (batched) {
    summary.lidar_blocks = batch_blocks;
    return summary;
  }
  for (ceres::ResidualBlockId id : block) {
    if (id != nullptr) summary.lidar_blocks.push_back(id);
  }
  return summary;
}

}  // namespace ctlio::lio
