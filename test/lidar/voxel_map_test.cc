// Voxel hash map (SPEC §4): bounds per voxel, minimum spacing, far-voxel removal, and the
// neighbour search against brute force.
#include "ctlio/solvers/lio/voxel_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>

#include "ctlio/solvers/lio/frontend.h"

namespace ctlio::lio {
namespace {

std::vector<Vec3> RandomPoints(std::mt19937& rng, int n, double half_extent) {
  std::uniform_real_distribution<double> u(-half_extent, half_extent);
  std::vector<Vec3> pts(n);
  for (auto& p : pts) p = Vec3(u(rng), u(rng), u(rng));
  return pts;
}

std::vector<Vec3> AllPoints(const VoxelMap& map) {
  std::vector<Vec3> all;
  map.ForEachVoxel([&](const VoxelKey&, const VoxelPoints& pts) {
    all.insert(all.end(), pts.begin(), pts.end());
  });
  return all;
}

VoxelMap::Options DefaultOptions() { return VoxelMap::Options{}; }  // 1 m, 20, 0.1 m, 400 m

TEST(VoxelMap, BoundsAndSpacingHold) {
  std::mt19937 rng(11);
  VoxelMap map(DefaultOptions());
  // 60k points in a 6 m cube: ~280 per voxel offered, so the bounds must bite.
  const auto pts = RandomPoints(rng, 60000, 3.0);
  const size_t kept = map.Insert(pts);
  EXPECT_EQ(kept, map.num_points());
  EXPECT_LT(kept, pts.size());
  size_t total = 0;
  int full_voxels = 0;
  map.ForEachVoxel([&](const VoxelKey& key, const VoxelPoints& v) {
    total += v.size();
    EXPECT_LE(v.size(), 20u);
    if (v.size() == 20u) ++full_voxels;
    for (size_t i = 0; i < v.size(); ++i) {
      const VoxelKey k = VoxelKeyOf(v[i], 1.0);
      EXPECT_TRUE(k == key) << "point stored in the wrong voxel";
      for (size_t j = i + 1; j < v.size(); ++j) EXPECT_GE((v[i] - v[j]).norm(), 0.1);
    }
  });
  EXPECT_EQ(total, map.num_points());
  EXPECT_EQ(map.num_voxels(), 216u);
  EXPECT_GT(full_voxels, 200);
}

// Batch insertion (the lookup cache, the two-points-per-step distance test) against point-by-point
// insertion into a reference built on std::floor keys and an ordered map, with points exactly at
// and one ulp inside / outside the minimum spacing, on voxel faces, at negative coordinates,
// NaN, repeated points, and voxels revisited a few hundred points later (cache hits) and
// colliding in the cache.
TEST(VoxelMap, BatchInsertEqualsPointByPointReference) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-4.0, 4.0);
  std::uniform_int_distribution<int> cell(-4, 3);
  std::vector<Vec3> pts;
  for (int i = 0; i < 40000; ++i) {
    switch (i % 7) {
      case 0: {  // on a voxel face (or one ulp below it)
        Vec3 p(cell(rng), u(rng), cell(rng));
        if (i % 2 == 0) p.x() = std::nextafter(p.x(), -1e9);
        pts.push_back(p);
        break;
      }
      case 1: {  // exactly min_point_distance (0.1) from an earlier point along x, ± one ulp
        const Vec3 q = pts[rng() % pts.size()];
        Vec3 p = q + Vec3(0.1, 0.0, 0.0);
        if (i % 3 == 1) p.x() = std::nextafter(p.x(), 1e9);
        if (i % 3 == 2) p.x() = std::nextafter(p.x(), -1e9);
        pts.push_back(p);
        break;
      }
      case 2:  // a repeat of a recent point (the same voxel a "firing" later)
        pts.push_back(pts[pts.size() - 1 - rng() % std::min<size_t>(pts.size(), 300)]);
        break;
      default:
        pts.emplace_back(u(rng), u(rng), 0.3 * u(rng));
    }
    if (i % 1777 == 0) pts.back() = Vec3(std::nan(""), 0.0, 1.0);
    if (i % 1999 == 0) pts.back() = Vec3(1.0, std::numeric_limits<double>::infinity(), 1.0);
  }
  for (const int max_points : {3, 20}) {
    VoxelMap::Options o;
    o.max_points_per_voxel = max_points;
    VoxelMap map(o);
    // Two batches, so the second starts with a populated map.
    const size_t half = pts.size() / 2;
    size_t kept = map.Insert(std::vector<Vec3>(pts.begin(), pts.begin() + half));
    kept += map.Insert(std::vector<Vec3>(pts.begin() + half, pts.end()));
    std::map<std::tuple<int, int, int>, std::vector<Vec3>> reference;
    size_t reference_kept = 0;
    for (const Vec3& p : pts) {
      if (!p.allFinite()) continue;
      auto& voxel =
          reference[{static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())),
                     static_cast<int>(std::floor(p.z()))}];
      if (static_cast<int>(voxel.size()) >= max_points) continue;
      bool close = false;
      for (const Vec3& q : voxel) close = close || (q - p).squaredNorm() < 0.1 * 0.1;
      if (close) continue;
      voxel.push_back(p);
      ++reference_kept;
    }
    EXPECT_EQ(kept, reference_kept);
    EXPECT_EQ(map.num_voxels(), reference.size());
    size_t compared = 0;
    map.ForEachVoxel([&](const VoxelKey& k, const VoxelPoints& v) {
      const auto it = reference.find({k.x, k.y, k.z});
      ASSERT_NE(it, reference.end());
      ASSERT_EQ(v.size(), it->second.size());
      for (size_t i = 0; i < v.size(); ++i) {
        EXPECT_EQ(v[i], it->second[i]) << "voxel " << k.x << " " << k.y << " " << k.z;
      }
      ++compared;
    });
    EXPECT_EQ(compared, reference.size());
    EXPECT_GT(reference_kept, 1000u);
  }
}

TEST(VoxelMap, RejectsClosePointsAndFullVoxels) {
  VoxelMap::Options o;
  o.max_points_per_voxel = 3;
  VoxelMap map(o);
  EXPECT_TRUE(map.Insert(Vec3(0.5, 0.5, 0.5)));
  EXPECT_FALSE(map.Insert(Vec3(0.55, 0.5, 0.5)));  // 5 cm from an existing point
  EXPECT_TRUE(map.Insert(Vec3(0.2, 0.5, 0.5)));
  EXPECT_TRUE(map.Insert(Vec3(0.8, 0.5, 0.5)));
  EXPECT_FALSE(map.Insert(Vec3(0.5, 0.1, 0.9)));  // voxel full
  EXPECT_TRUE(map.Insert(Vec3(1.5, 0.5, 0.5)));   // next voxel
  EXPECT_FALSE(map.Insert(Vec3(std::nan(""), 0.0, 0.0)));
  EXPECT_EQ(map.num_points(), 4u);
  EXPECT_EQ(map.num_voxels(), 2u);
}

TEST(VoxelMap, RemovesFarVoxelsOnly) {
  std::mt19937 rng(12);
  VoxelMap::Options o;
  o.max_distance = 5.0;
  VoxelMap map(o);
  map.Insert(RandomPoints(rng, 20000, 10.0));
  const size_t voxels_before = map.num_voxels();
  const Vec3 location(2.0, -1.0, 0.5);
  // Expected survivors: voxels whose centre is within 5 m.
  size_t expected = 0, expected_points = 0;
  map.ForEachVoxel([&](const VoxelKey& k, const VoxelPoints& v) {
    const Vec3 c = Vec3(k.x + 0.5, k.y + 0.5, k.z + 0.5);
    if ((c - location).norm() <= 5.0) {
      ++expected;
      expected_points += v.size();
    }
  });
  const size_t removed = map.RemoveFar(location);
  EXPECT_EQ(removed, voxels_before - expected);
  EXPECT_EQ(map.num_voxels(), expected);
  EXPECT_EQ(map.num_points(), expected_points);
  EXPECT_GT(removed, 0u);
  map.ForEachVoxel([&](const VoxelKey& k, const VoxelPoints&) {
    EXPECT_LE((Vec3(k.x + 0.5, k.y + 0.5, k.z + 0.5) - location).norm(), 5.0);
  });
  EXPECT_EQ(AllPoints(map).size(), map.num_points());
}

// Within one voxel size of the query, the ±1-voxel search is exact: it must return exactly the
// brute-force k nearest of all map points.
TEST(VoxelMap, KNearestWithinOneVoxelEqualsBruteForce) {
  std::mt19937 rng(13);
  VoxelMap map(DefaultOptions());
  map.Insert(RandomPoints(rng, 30000, 8.0));
  const std::vector<Vec3> all = AllPoints(map);
  std::vector<VoxelMap::Neighbour> out;
  int nonempty = 0;
  for (const Vec3& q : RandomPoints(rng, 300, 9.0)) {
    for (int k : {1, 5, 20}) {
      const int n = map.KNearest(q, k, &out, 1.0);
      std::vector<double> d2;
      for (const Vec3& p : all) {
        const double d = (p - q).squaredNorm();
        if (d <= 1.0) d2.push_back(d);
      }
      std::sort(d2.begin(), d2.end());
      const int expected = std::min<int>(k, static_cast<int>(d2.size()));
      ASSERT_EQ(n, expected);
      ASSERT_EQ(static_cast<int>(out.size()), n);
      for (int i = 0; i < n; ++i) {
        EXPECT_DOUBLE_EQ(out[i].squared_distance, d2[i]);
        EXPECT_DOUBLE_EQ((out[i].point - q).squaredNorm(), out[i].squared_distance);
      }
      nonempty += n > 0;
    }
  }
  EXPECT_GT(nonempty, 500);
}

// Before the first insertion there is no slot table at all; after removing every voxel there is
// one with every slot empty (the search's first probe answers "no voxel" for each neighbour).
TEST(VoxelMap, KNearestOnAnEmptyMapFindsNothing) {
  VoxelMap map(DefaultOptions());
  std::vector<VoxelMap::Neighbour> out(3);
  EXPECT_EQ(map.KNearest(Vec3(0.5, 0.5, 0.5), 5, &out), 0);
  EXPECT_TRUE(out.empty());
  map.Insert(Vec3(0.5, 0.5, 0.5));
  EXPECT_EQ(map.KNearest(Vec3(0.6, 0.5, 0.5), 5, &out), 1);
  EXPECT_EQ(map.RemoveFar(Vec3(1000.0, 0.0, 0.0)), 1u);
  EXPECT_EQ(map.KNearest(Vec3(0.6, 0.5, 0.5), 5, &out), 0);
}

// Without a radius: the k nearest among all points of the 27 voxels around the query.
TEST(VoxelMap, KNearestSearchesPlusMinusOneVoxel) {
  std::mt19937 rng(14);
  VoxelMap map(DefaultOptions());
  map.Insert(RandomPoints(rng, 5000, 6.0));
  const std::vector<Vec3> all = AllPoints(map);
  std::vector<VoxelMap::Neighbour> out;
  for (const Vec3& q : RandomPoints(rng, 200, 7.0)) {
    const VoxelKey c = VoxelKeyOf(q, 1.0);
    std::vector<double> d2;
    for (const Vec3& p : all) {
      const VoxelKey k = VoxelKeyOf(p, 1.0);
      if (std::abs(k.x - c.x) <= 1 && std::abs(k.y - c.y) <= 1 && std::abs(k.z - c.z) <= 1) {
        d2.push_back((p - q).squaredNorm());
      }
    }
    std::sort(d2.begin(), d2.end());
    const int n = map.KNearest(q, 20, &out);
    ASSERT_EQ(n, std::min<int>(20, static_cast<int>(d2.size())));
    for (int i = 0; i < n; ++i) EXPECT_DOUBLE_EQ(out[i].squared_distance, d2[i]);
  }
}

// RemoveFar compacts the voxels and rebuilds the lookup table: afterwards every surviving point
// must still be found, removed regions must accept points again, and bounds must still hold.
TEST(VoxelMap, SearchAndInsertStayExactAfterRemoval) {
  std::mt19937 rng(15);
  VoxelMap::Options o;
  o.max_distance = 4.0;
  VoxelMap map(o);
  map.Insert(RandomPoints(rng, 20000, 8.0));  // ~4000 voxels: the table grows several times
  ASSERT_GT(map.RemoveFar(Vec3(3.0, 3.0, 3.0)), 0u);
  const size_t voxels_after_removal = map.num_voxels();
  map.Insert(RandomPoints(rng, 5000, 8.0));  // refills removed voxels, adds to kept ones
  EXPECT_GT(map.num_voxels(), voxels_after_removal);
  const std::vector<Vec3> all = AllPoints(map);
  ASSERT_EQ(all.size(), map.num_points());
  map.ForEachVoxel([&](const VoxelKey& key, const VoxelPoints& v) {
    EXPECT_LE(v.size(), 20u);
    for (const Vec3& p : v) EXPECT_TRUE(VoxelKeyOf(p, 1.0) == key);
  });
  std::vector<VoxelMap::Neighbour> out;
  for (const Vec3& q : RandomPoints(rng, 200, 8.0)) {
    std::vector<double> d2;
    for (const Vec3& p : all) {
      const double d = (p - q).squaredNorm();
      if (d <= 1.0) d2.push_back(d);
    }
    std::sort(d2.begin(), d2.end());
    const int n = map.KNearest(q, 10, &out, 1.0);
    ASSERT_EQ(n, std::min<int>(10, static_cast<int>(d2.size())));
    for (int i = 0; i < n; ++i) EXPECT_DOUBLE_EQ(out[i].squared_distance, d2[i]);
  }
}

// Every voxel's kept plane equals the PCA plane of the points it holds (FitPlane, two-pass) after
// each batch of insertions (batches partly into voxels that already have points, partly into
// full ones) and after removing far voxels; a map without fit_planes keeps none.
TEST(VoxelMap, PlanesFollowTheirPoints) {
  std::mt19937 rng(17);
  VoxelMap::Options o = DefaultOptions();
  o.fit_planes = true;
  o.max_distance = 4.0;
  VoxelMap map(o);
  std::normal_distribution<double> noise(0.0, 0.01);
  const auto check = [&](const char* when) {
    int planes = 0;
    map.ForEachVoxel([&](const VoxelKey&, const VoxelPoints& pts) {
      const VoxelPlane* plane = map.PlaneOf(pts[0]);
      ASSERT_NE(plane, nullptr) << when;
      std::vector<VoxelMap::Neighbour> nb;
      for (const Vec3& p : pts) nb.push_back({p, 0.0});
      PlaneFit fit;
      if (!FitPlane(nb, &fit)) {
        EXPECT_EQ(plane->points, 0) << when;
        return;
      }
      ++planes;
      EXPECT_EQ(plane->points, static_cast<int32_t>(pts.size())) << when;
      EXPECT_LT((plane->fit.centroid - fit.centroid).norm(), 1e-12) << when;
      EXPECT_GT(std::abs(plane->fit.normal.dot(fit.normal)), 1.0 - 1e-9) << when;
      // One-pass moments against the two-pass covariance, through the closed-form eigensolver
      // (accurate to ~1e-8 relative): rounding, not a different plane.
      EXPECT_NEAR(plane->fit.planarity_weight, fit.planarity_weight, 1e-6) << when;
      EXPECT_NEAR(plane->fit.sigma3, fit.sigma3, 1e-6) << when;
    });
    EXPECT_GT(planes, 20) << when;
  };
  for (int batch = 0; batch < 4; ++batch) {
    // Noisy planar patches (the z = 0.3·x plane) 3 m around the origin, plus blobs.
    std::vector<Vec3> pts = RandomPoints(rng, 400, 3.0);
    for (size_t i = 0; i < pts.size(); i += 2) pts[i].z() = 0.3 * pts[i].x() + noise(rng);
    map.Insert(pts);
    map.Insert(Vec3(0.5, 0.5, 0.15 + 0.01 * batch));  // the single-point path
    check("after an insertion");
  }
  EXPECT_GT(map.RemoveFar(Vec3(2.0, 2.0, 0.0)), 0u);
  check("after RemoveFar");
  map.Insert(RandomPoints(rng, 400, 3.0));
  check("after an insertion following RemoveFar");
  VoxelMap plain(DefaultOptions());
  plain.Insert(RandomPoints(rng, 100, 1.0));
  EXPECT_EQ(plain.PlaneOf(Vec3(0.1, 0.1, 0.1)), nullptr);
  EXPECT_EQ(map.PlaneOf(Vec3(100.0, 0.0, 0.0)), nullptr);  // no such voxel
}

// The floor-free voxel key equals std::floor on and one ulp beside voxel boundaries, both signs.
TEST(VoxelMap, VoxelKeyIsTheFloor) {
  for (int i = -40; i <= 40; ++i) {
    for (const double a : {0.5 * i, std::nextafter(0.5 * i, -1e9), std::nextafter(0.5 * i, 1e9)}) {
      const VoxelKey k = VoxelKeyOf(Vec3(a, -a, a + 0.25), 2.0);
      EXPECT_EQ(k.x, static_cast<int32_t>(std::floor(a * 2.0))) << a;
      EXPECT_EQ(k.y, static_cast<int32_t>(std::floor(-a * 2.0))) << a;
      EXPECT_EQ(k.z, static_cast<int32_t>(std::floor((a + 0.25) * 2.0))) << a;
    }
  }
}

TEST(VoxelMap, RejectsBadOptions) {
  VoxelMap::Options o;
  o.voxel_size = 0.0;
  EXPECT_THROW(VoxelMap{o}, std::invalid_argument);
}

}  // namespace
}  // namespace ctlio::lio
