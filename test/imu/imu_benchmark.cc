// Speed of the IMU factors (SPEC §9: the reference's accelerometer error with
// Jacobians takes 0.59 µs; ctlio aims at ≤ 1 µs per factor with Jacobians).
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <vector>

#include "common/gradient_check.h"
#include "common/singer_model.h"
#include "ctlio/factors/gp/shared_knot_interval.h"
#include "ctlio/factors/gp/shared_state_interpolation.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/factors/imu/preintegrated_imu.h"
#include "ctlio/factors/imu/preintegrated_imu_factor.h"
#include "ctlio/manifolds/rotation_manifold.h"

namespace ctlio::imu {
namespace {

struct Knots {
  double pose_k[7], vel_k[6], acc_k[6], pose_k1[7], vel_k1[6], acc_k1[6], b_k[6], b_k1[6], q[4];
  double* params[9];
  double jac_store[9][3 * 7];
  double* jacobians[9];
  Knots() {
    std::mt19937 rng(1);
    PoseManifold::Store(testing::RandomPose(rng, 2.0, 3.0), pose_k);
    PoseManifold::Store(testing::RandomPose(rng, 2.0, 3.0), pose_k1);
    for (double* v : {vel_k, acc_k, vel_k1, acc_k1, b_k, b_k1}) {
      Eigen::Map<Vec6>{v} = testing::RandomVec6(rng, 1.0);
    }
    RotationManifold::Store(so3::Exp(Vec3(0.1, -0.2, 0.0)), q);
    double* p[] = {pose_k, vel_k, acc_k, pose_k1, vel_k1, acc_k1, b_k, b_k1, q};
    for (int i = 0; i < 9; ++i) {
      params[i] = p[i];
      jacobians[i] = jac_store[i];
    }
  }
};

void BM_AccelMeasurementWithJacobians(benchmark::State& state) {
  Knots k;
  const ImuAccelMeasurement cost(
      ctlio::testing::NewerCollegeSingerModel(), 0.0, 0.1, 0.043, Vec3(0.1, 0.2, 9.8),
      0.156 * Mat3::Identity(), 9.81,
      state.range(0) ? AccelModel::kSpecificForce : AccelModel::kBodyCentric);
  double r[3];
  for (auto _ : state) {
    cost.Evaluate(k.params, r, k.jacobians);
    benchmark::DoNotOptimize(r);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_AccelMeasurementWithJacobians)->Arg(0)->Arg(1);

// The accelerometer factor as it was before GpInterpolator::StateRows (full 18×18 state
// Jacobians, then the three rows it reads): the "before" of the speed-up, in the same run.
void BM_AccelMeasurementWithJacobiansFullState(benchmark::State& state) {
  Knots k;
  const gp::GpInterpolator interp(ctlio::testing::NewerCollegeSingerModel(), 0.0, 0.1, 0.043);
  const Mat3 S = SqrtInformation(0.156 * Mat3::Identity());
  const Vec3 accel(0.1, 0.2, 9.8), g_i(0, 0, -9.81);
  double r[3];
  for (auto _ : state) {
    const gp::KnotState a = gp::ReadKnotState(k.params[0], k.params[1], k.params[2]);
    const gp::KnotState b = gp::ReadKnotState(k.params[3], k.params[4], k.params[5]);
    const Mat3 C_mi = RotationManifold::Rotation(k.params[8]);
    gp::KnotState x;
    gp::StateJacobian J_k, J_k1;
    interp.State(a, b, &x, &J_k, &J_k1);
    const Vec3 g_r = x.pose.rotation() * (C_mi * g_i);
    const Vec3 ba = 0.57 * Eigen::Map<const Vec3>(k.b_k) + 0.43 * Eigen::Map<const Vec3>(k.b_k1);
    Eigen::Map<Vec3>{r} = S * (accel + x.acceleration.head<3>() + g_r - ba);
    const Mat3 G = -so3::Hat(g_r);
    for (int i = 0; i < 2; ++i) {
      const gp::StateJacobian& J = i == 0 ? J_k : J_k1;
      Eigen::Matrix<double, 3, 18> DJ = J.middleRows<3>(12);
      DJ.noalias() += G * J.middleRows<3>(3);
      const Eigen::Matrix<double, 3, 18> W = S * DJ;
      LiftPoseJacobian<3>(W.leftCols<6>(), k.params[3 * i], k.jacobians[3 * i]);
      Eigen::Map<Eigen::Matrix<double, 3, 6, Eigen::RowMajor>>{k.jacobians[3 * i + 1]} =
          W.middleCols<6>(6);
      Eigen::Map<Eigen::Matrix<double, 3, 6, Eigen::RowMajor>>{k.jacobians[3 * i + 2]} =
          W.rightCols<6>();
    }
    for (int i = 0; i < 2; ++i) {
      Eigen::Map<Eigen::Matrix<double, 3, 6, Eigen::RowMajor>> J{k.jacobians[6 + i]};
      J.leftCols<3>() = -(i == 0 ? 0.57 : 0.43) * S;
      J.rightCols<3>().setZero();
    }
    LiftRotationJacobian<3>(-S * x.pose.rotation() * so3::Hat(C_mi * g_i), k.params[8],
                            k.jacobians[8]);
    benchmark::DoNotOptimize(r);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_AccelMeasurementWithJacobiansFullState);

// The interpolator alone: the full 18×18 Jacobians and the rows each IMU factor reads.
void BM_InterpolatorState(benchmark::State& state) {
  Knots k;
  const gp::GpInterpolator interp(ctlio::testing::NewerCollegeSingerModel(), 0.0, 0.1, 0.043);
  const gp::KnotState a = gp::ReadKnotState(k.params[0], k.params[1], k.params[2]);
  const gp::KnotState b = gp::ReadKnotState(k.params[3], k.params[4], k.params[5]);
  const unsigned masks[] = {gp::kAllStateRows, gp::kRotationRows | gp::kLinearAccelerationRows,
                            gp::kAngularVelocityRows};
  const unsigned rows = masks[state.range(0)];
  gp::KnotState x;
  gp::StateJacobian J_k, J_k1;
  for (auto _ : state) {
    if (state.range(0) == 0) {
      interp.State(a, b, &x, &J_k, &J_k1);
    } else {
      interp.StateRows(a, b, rows, &x, &J_k, &J_k1);
    }
    benchmark::DoNotOptimize(J_k.data());
    benchmark::DoNotOptimize(J_k1.data());
    benchmark::ClobberMemory();
  }
}
// 0: State (all rows), 1: StateRows accelerometer rows, 2: StateRows gyro rows.
BENCHMARK(BM_InterpolatorState)->Arg(0)->Arg(1)->Arg(2);

void BM_AccelMeasurementValueOnly(benchmark::State& state) {
  Knots k;
  // The paper's model, as these rows were recorded with before the default became the exact one.
  const ImuAccelMeasurement cost(ctlio::testing::NewerCollegeSingerModel(), 0.0, 0.1, 0.043,
                                 Vec3(0.1, 0.2, 9.8), 0.156 * Mat3::Identity(), 9.81,
                                 AccelModel::kBodyCentric);
  double r[3];
  for (auto _ : state) {
    cost.Evaluate(k.params, r, nullptr);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_AccelMeasurementValueOnly);

void BM_AccelMeasurementConstructAndEvaluate(benchmark::State& state) {
  Knots k;
  const gp::SingerModel<6> model = ctlio::testing::NewerCollegeSingerModel();
  double r[3];
  for (auto _ : state) {
    const ImuAccelMeasurement cost(model, 0.0, 0.1, 0.043, Vec3(0.1, 0.2, 9.8),
                                   0.156 * Mat3::Identity(), 9.81, AccelModel::kBodyCentric);
    cost.Evaluate(k.params, r, k.jacobians);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_AccelMeasurementConstructAndEvaluate);

void BM_GyroMeasurementWithJacobians(benchmark::State& state) {
  Knots k;
  const ImuGyroMeasurement cost(ctlio::testing::NewerCollegeSingerModel(), 0.0, 0.1, 0.043,
                                Vec3(0.1, 0.2, 0.3), 4.326e-4 * Mat3::Identity());
  double r[3];
  for (auto _ : state) {
    cost.Evaluate(k.params, r, k.jacobians);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_GyroMeasurementWithJacobians);

// One IMU sample as a window's solve evaluates it (the main job's exact specific force): per
// iteration the knots move (as between two evaluation points), the evaluation callback prepares
// the knot interval once (gp::SharedKnotInterval) and each sample's state once
// (gp::SharedStateInterpolation), and each sample's gyro and accelerometer residual are
// evaluated with Jacobians. Arg: samples on the interval (1: nothing shared between samples;
// 20: 200 Hz over a 0.1 s interval, as in the LIO). Counter per_sample: CPU time per sample
// (gyro + accelerometer), to set beside BM_GyroMeasurementWithJacobians +
// BM_AccelMeasurementWithJacobians/1, which each interpolate on their own.
void BM_ImuSampleInSolve(benchmark::State& state) {
  Knots k;
  const int n = static_cast<int>(state.range(0));
  const gp::KnotBlocks knots = {k.pose_k, k.vel_k, k.acc_k, k.pose_k1, k.vel_k1, k.acc_k1};
  const auto interval = std::make_shared<gp::SharedKnotInterval>(knots);
  std::vector<std::shared_ptr<gp::SharedStateInterpolation>> states;
  std::vector<std::unique_ptr<ImuGyroMeasurement>> gyro;
  std::vector<std::unique_ptr<ImuAccelMeasurement>> accel;
  for (int i = 0; i < n; ++i) {
    states.push_back(std::make_shared<gp::SharedStateInterpolation>(
        ctlio::testing::NewerCollegeSingerModel(), 0.0, 0.1, 0.1 * (i + 0.5) / n, knots));
    states.back()->set_interval(interval);
    gyro.push_back(std::make_unique<ImuGyroMeasurement>(states.back(), Vec3(0.1, 0.2, 0.3),
                                                        4.326e-4 * Mat3::Identity()));
    accel.push_back(std::make_unique<ImuAccelMeasurement>(states.back(), Vec3(0.1, 0.2, 9.8),
                                                          0.156 * Mat3::Identity(), 9.81,
                                                          AccelModel::kSpecificForce));
  }
  double r[3], step = 1e-9;
  for (auto _ : state) {
    k.vel_k1[0] += step;  // a new evaluation point: everything is prepared again
    step = -step;
    for (const auto& s : states) s->Prepare();
    for (int i = 0; i < n; ++i) {
      gyro[i]->Evaluate(k.params, r, k.jacobians);
      benchmark::DoNotOptimize(r);
      accel[i]->Evaluate(k.params, r, k.jacobians);
      benchmark::DoNotOptimize(r);
    }
    benchmark::ClobberMemory();
  }
  int64_t computed = 0;
  for (const auto& s : states) computed += s->num_computed();
  if (computed != 0) state.SkipWithError("a residual interpolated on its own");
  state.counters["per_sample"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * n,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ImuSampleInSolve)->Arg(1)->Arg(20);

ImuNoise Noise() {
  ImuNoise n;
  n.gyro_noise_density = 1.7e-4;
  n.accel_noise_density = 2e-3;
  return n;
}

void BM_PreintegrationStep(benchmark::State& state) {
  PreintegratedImu pim(Vec6::Zero(), Noise());
  for (auto _ : state) {
    pim.Integrate(Vec3(0.1, 0.2, 9.8), Vec3(0.1, -0.2, 0.3), 0.005);
    benchmark::DoNotOptimize(pim.delta_position());
  }
}
BENCHMARK(BM_PreintegrationStep);

void BM_PreintegratedImuFactorWithJacobians(benchmark::State& state) {
  PreintegratedImu pim(Vec6::Zero(), Noise());
  for (int i = 0; i < 200; ++i) pim.Integrate(Vec3(0.1, 0.2, 9.8), Vec3(0.1, -0.2, 0.3), 0.005);
  const PreintegratedImuFactor cost(pim, Vec3(0, 0, -9.81));
  std::mt19937 rng(2);
  double pi[7], pj[7], vi[3] = {0.1, 0.2, 0.3}, vj[3] = {0.3, 0.2, 0.1},
                       b[6] = {0.01, 0, 0, 0, 0.01, 0};
  PoseManifold::Store(testing::RandomPose(rng, 2.0, 3.0), pi);
  PoseManifold::Store(testing::RandomPose(rng, 2.0, 3.0), pj);
  const double* params[] = {pi, vi, b, pj, vj};
  double j0[63], j1[27], j2[54], j3[63], j4[27];
  double* jac[] = {j0, j1, j2, j3, j4};
  double r[9];
  for (auto _ : state) {
    cost.Evaluate(params, r, jac);
    benchmark::DoNotOptimize(r);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_PreintegratedImuFactorWithJacobians);

}  // namespace
}  // namespace ctlio::imu

BENCHMARK_MAIN();
