// The map's error as the map is built (window.pose_covariance_map_growth,
// solvers/lio/map_growth_covariance.h). A map made of the points of its scans, each point carrying
// the error of the scan that inserted it, and registered as a whole (it moves by the mean of its
// points' errors): a scan's error in the map frame is its own relative error plus the map's. The
// reported covariance Σ_rel + Σ_map is the exact covariance of that error (mean NEES 6), where
// Σ_rel alone is far too small once the map holds the early scans' errors.
#include "ctlio/solvers/lio/map_growth_covariance.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>
#include <vector>

namespace ctlio::lio {
namespace {

// A random SPD matrix with σ between ~1 mm and ~3 cm (translation) and ~0.1-3 mrad (rotation).
Mat6 RandomCovariance(std::mt19937_64* rng) {
  std::normal_distribution<double> n;
  Mat6 A;
  for (int i = 0; i < 36; ++i) A.data()[i] = n(*rng);
  const Vec6 scale = (Vec6() << 0.01, 0.01, 0.02, 1e-3, 1e-3, 5e-4).finished();
  const Mat6 S =
      scale.asDiagonal() * (A * A.transpose() / 6.0 + 0.05 * Mat6::Identity()) * scale.asDiagonal();
  return 0.5 * (S + S.transpose());
}

TEST(MapGrowthCovariance, IsTheCovarianceOfAMapAveragedFromItsScans) {
  std::mt19937_64 rng(43);
  const int kScans = 12;
  const size_t first_scan_points = 2000;  // the first scan's map: exact (the gauge)
  std::vector<Mat6> relative;
  std::vector<size_t> inserted;
  std::uniform_int_distribution<size_t> count(200, 2500);
  for (int k = 0; k < kScans; ++k) {
    relative.push_back(RandomCovariance(&rng));
    inserted.push_back(count(rng));
  }
  // The model's reported covariances (gain 1, as derived).
  std::vector<Mat6> reported, window_only;
  MapGrowthCovariance model;
  size_t map_points = first_scan_points;
  for (int k = 0; k < kScans; ++k) {
    reported.push_back(relative[size_t(k)] + model.map());
    window_only.push_back(relative[size_t(k)]);
    model.Registered(relative[size_t(k)]);
    map_points += inserted[size_t(k)];
    model.Inserted(inserted[size_t(k)], map_points, 1.0);
  }
  // Monte Carlo of the map: its error is the mean of its points' errors.
  std::normal_distribution<double> n;
  double nees = 0.0, nees_window_only = 0.0;
  const int kDraws = 4000;
  for (int d = 0; d < kDraws; ++d) {
    Vec6 map_error = Vec6::Zero();
    double points = static_cast<double>(first_scan_points);
    for (int k = 0; k < kScans; ++k) {
      Vec6 z;
      for (int i = 0; i < 6; ++i) z[i] = n(rng);
      const Vec6 e_rel = Eigen::LLT<Mat6>(relative[size_t(k)]).matrixL() * z;
      const Vec6 e_w = map_error + e_rel;
      nees += e_w.dot(reported[size_t(k)].ldlt().solve(e_w));
      nees_window_only += e_w.dot(window_only[size_t(k)].ldlt().solve(e_w));
      const double added = static_cast<double>(inserted[size_t(k)]);
      map_error = (points * map_error + added * e_w) / (points + added);
      points += added;
    }
  }
  nees /= kDraws * kScans;
  nees_window_only /= kDraws * kScans;
  EXPECT_NEAR(nees, 6.0, 0.15);
  EXPECT_GT(nees_window_only, 7.5);  // the map's error is a real part of the error
}

TEST(MapGrowthCovariance, OnlyARegisteredScanThatInsertedPointsMovesTheMap) {
  std::mt19937_64 rng(7);
  const Mat6 S = RandomCovariance(&rng);
  MapGrowthCovariance model;
  model.Inserted(100, 1000, 1.0);  // nothing registered (the first scan's map is exact)
  EXPECT_EQ(model.map(), Mat6::Zero());
  model.Registered(S);
  model.Inserted(0, 1000, 1.0);  // registered, nothing kept (a full map)
  EXPECT_EQ(model.map(), Mat6::Zero());
  model.Inserted(100, 1000, 1.0);  // its registration was used up by the call before
  EXPECT_EQ(model.map(), Mat6::Zero());
  model.Registered(S);
  model.Inserted(250, 1000, 2.0);  // β = 1/4, g = 2
  EXPECT_LT((model.map() - 2.0 / 16.0 * S).norm(), 1e-15 * S.norm());
  model.Registered(S);
  model.Inserted(250, 1000, 0.0);  // g = 0: none
  EXPECT_LT((model.map() - 2.0 / 16.0 * S).norm(), 1e-15 * S.norm());
}

}  // namespace
}  // namespace ctlio::lio
