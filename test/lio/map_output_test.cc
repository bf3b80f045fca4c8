// The map of a run (ctlio_odometry --save_map): on a short simulated sequence the deskewed,
// registered points the odometry inserted (RunOptions::map_points → MapAccumulator) lie on the
// simulated world's surfaces, and the same check rejects the map moved by 15 cm; the file
// written reads back with the same points.
#include "lio/map_output.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "common/sim_lio.h"
#include "common/temp_dir.h"
#include "ctlio/io/map_cloud_io.h"
#include "ctlio/io/point_cloud_io.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/odometry_config.h"
#include "lio/map_accumulator.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

// True if a surface of `scene` passes within `d` of p: among p and its 26 neighbours at ±d along
// the axes and diagonals, some lie inside a solid and some do not.
bool NearSurface(const sim::Scene& scene, const Vec3& p, double d) {
  bool inside = false, outside = false;
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      for (int k = -1; k <= 1; ++k) {
        (scene.Occupied(p + d * Vec3(i, j, k)) ? inside : outside) = true;
      }
    }
  }
  return inside && outside;
}

double FractionNearSurface(const sim::Scene& scene, const std::vector<Vec3>& points,
                           const SE3& T_world_map, double d) {
  size_t near = 0;
  for (const Vec3& p : points) near += NearSurface(scene, T_world_map * p, d) ? 1 : 0;
  return double(near) / double(points.size());
}

// The map frame in the world: the true lidar pose of the estimated scan `k` (default: the
// first) times its estimate's inverse. (The lidar's, not the robot's: with an extrinsic estimated
// online the registration fixes the lidar pose, T_mr absorbs the extrinsic's error.)
SE3 WorldFromMap(const lioapp::RunSummary& run, const sim::SimulatedSource& source, size_t k = 0) {
  const auto truth = source.GroundTruth();
  const io::StampedPose& scan = run.trajectory.at(k);
  const auto at = std::find_if(truth->begin(), truth->end(),
                               [&](const io::StampedPose& q) { return q.t_ns == scan.t_ns; });
  EXPECT_NE(at, truth->end());
  return at == truth->end() ? SE3() : at->pose * scan.pose.Inverse();
}

TEST(MapOutput, PointsLieOnTheSimulatedSurfaces) {
  // The street world (façades, cars, poles, trees) at walking pace, reduced lidar.
  sim::SimConfig c =
      sim::ExperimentConfig(sim::Regime::kMedium, 0, sim::kExperimentSeed, sim::WorldKind::kStreet);
  c.duration_s = 2.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 4;
  sim::SimulatedSource source(c);
  OdometryConfig config = testing::SimLioConfig();
  config.method = LioMethod::kSingerLio;
  lioapp::MapAccumulator map(0.2);
  size_t scans_mapped = 0;
  lioapp::RunOptions options;
  options.map_points = [&](const ScanResult& r, const std::vector<Vec3>& points) {
    EXPECT_NE(r.status, ScanStatus::kFailed);
    EXPECT_FALSE(points.empty());
    map.Add(points);
    ++scans_mapped;
  };
  const lioapp::RunSummary run = lioapp::RunOdometry(source, config, options);
  ASSERT_EQ(run.failed, 0) << run.first_failure;
  ASSERT_TRUE(run.ate);
  EXPECT_EQ(scans_mapped, run.trajectory.size());  // every estimated scan, the first included
  EXPECT_GT(map.size(), 3000u);

  const SE3 T_world_map = WorldFromMap(run, source);
  const std::vector<Vec3> points = map.Points();
  const sim::Scene& scene = source.simulator().world().scene;
  // Within 0.1 m, half a voxel: the centroid of a voxel cut by a corner sits off its surfaces by
  // up to that (0.05 m leaves out ~9 % of the points, those near edges).
  const double on = FractionNearSurface(scene, points, T_world_map, 0.1);
  EXPECT_GT(on, 0.95) << "ATE " << run.ate->rmse;
  // The check can fail: 15 cm off in every axis takes most points off their surfaces.
  const SE3 moved(Mat3::Identity(), Vec3(0.15, 0.15, 0.15));
  const double off = FractionNearSurface(scene, points, moved * T_world_map, 0.1);
  EXPECT_LT(off, 0.5);
  std::printf("map: %zu points, %.1f%% within 0.1 m of a surface, %.1f%% when moved by 15 cm\n",
              points.size(), 100.0 * on, 100.0 * off);

  // What --save_map writes: these points, read back by the project's reader.
  const std::string path =
      lioapp::MapPath("map.pcd", testing::FreshTempDir("map_output").string(), "singer_lio", false);
  io::WriteMapCloud(path, points);
  const io::PointCloud back = io::ReadPcd(path);
  ASSERT_EQ(back.size(), points.size());
  for (size_t i = 0; i < points.size(); i += 97) {
    EXPECT_LT((back.points[i] - points[i]).norm(), 1e-4);
  }
}

TEST(MapOutput, StartsOverAtTheCalibrationWarmupReplay) {
  // Both calibrations from a wrong start (3° / 10 cm extrinsic, 20 ms clock offset), replayed
  // after 1 s: the warm-up's live points, placed with the wrong extrinsic, are not in the map;
  // the replay's are, in the frame of the revised trajectory.
  sim::SimulatedSource source(testing::WrongCalibrationSequence(sim::Regime::kMedium, 2.0, 0.020));
  OdometryConfig config = testing::SimLioConfig();
  config.calibration.estimate_time_offset = true;
  config.calibration.estimate_extrinsic = true;
  config.calibration.warmup_replay_s = 1.0;
  config.T_imu_lidar = source.ImuFromLidar();  // the perturbed nominal
  lioapp::MapAccumulator map(0.2), everything(0.2);
  int restarts = 0;
  lioapp::RunOptions options;
  options.extrinsic_from_config = true;
  // The replay adopted with the scan that reaches the span: from there the replayed pipeline's
  // points (adopted at the end of the input, the default, no scan follows: the map stays the live
  // one, calibration.md).
  options.replay_adopt_after_s = 0.0;
  options.map_points = [&](const ScanResult& r, const std::vector<Vec3>& points) {
    if (r.revised_scans > 0) {
      ++restarts;
      map.Clear();
    }
    map.Add(points);
    everything.Add(points);
  };
  const lioapp::RunSummary run = lioapp::RunOdometry(source, config, options);
  ASSERT_EQ(run.failed, 0) << run.first_failure;
  ASSERT_GT(run.warmup_replayed_scans, 0);
  EXPECT_EQ(restarts, 1);
  // Anchored at the newest scan: the map starts at the replay, whose first scans' poses it
  // revised (anchored at the first, 70 % of the points are within 0.1 m; 100 % from the replay
  // on).
  const sim::Scene& scene = source.simulator().world().scene;
  const SE3 T_world_map = WorldFromMap(run, source, run.trajectory.size() - 1);
  const double on = FractionNearSurface(scene, map.Points(), T_world_map, 0.1);
  // Without the restart the warm-up's live points, in the live frame with the wrong extrinsic,
  // stay in the map.
  const double kept = FractionNearSurface(scene, everything.Points(), T_world_map, 0.1);
  std::printf(
      "replayed map: %zu points, %.1f%% within 0.1 m of a surface; %.1f%% of %zu with "
      "the warm-up kept\n",
      map.size(), 100.0 * on, 100.0 * kept, everything.size());
  EXPECT_GT(on, 0.95);
  EXPECT_LT(kept, on - 0.05);
}

TEST(MapOutput, OneFilePerMethod) {
  EXPECT_EQ(lioapp::MapPath("map.pcd", "/out", "singer_lio", false), "/out/map.pcd");
  EXPECT_EQ(lioapp::MapPath("maps/m.ply", "/out/imu_input", "imu_input", true),
            "/out/imu_input/maps/m.ply");
  EXPECT_EQ(lioapp::MapPath("/data/run.pcd", "/out", "singer_lio", false), "/data/run.pcd");
  EXPECT_EQ(lioapp::MapPath("/data/run.pcd", "/out/imu_input", "imu_input", true),
            "/data/run_imu_input.pcd");
  EXPECT_EQ(lioapp::MapPicturePath("/out/map.pcd"), "/out/map.png");
}

}  // namespace
}  // namespace ctlio::lio
