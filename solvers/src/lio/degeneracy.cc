#include "ctlio/solvers/lio/degeneracy.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

#include "ctlio/solvers/schur_complement.h"

namespace ctlio::lio {

std::string DegeneracyReport::DirectionString() const {
  if (directions.empty()) return "-";
  const Vec6& u = directions.front();
  const bool translation = u.head<3>().squaredNorm() >= u.tail<3>().squaredNorm();
  const Vec3 v = translation ? Vec3(u.head<3>()) : Vec3(u.tail<3>());
  std::ostringstream s;
  s.precision(3);
  s << std::fixed << (translation ? "t:" : "r:") << v.x() << ',' << v.y() << ',' << v.z();
  return s.str();
}

namespace {

// The ordering of Linearize: `leading` first (in that order, constant or not), then every other
// non-constant state the residuals touch, in ascending id (deterministic).
std::vector<StateId> Ordering(const SlidingWindow& window,
                              const std::vector<ceres::ResidualBlockId>& residuals,
                              const std::vector<StateId>& leading) {
  std::vector<StateId> ids;
  for (const ceres::ResidualBlockId r : residuals) {
    for (const StateId id : window.StatesOf(r)) {
      if (std::find(leading.begin(), leading.end(), id) == leading.end() &&
          !window.IsStateConstant(id)) {
        ids.push_back(id);
      }
    }
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  ids.insert(ids.begin(), leading.begin(), leading.end());
  return ids;
}

Mat6 ToBody(const Eigen::MatrixXd& H_state, const Mat6& A) {
  const Mat6 H = A.transpose() * H_state * A;
  return 0.5 * (H + H.transpose());
}

// Block b (0 translation, 1 rotation) with the other block marginalised (Schur complement).
Mat3 MarginalBlock(const Mat6& H, int b) {
  const SchurComplementResult s = b == 0 ? SchurComplement(H, Vec6::Zero(), {0, 1, 2}, {3, 4, 5})
                                         : SchurComplement(H, Vec6::Zero(), {3, 4, 5}, {0, 1, 2});
  return s.information;
}

}  // namespace

Mat6 PoseInformation(const SlidingWindow& window,
                     const std::vector<ceres::ResidualBlockId>& residuals, StateId pose,
                     const Mat6& A) {
  if (window.IsStateConstant(pose)) return Mat6::Zero();
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  window.Linearize(residuals, Ordering(window, residuals, {pose}), &H, &b);
  return ToBody(H.topLeftCorner<6, 6>(), A);
}

Mat6 OtherInformation(const SlidingWindow& window,
                      const std::vector<ceres::ResidualBlockId>& excluded, StateId pose,
                      const Mat6& A) {
  if (window.IsStateConstant(pose)) return Mat6::Zero();
  const std::unordered_set<ceres::ResidualBlockId> skip(excluded.begin(), excluded.end());
  std::unordered_set<ceres::ResidualBlockId> seen;
  std::vector<ceres::ResidualBlockId> others;
  for (const StateId id : window.StateIds()) {
    for (const ceres::ResidualBlockId r : window.ResidualBlocksOf(id)) {
      if (skip.count(r) == 0 && seen.insert(r).second) others.push_back(r);
    }
  }
  if (others.empty()) return Mat6::Zero();
  return ToBody(MarginalInformation(window, others, {pose}), A);
}

Eigen::MatrixXd MarginalInformation(const SlidingWindow& window,
                                    const std::vector<ceres::ResidualBlockId>& residuals,
                                    const std::vector<StateId>& states) {
  const std::vector<StateId> ordering = Ordering(window, residuals, states);
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  window.Linearize(residuals, ordering, &H, &b);
  int n = 0;
  for (const StateId id : states) n += window.TangentSize(id);
  std::vector<int> keep(n), marginalize;
  for (int i = 0; i < n; ++i) keep[i] = i;
  for (int i = n; i < H.rows(); ++i) marginalize.push_back(i);
  return SchurComplement(H, b, keep, marginalize).information;
}

DegeneracyReport AnalyseDegeneracy(const Mat6& H, const DegeneracyOptions& options) {
  DegeneracyReport report;
  report.analysed = true;
  struct Candidate {
    double nu;
    Vec6 u;
  };
  std::vector<Candidate> degenerate;
  for (int b = 0; b < 2; ++b) {
    const Mat3 S = MarginalBlock(H, b);
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(S);  // ascending eigenvalues
    const double mean = S.trace() / 3.0;
    const Vec3 nu = mean > 0 ? Vec3(eig.eigenvalues().cwiseMax(0.0) / mean) : Vec3::Zero();
    (b == 0 ? report.translation_eigenvalues : report.rotation_eigenvalues) = nu;
    const double threshold = b == 0 ? options.translation_threshold : options.rotation_threshold;
    for (int i = 0; i < 3; ++i) {
      if (nu[i] >= threshold) continue;
      Vec6 u = Vec6::Zero();
      u.segment<3>(3 * b) = eig.eigenvectors().col(i).normalized();
      // Sign convention: largest component positive (the direction, not its sign, matters).
      Eigen::Index k;
      u.cwiseAbs().maxCoeff(&k);
      if (u[k] < 0) u = -u;
      degenerate.push_back({nu[i], u});
    }
  }
  std::stable_sort(degenerate.begin(), degenerate.end(),
                   [](const Candidate& a, const Candidate& b) { return a.nu < b.nu; });
  for (const Candidate& c : degenerate) report.directions.push_back(c.u);
  if (!report.directions.empty()) {
    const Vec6& u = report.directions.front();
    report.lidar_information = u.dot(H * u);
  }
  return report;
}

Mat6 RemapSqrtInformation(const DegeneracyReport& report, const DegeneracyOptions& options,
                          const Mat6& A) {
  Mat6 P = Mat6::Zero();
  for (const Vec6& u : report.directions) P += u * u.transpose();
  // r = √w·P·δ_body with δ_body = A⁻¹·δ_state.
  return std::sqrt(options.remap_information) * P * A.inverse();
}

}  // namespace ctlio::lio
