// The IMU samples of one knot interval as one residual block (imu/imu_interval_batch.h): its rows
// and Jacobians are the stacked per-sample factors' (ImuGyroMeasurement, ImuAccelMeasurement and
// their time-offset forms) with Ceres' loss correction of each accelerometer sample, its cost and
// gradient in a ceres::Problem equal the per-sample blocks', and without a loss its Jacobians
// match numeric differentiation at generic, near-π and near-identity knots, for the WNOJ prior,
// the Singer prior and a Singer prior with α·Δt → 0.
#include "ctlio/factors/imu/imu_interval_batch.h"

#include <ceres/crs_matrix.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "common/gradient_check.h"
#include "ctlio/factors/imu/imu_accel_time_offset.h"
#include "ctlio/factors/imu/imu_gyro_time_offset.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/manifolds/pose_manifold.h"
#include "ctlio/manifolds/rotation_manifold.h"
#include "imu/imu_test_blocks.h"

namespace ctlio::imu {
namespace {

using gp::SingerModel;
using testing::Blocks;

constexpr double kTk = 0.3, kTk1 = 0.4;

// α·Δt = 1e-8 on every axis: the Singer transition's near-singular branch.
SingerModel<6> TinyAlpha() { return SingerModel<6>(Vec6::Constant(300.0), Vec6::Constant(1e-7)); }

std::vector<SingerModel<6>> Models() { return {testing::Wnoj(), testing::Singer(), TinyAlpha()}; }

ImuMounting Mounted(std::mt19937& rng) {
  ImuMounting m;
  m.C_ri = testing::RandomPose(rng, 1.0, 0.0).rotation();
  m.lever_arm = testing::RandomVec6(rng, 0.3).head<3>();
  return m;
}

// N samples at distinct times in the interval (both ends included), with measurements large
// enough that several whitened accelerometer errors sit in the Cauchy loss's outlier region.
std::vector<ImuIntervalBatch::Sample> Samples(std::mt19937& rng, int n) {
  std::vector<ImuIntervalBatch::Sample> out;
  for (int i = 0; i < n; ++i) {
    ImuIntervalBatch::Sample s;
    s.time = kTk + (kTk1 - kTk) * i / (n - 1.0);
    s.gyro = testing::RandomVec6(rng, 3.0).head<3>();
    s.accel = testing::RandomVec6(rng, 12.0).head<3>();
    out.push_back(s);
  }
  return out;
}

struct Params {
  Blocks blocks;
  double delta[1] = {0.0};
  std::vector<const double*> Batch(const ImuIntervalBatch& b) const {
    std::vector<const double*> p = b.accelerometer() ? blocks.Accel() : blocks.Gyro();
    if (b.offset_block() >= 0) p.push_back(delta);
    return p;
  }
};

std::vector<const ceres::Manifold*> BatchManifolds(const testing::ImuManifolds& m,
                                                   const ImuIntervalBatch& b) {
  std::vector<const ceres::Manifold*> out = b.accelerometer() ? m.accel : m.gyro;
  if (b.offset_block() >= 0) out.push_back(nullptr);
  return out;
}

// The per-sample factors of the batch's samples, in its row order (gyro, then accelerometer).
struct PerSample {
  std::vector<std::unique_ptr<ceres::CostFunction>> gyro, accel;
};
PerSample PerSampleFactors(const SingerModel<6>& model,
                           const std::vector<ImuIntervalBatch::Sample>& samples,
                           const ImuIntervalBatch::Options& o) {
  PerSample f;
  for (const ImuIntervalBatch::Sample& s : samples) {
    if (o.estimate_time_offset) {
      f.gyro.emplace_back(new ImuGyroMeasurementWithTimeOffset(model, kTk, kTk1, s.time, s.gyro,
                                                               o.gyro_covariance, o.mounting));
      if (o.accelerometer) {
        f.accel.emplace_back(new ImuAccelMeasurementWithTimeOffset(
            model, kTk, kTk1, s.time, s.accel, o.accel_covariance, o.gravity, o.accel_model,
            o.mounting));
      }
    } else {
      f.gyro.emplace_back(
          new ImuGyroMeasurement(model, kTk, kTk1, s.time, s.gyro, o.gyro_covariance, o.mounting));
      if (o.accelerometer) {
        f.accel.emplace_back(new ImuAccelMeasurement(model, kTk, kTk1, s.time, s.accel,
                                                     o.accel_covariance, o.gravity, o.accel_model,
                                                     o.mounting));
      }
    }
  }
  return f;
}

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Residuals and ambient Jacobians of `cost` at `p` (all blocks requested).
void EvaluateAll(const ceres::CostFunction& cost, const std::vector<const double*>& p,
                 Eigen::VectorXd* r, std::vector<RowMatrix>* J) {
  const int m = cost.num_residuals();
  r->resize(m);
  J->clear();
  std::vector<double*> ptrs;
  for (int size : cost.parameter_block_sizes()) J->emplace_back(RowMatrix::Zero(m, size));
  for (RowMatrix& j : *J) ptrs.push_back(j.data());
  ASSERT_TRUE(cost.Evaluate(p.data(), r->data(), ptrs.data()));
}

double MaxAbs(const RowMatrix& a) { return a.cwiseAbs().maxCoeff(); }

// The configurations every test runs: model × accelerometer on/off × accelerometer model ×
// mounting × time offset held/estimated.
struct Case {
  SingerModel<6> model;
  ImuIntervalBatch::Options options;
};
std::vector<Case> Cases(std::mt19937& rng) {
  std::vector<Case> out;
  Mat3 A = Mat3::Random();
  const Mat3 cov = 1e-3 * (A * A.transpose() + Mat3::Identity());
  for (const SingerModel<6>& model : Models()) {
    for (int variant = 0; variant < 5; ++variant) {
      ImuIntervalBatch::Options o;
      o.gyro_covariance = 0.5 * cov;
      o.accel_covariance = cov;
      o.accelerometer = variant != 1;
      o.accel_model = variant == 2 ? AccelModel::kBodyCentric : AccelModel::kSpecificForce;
      if (variant == 3) o.mounting = Mounted(rng);
      o.estimate_time_offset = variant == 4;
      out.push_back({model, o});
    }
  }
  return out;
}

// Rows and Jacobians equal the stacked per-sample factors', each accelerometer sample corrected
// as Ceres corrects a one-sample block with a loss of ρ'' ≤ 0 (√ρ' on residual and Jacobian), and
// the last row closes the cost to Σ ½‖e_g‖² + ½ρ(‖e_a‖²).
TEST(ImuIntervalBatch, RowsEqualTheStackedPerSampleFactors) {
  std::mt19937 rng(11);
  const auto cauchy = std::make_shared<ceres::CauchyLoss>(1.0);
  for (const Case& c : Cases(rng)) {
    for (const bool with_loss : {false, true}) {
      for (int trial = 0; trial < 6; ++trial) {
        Params p{testing::JacobianCheckBlocks(rng, trial)};
        p.delta[0] = c.options.estimate_time_offset ? 0.004 : 0.0;
        std::vector<ImuIntervalBatch::Sample> samples = Samples(rng, 7);
        if (c.options.estimate_time_offset) {
          for (auto& s : samples) s.time -= 0.004;  // stamps whose τ = t + δ spans the interval
        }
        const ImuIntervalBatch batch(c.model, kTk, kTk1, samples, c.options,
                                     with_loss ? cauchy : nullptr);
        const PerSample single = PerSampleFactors(c.model, samples, c.options);
        const std::vector<const double*> params = p.Batch(batch);
        Eigen::VectorXd r;
        std::vector<RowMatrix> J;
        EvaluateAll(batch, params, &r, &J);
        if (!c.options.estimate_time_offset) {
          // Reading each sample's state from a shared interpolation (computed on demand here,
          // prepared by a window's callback in a solve): the same values to the bit.
          std::vector<std::shared_ptr<gp::SharedStateInterpolation>> states;
          for (const auto& s : samples) {
            states.push_back(
                std::make_shared<gp::SharedStateInterpolation>(c.model, kTk, kTk1, s.time));
          }
          const ImuIntervalBatch shared(c.model, kTk, kTk1, samples, states, c.options,
                                        with_loss ? cauchy : nullptr);
          Eigen::VectorXd r_shared;
          std::vector<RowMatrix> J_shared;
          EvaluateAll(shared, params, &r_shared, &J_shared);
          EXPECT_EQ(r_shared, r) << "trial " << trial;
          for (size_t b = 0; b < J.size(); ++b) EXPECT_EQ(J_shared[b], J[b]) << "block " << b;
        }
        const int per = c.options.accelerometer ? 6 : 3;
        ASSERT_EQ(r.size(), per * 7 + (with_loss && c.options.accelerometer ? 1 : 0));
        double cost = 0.0;
        for (size_t i = 0; i < samples.size(); ++i) {
          for (const bool is_accel : {false, true}) {
            if (is_accel && !c.options.accelerometer) continue;
            const ceres::CostFunction& f = is_accel ? *single.accel[i] : *single.gyro[i];
            std::vector<const double*> fp = is_accel ? p.blocks.Accel() : p.blocks.Gyro();
            if (c.options.estimate_time_offset) fp.push_back(p.delta);
            Eigen::VectorXd e;
            std::vector<RowMatrix> Je;
            EvaluateAll(f, fp, &e, &Je);
            double scale = 1.0;
            if (is_accel && with_loss) {
              double rho[3];
              cauchy->Evaluate(e.squaredNorm(), rho);
              scale = std::sqrt(rho[1]);
              cost += 0.5 * rho[0];
            } else {
              cost += 0.5 * e.squaredNorm();
            }
            const int row = per * static_cast<int>(i) + (is_accel ? 3 : 0);
            EXPECT_LE((r.segment<3>(row) - scale * e).norm(), 1e-9 * (1.0 + e.norm()))
                << "sample " << i << (is_accel ? " accel" : " gyro") << " trial " << trial;
            // The batch's blocks: the factor's, plus C_mi (zero on the gyro rows) before δ.
            for (size_t b = 0; b < J.size(); ++b) {
              RowMatrix expected = RowMatrix::Zero(3, J[b].cols());
              const bool gravity = static_cast<int>(b) == batch.gravity_block();
              const bool offset = static_cast<int>(b) == batch.offset_block();
              if (b < 8) expected = scale * Je[b];
              if (gravity && is_accel) expected = scale * Je[8];
              if (offset) expected = scale * Je.back();
              const RowMatrix got = J[b].middleRows(row, 3);
              EXPECT_LE(MaxAbs(got - expected), 1e-9 * (1.0 + MaxAbs(expected)))
                  << "block " << b << " sample " << i << (is_accel ? " accel" : " gyro")
                  << " trial " << trial;
            }
          }
        }
        EXPECT_NEAR(0.5 * r.squaredNorm(), cost, 1e-9 * (1.0 + cost)) << "trial " << trial;
      }
    }
  }
}

// In a ceres::Problem (manifolds, Ceres' own loss correction of the per-sample blocks): the same
// cost, gradient and Gauss–Newton Hessian JᵀJ as 2N per-sample blocks with the Cauchy loss.
TEST(ImuIntervalBatch, ProblemCostGradientAndHessianEqualThePerSampleBlocks) {
  std::mt19937 rng(12);
  for (const Case& c : Cases(rng)) {
    for (int trial = 0; trial < 6; ++trial) {
      Params p{testing::JacobianCheckBlocks(rng, trial)};
      const std::vector<ImuIntervalBatch::Sample> samples = Samples(rng, 9);
      auto* batch = new ImuIntervalBatch(c.model, kTk, kTk1, samples, c.options,
                                         std::make_shared<ceres::CauchyLoss>(1.0));
      const PerSample single = PerSampleFactors(c.model, samples, c.options);
      std::vector<double*> blocks;
      for (const double* b : p.Batch(*batch)) blocks.push_back(const_cast<double*>(b));
      ceres::Problem::Options po;
      po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
      po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
      po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
      ceres::Problem a(po), b(po);
      std::unique_ptr<ceres::CostFunction> owned(batch);
      b.AddResidualBlock(batch, nullptr, blocks);
      ceres::CauchyLoss cauchy(1.0);
      std::vector<double*> gyro_blocks(blocks.begin(), blocks.begin() + 8);
      if (batch->offset_block() >= 0) gyro_blocks.push_back(blocks.back());
      for (size_t i = 0; i < samples.size(); ++i) {
        a.AddResidualBlock(single.gyro[i].get(), nullptr, gyro_blocks);
        if (c.options.accelerometer) a.AddResidualBlock(single.accel[i].get(), &cauchy, blocks);
      }
      PoseManifold pose_manifold;
      RotationManifold rotation_manifold;
      for (ceres::Problem* problem : {&a, &b}) {
        problem->SetManifold(blocks[0], &pose_manifold);
        problem->SetManifold(blocks[3], &pose_manifold);
        if (batch->gravity_block() >= 0) problem->SetManifold(blocks[8], &rotation_manifold);
      }
      ceres::Problem::EvaluateOptions eo;
      eo.parameter_blocks = blocks;
      double cost_a, cost_b;
      std::vector<double> g_a, g_b;
      ceres::CRSMatrix crs_a, crs_b;
      ASSERT_TRUE(a.Evaluate(eo, &cost_a, nullptr, &g_a, &crs_a));
      ASSERT_TRUE(b.Evaluate(eo, &cost_b, nullptr, &g_b, &crs_b));
      EXPECT_NEAR(cost_a, cost_b, 1e-9 * (1.0 + cost_a)) << "trial " << trial;
      const auto dense = [](const ceres::CRSMatrix& m) {
        Eigen::MatrixXd d = Eigen::MatrixXd::Zero(m.num_rows, m.num_cols);
        for (int row = 0; row < m.num_rows; ++row) {
          for (int k = m.rows[row]; k < m.rows[row + 1]; ++k) d(row, m.cols[k]) = m.values[k];
        }
        return d;
      };
      const Eigen::MatrixXd Ja = dense(crs_a), Jb = dense(crs_b);
      const Eigen::MatrixXd Ha = Ja.transpose() * Ja, Hb = Jb.transpose() * Jb;
      const Eigen::Map<const Eigen::VectorXd> ga(g_a.data(), g_a.size()),
          gb(g_b.data(), g_b.size());
      EXPECT_LE((ga - gb).cwiseAbs().maxCoeff(), 1e-9 * (1.0 + ga.cwiseAbs().maxCoeff()))
          << "trial " << trial;
      EXPECT_LE((Ha - Hb).cwiseAbs().maxCoeff(), 1e-9 * (1.0 + Ha.cwiseAbs().maxCoeff()))
          << "trial " << trial;
    }
  }
}

// Without a loss the block is an ordinary cost function: every Jacobian against numeric
// differentiation, at generic (0, 1), near-π (2, 3) and near-identity (4, 5) knots.
TEST(ImuIntervalBatch, JacobiansMatchNumeric) {
  std::mt19937 rng(13);
  const testing::ImuManifolds manifolds;
  for (const Case& c : Cases(rng)) {
    for (int trial = 0; trial < 6; ++trial) {
      Params p{testing::JacobianCheckBlocks(rng, trial)};
      p.delta[0] = 2.0;  // ms (testing::DeltaInMilliseconds)
      std::vector<ImuIntervalBatch::Sample> samples = Samples(rng, 4);
      // Off the knots (the clamped ends have a kink in δ).
      for (auto& s : samples) s.time = kTk + 0.005 + 0.9 * (s.time - kTk);
      const ImuIntervalBatch batch(c.model, kTk, kTk1, samples, c.options);
      const testing::DeltaInMilliseconds batch_ms(batch);
      const ceres::CostFunction& checked = c.options.estimate_time_offset
                                               ? static_cast<const ceres::CostFunction&>(batch_ms)
                                               : batch;
      // Absolute floor 1e-9: the measurements here are large (|f_m| up to 12·√3 m/s², whitened
      // by σ ≈ 0.03), and the differencing noise with them.
      EXPECT_TRUE(testing::JacobiansMatchNumeric(checked, BatchManifolds(manifolds, batch),
                                                 p.Batch(batch), 1e-6, 1e-9))
          << "trial " << trial << " accelerometer " << c.options.accelerometer << " offset "
          << c.options.estimate_time_offset;
    }
  }
}

// The χ² of the consistency check: without the loss, per sensor.
TEST(ImuIntervalBatch, ChiSquareIsTheUnrobustifiedSumPerSensor) {
  std::mt19937 rng(14);
  for (const Case& c : Cases(rng)) {
    Params p{testing::JacobianCheckBlocks(rng, 0)};
    const std::vector<ImuIntervalBatch::Sample> samples = Samples(rng, 5);
    const ImuIntervalBatch batch(c.model, kTk, kTk1, samples, c.options,
                                 std::make_shared<ceres::CauchyLoss>(1.0));
    const ImuIntervalBatch plain(c.model, kTk, kTk1, samples, c.options);
    double accel = 0.0, gyro = 0.0;
    ASSERT_TRUE(batch.ChiSquare(p.Batch(batch).data(), &accel, &gyro));
    Eigen::VectorXd r(plain.num_residuals());
    ASSERT_TRUE(plain.Evaluate(p.Batch(plain).data(), r.data(), nullptr));
    double want_accel = 0.0, want_gyro = 0.0;
    const int per = c.options.accelerometer ? 6 : 3;
    for (int i = 0; i < 5; ++i) {
      want_gyro += r.segment<3>(per * i).squaredNorm();
      if (c.options.accelerometer) want_accel += r.segment<3>(per * i + 3).squaredNorm();
    }
    EXPECT_NEAR(gyro, want_gyro, 1e-9 * want_gyro);
    EXPECT_NEAR(accel, want_accel, 1e-9 * (1.0 + want_accel));
    if (c.options.accelerometer) EXPECT_GT(accel, 5 * 3.0);  // the outliers the loss would cap
  }
}

TEST(ImuIntervalBatch, RejectsBadArguments) {
  const ImuIntervalBatch::Options o;
  EXPECT_THROW(ImuIntervalBatch(testing::Wnoj(), kTk, kTk1, {}, o), std::invalid_argument);
  EXPECT_THROW(ImuIntervalBatch(testing::Wnoj(), kTk, kTk1, {{0.5, Vec3::Zero(), Vec3::Zero()}}, o),
               std::invalid_argument);
  EXPECT_ANY_THROW(
      ImuIntervalBatch(testing::Wnoj(), kTk, kTk, {{kTk, Vec3::Zero(), Vec3::Zero()}}, o));
  // A convex loss (ρ'' > 0; Ceres' TolerantLoss has it below s ≈ a + 36.7b) has no exact
  // constant row: the evaluation fails instead of lying.
  std::mt19937 rng(15);
  Params p{testing::JacobianCheckBlocks(rng, 0)};
  const ImuIntervalBatch tolerant(testing::Wnoj(), kTk, kTk1, Samples(rng, 3), o,
                                  std::make_shared<ceres::TolerantLoss>(1e6, 1e6));
  Eigen::VectorXd r(tolerant.num_residuals());
  EXPECT_FALSE(tolerant.Evaluate(p.Batch(tolerant).data(), r.data(), nullptr));
}

}  // namespace
}  // namespace ctlio::imu
