// Lidar front end (SPEC §4): range gate, voxel subsampling, plane fit and its planarity weight,
// and the YAML options (the plane association: plane_association_test.cc).
#include "ctlio/solvers/lio/frontend.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "common/test_paths.h"
#include "ctlio/solvers/lio/lidar_frontend_options.h"

namespace ctlio::lio {
namespace {

std::vector<TimedPoint> RandomSweep(std::mt19937& rng, int n, double half_extent) {
  std::uniform_real_distribution<double> u(-half_extent, half_extent);
  std::vector<TimedPoint> pts(n);
  for (int i = 0; i < n; ++i) pts[i] = {Vec3(u(rng), u(rng), u(rng)), 1e-5 * i};
  return pts;
}

TEST(Frontend, RangeGateKeepsExactlyTheBand) {
  std::mt19937 rng(21);
  auto pts = RandomSweep(rng, 5000, 20.0);
  pts.push_back({Vec3(std::nan(""), 0, 0), 0.0});
  const auto kept = RangeGate(pts, 2.0, 15.0);
  size_t expected = 0;
  for (const auto& p : pts) {
    const double r = p.point.norm();
    expected += (r >= 2.0 && r <= 15.0) ? 1 : 0;
  }
  EXPECT_EQ(kept.size(), expected);
  for (const auto& p : kept) {
    EXPECT_GE(p.point.norm(), 2.0);
    EXPECT_LE(p.point.norm(), 15.0);
  }
  for (size_t i = 1; i < kept.size(); ++i) EXPECT_LT(kept[i - 1].time, kept[i].time);
}

// Reference: an ordered map of voxel keys, first point wins.
TEST(Frontend, VoxelSubsampleKeepsFirstPointOfEveryVoxel) {
  std::mt19937 rng(22);
  const auto pts = RandomSweep(rng, 20000, 10.0);
  for (double size : {0.2, 0.5, 1.0, 3.0}) {
    std::map<std::tuple<int, int, int>, size_t> first;
    std::vector<size_t> expected;
    for (size_t i = 0; i < pts.size(); ++i) {
      const VoxelKey k = VoxelKeyOf(pts[i].point, 1.0 / size);
      if (first.emplace(std::make_tuple(k.x, k.y, k.z), i).second) expected.push_back(i);
    }
    const auto out = VoxelGridSubsample(pts, size);
    ASSERT_EQ(out.size(), expected.size()) << size;
    for (size_t j = 0; j < out.size(); ++j) {
      EXPECT_EQ(out[j].point, pts[expected[j]].point);
      EXPECT_EQ(out[j].time, pts[expected[j]].time);
    }
  }
  EXPECT_TRUE(VoxelGridSubsample({}, 0.5).empty());
  EXPECT_THROW(VoxelGridSubsample(pts, 0.0), std::invalid_argument);
}

std::vector<VoxelMap::Neighbour> Neighbours(const std::vector<Vec3>& pts) {
  std::vector<VoxelMap::Neighbour> n;
  for (const auto& p : pts) n.push_back({p, 0.0});
  return n;
}

TEST(Frontend, PlaneFitRecoversNormalAndPlanarity) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.005);
  const Vec3 normal = Vec3(0.3, -0.5, 0.8).normalized();
  const Vec3 e1 = normal.unitOrthogonal(), e2 = normal.cross(e1);
  const Vec3 origin(4.0, -2.0, 1.0);
  std::vector<Vec3> plane, line, blob;
  for (int i = 0; i < 20; ++i) {
    plane.push_back(origin + 0.5 * u(rng) * e1 + 0.5 * u(rng) * e2 + noise(rng) * normal);
    line.push_back(origin + 0.5 * u(rng) * e1 + noise(rng) * e2 + noise(rng) * normal);
    blob.push_back(origin + 0.5 * Vec3(u(rng), u(rng), u(rng)));
  }
  PlaneFit fit;
  ASSERT_TRUE(FitPlane(Neighbours(plane), &fit));
  EXPECT_GT(std::abs(fit.normal.dot(normal)), 0.999);
  EXPECT_NEAR(fit.normal.norm(), 1.0, 1e-12);
  EXPECT_GT(fit.planarity_weight, 0.5);
  EXPECT_GE(fit.sigma1, fit.sigma2);
  EXPECT_GE(fit.sigma2, fit.sigma3);
  const double a2d = (fit.sigma2 - fit.sigma3) / fit.sigma1;
  EXPECT_DOUBLE_EQ(fit.planarity_weight, a2d * a2d);
  // The middle axis lies in the plane, a unit vector orthogonal to the normal.
  EXPECT_NEAR(fit.middle_axis.norm(), 1.0, 1e-12);
  EXPECT_LT(std::abs(fit.middle_axis.dot(normal)), 0.01);
  EXPECT_LT(std::abs(fit.middle_axis.dot(fit.normal)), 1e-9);
  ASSERT_TRUE(FitPlane(Neighbours(line), &fit));
  EXPECT_LT(fit.planarity_weight, 0.01);
  // A line's normal and middle axis are the two directions across it (where the fit across a
  // ring line probes): both orthogonal to the line's direction e1.
  EXPECT_LT(std::abs(fit.normal.dot(e1)), 0.05);
  EXPECT_LT(std::abs(fit.middle_axis.dot(e1)), 0.05);
  EXPECT_NEAR(fit.middle_axis.norm(), 1.0, 1e-12);
  ASSERT_TRUE(FitPlane(Neighbours(blob), &fit));
  EXPECT_LT(fit.planarity_weight, 0.3);
  EXPECT_FALSE(FitPlane(Neighbours({origin, origin}), &fit));
  EXPECT_FALSE(FitPlane(Neighbours({origin, origin, origin}), &fit));
}

// The one-pass range gate + subsampling against a reference built on std::floor voxel keys and
// an ordered set, with points on and just beside voxel boundaries (negative ones included, where
// the floor-free key must round down), for 1, 2 and 3 threads (same indices).
TEST(Frontend, RangeGatedVoxelIndicesMatchesReferenceForAnyThreads) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  std::uniform_int_distribution<int> cell(-60, 60);
  std::vector<Vec3> raw;
  for (int i = 0; i < 70000; ++i) {
    if (i % 5 == 0) {  // exactly on a 0.5 m boundary, or one ulp beside it
      Vec3 p(0.5 * cell(rng), 0.5 * cell(rng), 0.5 * cell(rng));
      if (i % 3 == 1) p.x() = std::nextafter(p.x(), -1e9);
      if (i % 3 == 2) p.y() = std::nextafter(p.y(), 1e9);
      raw.push_back(p);
    } else {
      raw.emplace_back(u(rng), u(rng), 0.2 * u(rng));
    }
    if (i % 997 == 0) raw.back() = Vec3(0.2, 0.0, 0.0);  // inside min_range
    if (i % 1999 == 0) raw.back() = Vec3(std::nan(""), 1.0, 1.0);
  }
  std::vector<size_t> reference;
  std::set<std::tuple<int, int, int>> seen;
  for (size_t i = 0; i < raw.size(); ++i) {
    const double r2 = raw[i].squaredNorm();
    if (!(r2 >= 1.0 && r2 <= 40.0 * 40.0)) continue;
    const auto key = std::make_tuple(static_cast<int>(std::floor(raw[i].x() / 0.5)),
                                     static_cast<int>(std::floor(raw[i].y() / 0.5)),
                                     static_cast<int>(std::floor(raw[i].z() / 0.5)));
    if (seen.insert(key).second) reference.push_back(i);
  }
  ASSERT_GT(reference.size(), 10000u);
  // The buffer form (the odometry's, reused from sweep to sweep) starts from what it is given:
  // stale indices of a longer earlier sweep must not survive into the next result.
  std::vector<size_t> reused(reference.size() + 100, 7);
  for (const int threads : {1, 2, 3}) {
    EXPECT_EQ(RangeGatedVoxelIndices(raw, 0.5, 1.0, 40.0, threads), reference)
        << threads << " threads";
    RangeGatedVoxelIndices(raw, 0.5, 1.0, 40.0, threads, &reused);
    EXPECT_EQ(reused, reference) << threads << " threads, reused buffer";
  }
}

// The first point of each voxel among `points`, in order (std::floor keys, an ordered set).
std::vector<size_t> FirstOfVoxelReference(const std::vector<Vec3>& points, double size) {
  std::vector<size_t> kept;
  std::set<std::tuple<int64_t, int64_t, int64_t>> seen;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    if (!p.allFinite()) continue;
    const double inverse = 1.0 / size;  // the voxel of p is ⌊p · (1 / size)⌋
    if (seen.insert({static_cast<int64_t>(std::floor(p.x() * inverse)),
                     static_cast<int64_t>(std::floor(p.y() * inverse)),
                     static_cast<int64_t>(std::floor(p.z() * inverse))})
            .second) {
      kept.push_back(i);
    }
  }
  return kept;
}

// SelectSweep (one stream, identity shortcut) against the stages done one after the other with
// reference sets: the lidar-frame gate + 0.5 m subsampling, the robot-frame gate + subsampling
// of T·survivors, the 1 m keypoint voxels and the evenly spaced cap. Raw points on and one ulp
// beside voxel boundaries, negative ones, NaN, repeats, at the range limits; the identity, a
// rotation about z by π (a grid symmetry up to the floor's half-open cells) and the Newer
// College-like extrinsic; initial and regular voxel size; with and without a keypoint cap.
TEST(Frontend, SelectSweepEqualsThePreprocessingStages) {
  std::mt19937 rng(43);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  std::uniform_int_distribution<int> cell(-60, 60);
  std::vector<Vec3> raw;
  for (int i = 0; i < 20000; ++i) {
    if (i % 5 == 0) {
      Vec3 p(0.5 * cell(rng), 0.5 * cell(rng), 0.25 * cell(rng));
      if (i % 3 == 1) p.x() = std::nextafter(p.x(), -1e9);
      if (i % 3 == 2) p.z() = std::nextafter(p.z(), 1e9);
      raw.push_back(p);
    } else if (i % 5 == 1 && !raw.empty()) {
      raw.push_back(raw[raw.size() - 1 - rng() % std::min<size_t>(raw.size(), 200)]);
    } else {
      raw.emplace_back(u(rng), u(rng), 0.2 * u(rng));
    }
    if (i % 997 == 0) raw.back() = Vec3(0.3, -0.2, 0.0);   // inside min_range
    if (i % 1301 == 0) raw.back() = Vec3(40.0, 0.0, 0.0);  // exactly max_range
    if (i % 1999 == 0) raw.back() = Vec3(std::nan(""), 1.0, 1.0);
    if (i % 2003 == 0) raw.back() = Vec3(-0.0, 2.0 + 1e-3 * i, -0.0);  // T·p turns −0 into +0
  }
  SE3 rotated_z(Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix(), Vec3::Zero());
  Mat3 flip;
  flip << -1, 0, 0, 0, -1, 0, 0, 0, 1;
  const SE3 newer_college(flip, Vec3(-0.006253, 0.011775, 0.028535));
  for (const SE3& T : {SE3(), rotated_z, newer_college}) {
    for (const int cap : {0, 600}) {
      LidarFrontendOptions options;
      options.min_range = 1.0;
      options.max_range = 40.0;
      options.initial_scans = 1;
      options.max_keypoints = cap;
      LidarFrontend frontend(options);
      for (const double size : {options.initial_voxel_size, options.voxel_size}) {
        SweepSelection selection;
        frontend.SelectSweep(raw, T, &selection);
        // Reference: each stage on the previous one's survivors.
        std::vector<Vec3> gated;
        std::vector<size_t> gated_index;
        for (size_t i = 0; i < raw.size(); ++i) {
          const double r2 = raw[i].squaredNorm();
          if (r2 >= 1.0 && r2 <= 1600.0) {
            gated.push_back(raw[i]);
            gated_index.push_back(i);
          }
        }
        std::vector<Vec3> robot;
        std::vector<size_t> robot_index;
        for (const size_t j : FirstOfVoxelReference(gated, size)) {
          const Vec3 q = T * gated[j];
          const double r2 = q.squaredNorm();
          if (r2 >= 1.0 && r2 <= 1600.0) {
            robot.push_back(q);
            robot_index.push_back(gated_index[j]);
          }
        }
        std::vector<size_t> indices;
        std::vector<Vec3> points;
        for (const size_t j : FirstOfVoxelReference(robot, size)) {
          indices.push_back(robot_index[j]);
          points.push_back(robot[j]);
        }
        std::vector<size_t> keypoints = FirstOfVoxelReference(points, 1.0);
        if (cap > 0 && keypoints.size() > static_cast<size_t>(cap)) {
          std::vector<size_t> spaced;
          for (int i = 0; i < cap; ++i) spaced.push_back(keypoints[i * keypoints.size() / cap]);
          keypoints = spaced;
        }
        ASSERT_GT(indices.size(), 5000u);
        EXPECT_EQ(selection.indices, indices) << "size " << size;
        EXPECT_EQ(selection.points_robot, points) << "size " << size;
        for (size_t j = 0; j < std::min(points.size(), selection.points_robot.size()); ++j) {
          for (int a = 0; a < 3; ++a) {
            ASSERT_EQ(std::signbit(selection.points_robot[j][a]), std::signbit(points[j][a]))
                << "sign of zero, point " << j;
          }
        }
        EXPECT_EQ(selection.keypoints, keypoints) << "size " << size;
      }
      EXPECT_EQ(frontend.num_scans(), 2);
    }
  }
}

TEST(Frontend, PreprocessUsesFineVoxelsForInitialScans) {
  std::mt19937 rng(24);
  LidarFrontendOptions options;
  options.initial_scans = 1;
  LidarFrontend frontend(options);
  const auto sweep = RandomSweep(rng, 20000, 10.0);
  const auto first = frontend.Preprocess(sweep);
  const auto second = frontend.Preprocess(sweep);
  EXPECT_EQ(first.size(), VoxelGridSubsample(RangeGate(sweep, 1.0, 100.0), 0.2).size());
  EXPECT_EQ(second.size(), VoxelGridSubsample(RangeGate(sweep, 1.0, 100.0), 0.5).size());
  EXPECT_LT(second.size(), first.size());
  const auto keypoints = frontend.Keypoints(second);
  EXPECT_EQ(keypoints.size(), VoxelGridSubsample(second, 1.0).size());
  EXPECT_EQ(frontend.num_scans(), 2);
}

TEST(FrontendOptions, ShippedYamlHasTheDocumentedDefaults) {
  const auto o =
      LoadLidarFrontendOptions(ctlio::testing::SourceDir() + "/data/lidar_frontend.yaml");
  const LidarFrontendOptions d;
  EXPECT_EQ(o.min_range, d.min_range);
  EXPECT_EQ(o.max_range, d.max_range);
  EXPECT_EQ(o.voxel_size, 0.5);
  EXPECT_EQ(o.initial_voxel_size, 0.2);
  EXPECT_EQ(o.initial_scans, 20);
  EXPECT_EQ(o.keypoint_voxel_size, 1.0);
  EXPECT_EQ(o.map_voxel_size, 1.0);
  EXPECT_EQ(o.max_points_per_voxel, 20);
  EXPECT_EQ(o.min_point_distance, 0.1);
  EXPECT_EQ(o.max_map_distance, 400.0);
  EXPECT_EQ(o.max_neighbours, 20);
  EXPECT_EQ(o.min_neighbours, 10);
  EXPECT_EQ(o.max_plane_distance, 1.0);
  EXPECT_EQ(o.max_iterations, 10);
  EXPECT_EQ(o.solver_iterations, d.solver_iterations);
  EXPECT_EQ(o.point_noise_sigma, 0.03);
  EXPECT_EQ(o.point_noise_angle, 0.0);
  EXPECT_EQ(o.point_noise_angle, d.point_noise_angle);
  EXPECT_EQ(o.residual_blocks, "square_root");
  EXPECT_EQ(o.residual_blocks, d.residual_blocks);
  EXPECT_EQ(o.loss, d.loss);
  EXPECT_EQ(o.loss_scale, d.loss_scale);
  EXPECT_EQ(o.convergence_translation, d.convergence_translation);
  EXPECT_EQ(o.convergence_rotation, d.convergence_rotation);
  EXPECT_EQ(o.reassociation_distance, 0.0);
  EXPECT_EQ(o.reassociation_distance, d.reassociation_distance);
  EXPECT_EQ(o.association, "knn");
  EXPECT_EQ(o.association, d.association);
  EXPECT_EQ(o.voxel_plane_max_thickness, d.voxel_plane_max_thickness);
  EXPECT_EQ(o.line_neighbourhood_ratio, 0.0);
  EXPECT_EQ(o.line_neighbourhood_ratio, d.line_neighbourhood_ratio);
  EXPECT_EQ(o.max_plane_thickness, 0.0);
  EXPECT_EQ(o.max_plane_thickness, d.max_plane_thickness);
  EXPECT_EQ(o.plane_thickness_noise, 0.0);
  EXPECT_EQ(o.plane_thickness_noise, d.plane_thickness_noise);
  EXPECT_EQ(o.threads, 1);
  EXPECT_EQ(o.threads, d.threads);
}

std::string ErrorOf(const std::string& yaml) {
  try {
    LidarFrontendOptionsFromYaml(YAML::Load(yaml), "test.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(FrontendOptions, BadInputNamesFileAndLine) {
  EXPECT_EQ(ErrorOf("voxel_size: 0.3\nmax_neighbors: 20\n"),
            "test.yaml:2: unknown lidar front-end key 'max_neighbors'");
  EXPECT_EQ(ErrorOf("voxel_size: 0.3\nmin_neighbours: ten\n"),
            "test.yaml:2: bad value for 'min_neighbours'");
  EXPECT_NE(ErrorOf("min_neighbours: 30\n").find("max_neighbours"), std::string::npos);
  EXPECT_NE(ErrorOf("point_noise_sigma: 0\n").find("point_noise_sigma"), std::string::npos);
  EXPECT_NE(ErrorOf("loss: tukey\n").find("loss"), std::string::npos);
  EXPECT_NE(ErrorOf("association: kdtree\n").find("association"), std::string::npos);
  EXPECT_NE(ErrorOf("residual_blocks: scan\n").find("residual_blocks"), std::string::npos);
  EXPECT_EQ(LidarFrontendOptionsFromYaml(YAML::Load("residual_blocks: point\n")).residual_blocks,
            "point");
  EXPECT_NE(ErrorOf("threads: 0\n").find("threads"), std::string::npos);
  EXPECT_NE(ErrorOf("line_neighbourhood_ratio: 1.0\n").find("line_neighbourhood_ratio"),
            std::string::npos);
  EXPECT_NE(ErrorOf("line_neighbourhood_ratio: -0.1\n").find("line_neighbourhood_ratio"),
            std::string::npos);
  EXPECT_EQ(LidarFrontendOptionsFromYaml(YAML::Load("line_neighbourhood_ratio: 0.1\n"))
                .line_neighbourhood_ratio,
            0.1);
  EXPECT_NE(ErrorOf("max_plane_thickness: -0.01\n").find("max_plane_thickness"), std::string::npos);
  EXPECT_NE(ErrorOf("max_plane_thickness: .nan\n").find("max_plane_thickness"), std::string::npos);
  EXPECT_EQ(
      LidarFrontendOptionsFromYaml(YAML::Load("max_plane_thickness: 0.05\n")).max_plane_thickness,
      0.05);
  EXPECT_NE(ErrorOf("plane_thickness_noise: -1\n").find("plane_thickness_noise"),
            std::string::npos);
  EXPECT_NE(ErrorOf("plane_thickness_noise: .nan\n").find("plane_thickness_noise"),
            std::string::npos);
  EXPECT_EQ(
      LidarFrontendOptionsFromYaml(YAML::Load("plane_thickness_noise: 2\n")).plane_thickness_noise,
      2.0);
  EXPECT_NE(ErrorOf("reassociation_distance: -0.1\n").find("reassociation_distance"),
            std::string::npos);
  EXPECT_NE(ErrorOf("[1, 2]\n").find("mapping"), std::string::npos);
  EXPECT_EQ(LidarFrontendOptionsFromYaml(YAML::Load("voxel_size: 0.3\n")).voxel_size, 0.3);
  EXPECT_THROW(LoadLidarFrontendOptions("/nonexistent/lidar.yaml"), std::runtime_error);
  const std::string path = ::testing::TempDir() + "/lidar_frontend_bad.yaml";
  std::ofstream(path) << "voxel_size: [0.3\n";
  try {
    LoadLidarFrontendOptions(path);
    ADD_FAILURE() << "malformed YAML accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::ofstream(path) << "lidar_frontend:\n  voxel_size: 0.7\n";
  EXPECT_EQ(LoadLidarFrontendOptions(path).voxel_size, 0.7);
}

}  // namespace
}  // namespace ctlio::lio
