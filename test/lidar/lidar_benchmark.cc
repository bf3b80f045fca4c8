// Speed of the lidar front end and factors (SPEC §4, §9): voxel-map insertion and neighbour
// queries per second, voxel subsampling, the point-to-plane factors with Jacobians, and one
// registration of a real ~25k-point Newer College sweep (skipped if the data is absent).
// Report medians: --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <array>
#include <filesystem>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "common/gradient_check.h"
#include "common/singer_model.h"
#include "common/test_paths.h"
#include "ctlio/factors/gp/interpolator.h"
#include "ctlio/factors/gp/shared_knot_interval.h"
#include "ctlio/factors/lidar/continuous_point_to_plane.h"
#include "ctlio/factors/lidar/point_to_plane.h"
#include "ctlio/io/point_cloud_io.h"
#include "ctlio/solvers/lio/frontend.h"
#include "ctlio/solvers/lio/voxel_map.h"
#include "sweep_registration.h"

namespace ctlio::lio {
namespace {

const std::string kFolder =
    ctlio::testing::SharedDataDir() + "/gtsam_points_lidar_samples/newer_college_2020_06";

// A synthetic outdoor-like sweep: ground plane, walls and clutter within 40 m.
std::vector<Vec3> SyntheticSweep(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> pts(n);
  for (int i = 0; i < n; ++i) {
    const double a = M_PI * u(rng), r = 3.0 + 37.0 * std::abs(u(rng));
    switch (i % 3) {
      case 0:
        pts[i] = Vec3(r * std::cos(a), r * std::sin(a), -1.5);
        break;
      case 1:
        pts[i] = Vec3(20.0, 40.0 * u(rng), 5.0 * u(rng));
        break;
      default:
        pts[i] = Vec3(r * std::cos(a), r * std::sin(a), 3.0 * u(rng));
        break;
    }
  }
  return pts;
}

// Arg 1: the map keeps per-voxel planes (moments on insertion, refit of the changed voxels).
void BM_VoxelMapInsert(benchmark::State& state) {
  const auto pts = SyntheticSweep(25000, 1);
  VoxelMap::Options o;
  o.fit_planes = state.range(0) != 0;
  for (auto _ : state) {
    VoxelMap map(o);
    benchmark::DoNotOptimize(map.Insert(pts));
  }
  state.SetItemsProcessed(state.iterations() * pts.size());
}
BENCHMARK(BM_VoxelMapInsert)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// One association: Arg 0 the kNN plane (20 neighbours + PCA), Arg 1 the map's voxel plane.
void BM_Associate(benchmark::State& state) {
  LidarFrontendOptions options;
  options.association = state.range(0) != 0 ? "voxel_plane" : "knn";
  VoxelMap map(LidarFrontend::MapOptions(options));
  for (uint32_t s = 0; s < 8; ++s) map.Insert(SyntheticSweep(25000, 10 + s));
  const auto queries = SyntheticSweep(4096, 99);
  PlaneAssociator associator(map, options);
  PlaneAssociation a;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(associator.Associate(Vec3::Zero(), queries[i++ & 4095], &a));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Associate)->Arg(0)->Arg(1);

void BM_VoxelMapKNearest(benchmark::State& state) {
  VoxelMap map(VoxelMap::Options{});
  for (uint32_t s = 0; s < 8; ++s) map.Insert(SyntheticSweep(25000, 10 + s));
  const auto queries = SyntheticSweep(4096, 99);
  std::vector<VoxelMap::Neighbour> out;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(map.KNearest(queries[i++ & 4095], 20, &out));
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["map_points"] = static_cast<double>(map.num_points());
}
BENCHMARK(BM_VoxelMapKNearest);

void BM_VoxelGridSubsample(benchmark::State& state) {
  std::vector<TimedPoint> sweep;
  for (const Vec3& p : SyntheticSweep(100000, 2)) sweep.push_back({p, 0.0});
  const double size = state.range(0) / 10.0;
  for (auto _ : state) benchmark::DoNotOptimize(VoxelGridSubsample(sweep, size).size());
  state.SetItemsProcessed(state.iterations() * sweep.size());
}
BENCHMARK(BM_VoxelGridSubsample)->Arg(2)->Arg(5)->Arg(10)->Unit(benchmark::kMicrosecond);

// A 128-beam × 1800-firing sweep (230 400 returns, the main job's size) in firing order from the
// centre of a 100 × 60 × 10 m box, as the simulator's room: consecutive returns of a firing fall
// in neighbouring voxels, as in a real sweep.
std::vector<Vec3> BoxSweep() {
  const Vec3 half(50.0, 30.0, 5.0);
  std::vector<Vec3> pts;
  pts.reserve(128 * 1800);
  for (int f = 0; f < 1800; ++f) {
    const double azimuth = 2.0 * M_PI * f / 1800;
    for (int b = 0; b < 128; ++b) {
      const double elevation = (-22.5 + 45.0 * b / 127) * M_PI / 180.0;
      const Vec3 d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                   std::sin(elevation));
      double r = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        if (d[a] != 0.0) r = std::min(r, half[a] / std::abs(d[a]));
      }
      pts.push_back(r * d + Vec3(0.0, 0.0, 0.3));
    }
  }
  return pts;
}

// The preprocessing's one pass (range gate 1–100 m + first point per 0.5 m voxel) over the
// 230 400 returns, with Arg threads, against the floor of any such pass: reading the points
// once (BM_SweepBandwidthFloor).
void BM_RangeGatedVoxelIndices(benchmark::State& state) {
  const std::vector<Vec3> sweep = BoxSweep();
  const int threads = static_cast<int>(state.range(0));
  size_t kept = 0;
  for (auto _ : state) {
    kept = RangeGatedVoxelIndices(sweep, 0.5, 1.0, 100.0, threads).size();
    benchmark::DoNotOptimize(kept);
  }
  state.SetItemsProcessed(state.iterations() * sweep.size());
  state.counters["kept"] = static_cast<double>(kept);
}
BENCHMARK(BM_RangeGatedVoxelIndices)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_SweepBandwidthFloor(benchmark::State& state) {
  const std::vector<Vec3> sweep = BoxSweep();
  for (auto _ : state) {
    double sum = 0.0;
    for (const Vec3& p : sweep) sum += p.squaredNorm();
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * sweep.size());
}
BENCHMARK(BM_SweepBandwidthFloor)->Unit(benchmark::kMicrosecond);

PlaneAssociation SomeAssociation() {
  PlaneAssociation m;
  m.point_robot = Vec3(10.0, -3.0, 1.0);
  m.plane_point = Vec3(9.0, -2.0, 0.5);
  m.plane_normal = Vec3(0.3, 0.4, 0.8).normalized();
  m.weight = 0.7;
  return m;
}

void BM_PointToPlaneWithJacobian(benchmark::State& state) {
  std::mt19937 rng(3);
  const auto x = testing::PoseParameters(testing::RandomPose(rng, 1.0, 5.0));
  const PointToPlane cost(SomeAssociation());
  const double* params[] = {x.data()};
  double r, J[7];
  double* jac[] = {J};
  for (auto _ : state) {
    cost.Evaluate(params, &r, jac);
    benchmark::DoNotOptimize(J[0]);
  }
}
BENCHMARK(BM_PointToPlaneWithJacobian);

void BM_ContinuousPointToPlane(benchmark::State& state) {
  std::mt19937 rng(4);
  const gp::SingerModel<6> model = testing::NewerCollegeSingerModel();
  const SE3 T_k = testing::RandomPose(rng, 1.0, 5.0);
  const auto pk = testing::PoseParameters(T_k);
  const auto pk1 = testing::PoseParameters(testing::RandomPose(rng, 0.2, 0.3) * T_k);
  const Vec6 w_k = testing::RandomVec6(rng, 1.0), a_k = testing::RandomVec6(rng, 5.0);
  const Vec6 w_k1 = testing::RandomVec6(rng, 1.0), a_k1 = testing::RandomVec6(rng, 5.0);
  const ContinuousPointToPlane cost(
      std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.05), SomeAssociation());
  const double* params[] = {pk.data(),  w_k.data(),  a_k.data(),
                            pk1.data(), w_k1.data(), a_k1.data()};
  double r, J0[7], J1[6], J2[6], J3[7], J4[6], J5[6];
  double* jac[] = {J0, J1, J2, J3, J4, J5};
  const bool with_jacobians = state.range(0) != 0;
  for (auto _ : state) {
    cost.Evaluate(params, &r, with_jacobians ? jac : nullptr);
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(J0[0]);
  }
}
BENCHMARK(BM_ContinuousPointToPlane)->Arg(0)->Arg(1);

// One lidar residual as a window's solve evaluates it: per iteration the knots move (a new
// evaluation point), the evaluation callback prepares each firing's interpolation once with the
// interval's local variables formed once (gp/shared_knot_interval.h), and each firing's residual
// is evaluated with Jacobians. The main job has ~600 keypoints on ~1800 firings, i.e. about one
// residual per firing: Arg = firings on the interval, one residual each. Counter per_point: CPU
// time per residual including its firing's interpolation, to set beside
// BM_ContinuousPointToPlane/1, which interpolates on its own.
void BM_ContinuousPointToPlaneInSolve(benchmark::State& state) {
  std::mt19937 rng(4);
  const gp::SingerModel<6> model = testing::NewerCollegeSingerModel();
  const SE3 T_k = testing::RandomPose(rng, 1.0, 5.0);
  const auto pk = testing::PoseParameters(T_k);
  const auto pk1 = testing::PoseParameters(testing::RandomPose(rng, 0.2, 0.3) * T_k);
  const Vec6 w_k = testing::RandomVec6(rng, 1.0), a_k = testing::RandomVec6(rng, 5.0);
  Vec6 w_k1 = testing::RandomVec6(rng, 1.0);
  const Vec6 a_k1 = testing::RandomVec6(rng, 5.0);
  const gp::KnotBlocks knots = {pk.data(),  w_k.data(),  a_k.data(),
                                pk1.data(), w_k1.data(), a_k1.data()};
  const auto interval = std::make_shared<gp::SharedKnotInterval>(knots);
  const int n = static_cast<int>(state.range(0));
  std::vector<std::shared_ptr<SharedPoseInterpolation>> firings;
  std::vector<std::unique_ptr<ContinuousPointToPlane>> costs;
  for (int i = 0; i < n; ++i) {
    firings.push_back(std::make_shared<SharedPoseInterpolation>(
        std::make_shared<const gp::GpInterpolator>(model, 0.0, 0.1, 0.1 * (i + 0.5) / n), knots));
    firings.back()->set_interval(interval);
    costs.push_back(std::make_unique<ContinuousPointToPlane>(firings.back(), SomeAssociation()));
  }
  double r, J0[7], J1[6], J2[6], J3[7], J4[6], J5[6], step = 1e-9;
  double* jac[] = {J0, J1, J2, J3, J4, J5};
  for (auto _ : state) {
    w_k1[0] += step;  // a new evaluation point: everything is prepared again
    step = -step;
    for (const auto& f : firings) f->Prepare();
    for (const auto& c : costs) {
      c->Evaluate(knots.data(), &r, jac);
      benchmark::DoNotOptimize(r);
      benchmark::DoNotOptimize(J0[0]);
    }
    benchmark::ClobberMemory();
  }
  int64_t computed = 0;
  for (const auto& f : firings) computed += f->num_computed();
  if (computed != 0) state.SkipWithError("a residual interpolated on its own");
  state.counters["per_point"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * n,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ContinuousPointToPlaneInSolve)->Arg(1)->Arg(20);

// The real-data test's pipeline on sweep 00 (25,109 points): preprocessing, keypoints, rigid
// fit, then the two-knot continuous-time registration, with a residual block per keypoint
// (first arg 0, residual_blocks "point"), one for the interval (1, "interval") or that block in
// square-root form (2, "square_root", the default); second arg: the
// threads of the front end and of the window's solve (lidar_frontend.threads = window.threads).
void BM_RegisterNewerCollegeSweep(benchmark::State& state) {
  if (!std::filesystem::is_directory(kFolder)) {
    state.SkipWithError("Newer College sweeps not found");
    return;
  }
  const io::PointCloud raw =
      io::ReadKittiBin(kFolder + "/raw_00.bin", 3, kFolder + "/times_00.bin");
  const io::PointCloud deskewed = io::ReadKittiBin(kFolder + "/deskewed_00.bin", 3);
  const Mat3 Rz = Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix();
  std::vector<TimedPoint> sweep(raw.size());
  double t_end = 0.0;
  for (size_t i = 0; i < raw.size(); ++i) {
    sweep[i] = {Rz * raw.points[i], raw.RelativeTime(i)};
    t_end = std::max(t_end, sweep[i].time);
  }
  LidarFrontendOptions options;
  options.residual_blocks =
      std::array<const char*, 3>{"point", "interval", "square_root"}[state.range(0)];
  options.threads = static_cast<int>(state.range(1));
  const gp::SingerModel<6> model = testing::NewerCollegeSingerModel();
  LidarFrontend map_frontend(options);
  map_frontend.UpdateMap(deskewed.points, Vec3::Zero());
  int keypoints = 0;
  for (auto _ : state) {
    LidarFrontend frontend(options);
    const auto kp = frontend.Keypoints(frontend.Preprocess(sweep));
    keypoints = static_cast<int>(kp.size());
    SE3 T;
    sweep::RegisterRigid(map_frontend.map(), options, kp, &T);
    gp::KnotState k, k1;
    k.pose = T;
    k1.pose = T;
    benchmark::DoNotOptimize(
        sweep::RegisterContinuous(map_frontend.map(), options, model, kp, 0.0, t_end, &k, &k1));
  }
  state.counters["keypoints"] = keypoints;
  state.counters["points"] = static_cast<double>(sweep.size());
}
BENCHMARK(BM_RegisterNewerCollegeSweep)
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Args({1, 2})
    ->Args({2, 2})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

}  // namespace
}  // namespace ctlio::lio

BENCHMARK_MAIN();
