// Uses the installed ctlio package from another project (run_consumer.cmake): a pose fitted on
// the PoseManifold, the Singer prior and the IMU measurements evaluated on a motion they must
// explain exactly, and a ROS 1 bag written and opened with io::OpenDataset. Argument: a folder for
// the bag. Exits non-zero on the first failed check, saying which.
#include <ceres/ceres.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ctlio/factors/gp/singer_prior.h"
#include "ctlio/factors/imu/imu_measurement.h"
#include "ctlio/io/dataset.h"
#include "ctlio/io/ros2_bag.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/manifolds/pose_manifold.h"

namespace {

int failures = 0;
void Check(bool ok, const char* what, double value) {
  std::printf("consumer: %-58s %.3e %s\n", what, value, ok ? "ok" : "FAILED");
  if (!ok) ++failures;
}

// r = Log(T · T_target⁻¹), analytic Jacobian 𝒥⁻¹(r) lifted to the ambient block.
class PoseError final : public ceres::SizedCostFunction<6, 7> {
 public:
  explicit PoseError(const ctlio::SE3& target) : target_inverse_(target.Inverse()) {}
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const ctlio::Vec6 r = (ctlio::PoseManifold::Pose(p[0]) * target_inverse_).Log();
    Eigen::Map<ctlio::Vec6>{residuals} = r;
    if (jacobians && jacobians[0]) {
      ctlio::LiftPoseJacobian<6>(ctlio::se3::LeftJacobianInverse(r), p[0], jacobians[0]);
    }
    return true;
  }

 private:
  ctlio::SE3 target_inverse_;
};

void FitPose() {
  ctlio::Vec6 xi;
  xi << 1.0, -2.0, 0.5, 0.3, -0.2, 2.5;
  const ctlio::SE3 target = ctlio::SE3::Exp(xi);
  double x[7] = {0, 0, 0, 0, 0, 0, 1};
  ceres::Problem problem;
  problem.AddResidualBlock(new PoseError(target), nullptr, x);
  problem.SetManifold(x, new ctlio::PoseManifold);
  ceres::Solver::Options options;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  const double err = (ctlio::PoseManifold::Pose(x) * target.Inverse()).Log().norm();
  Check(err < 1e-9, "pose error after the solve", err);
}

// Two knots 0.1 s apart on a constant body twist (T(t) = Exp(ϖt)·T₀, ϖ̇ = 0): the Singer prior's
// error is zero (SPEC §2: γ₁ = Φγ₀ on this motion), and so are the gyro and the exact
// accelerometer residual at any time between the knots (SPEC §3, f = ϖ_ω×ϖ_v − C_rm g).
void EvaluateFactors() {
  using ctlio::Mat3;
  using ctlio::Vec3;
  using ctlio::Vec6;
  ctlio::Vec6 qc, alpha, w;
  qc << 50, 50, 50, 10, 10, 10;
  alpha << 1, 1, 1, 1, 1, 1;
  w << -1.0, 0.3, -0.1, -0.2, 0.4, -0.8;  // ϖ = −[v; ω]
  const ctlio::gp::SingerModel<6> model(qc, alpha);
  const double dt = 0.1, tau = 0.037;
  const ctlio::SE3 T0 = ctlio::SE3::Exp((Vec6() << 0.5, -1, 2, 0.1, 0.2, -0.3).finished());
  double pose0[7], pose1[7], zero[6] = {0, 0, 0, 0, 0, 0}, C_mi[4] = {0, 0, 0, 1};
  ctlio::PoseManifold::Store(T0, pose0);
  ctlio::PoseManifold::Store(ctlio::SE3::Exp(w * dt) * T0, pose1);
  const double* knots[9] = {pose0, w.data(), zero, pose1, w.data(), zero, zero, zero, C_mi};

  const ctlio::gp::SingerPrior prior(model, dt);
  Eigen::Matrix<double, 18, 1> r18;
  prior.Evaluate(knots, r18.data(), nullptr);
  Check(r18.norm() < 1e-9, "Singer prior on a constant twist", r18.norm());
  double moved[7];
  ctlio::PoseManifold::Store(ctlio::SE3::Exp(w * 1.1 * dt) * T0, moved);
  const double* off[6] = {pose0, w.data(), zero, moved, w.data(), zero};
  prior.Evaluate(off, r18.data(), nullptr);
  Check(r18.norm() > 1.0, "Singer prior with the second knot moved", r18.norm());

  const Mat3 cov = 1e-4 * Mat3::Identity();
  const Vec3 gyro = -w.tail<3>();
  Vec3 r;
  ctlio::imu::ImuGyroMeasurement(model, 0.0, dt, tau, gyro, cov).Evaluate(knots, r.data(), nullptr);
  Check(r.norm() < 1e-9, "gyro measurement on that motion", r.norm());
  const Mat3 C_rm = (ctlio::SE3::Exp(w * tau) * T0).rotation();
  const Vec3 f = w.tail<3>().cross(w.head<3>()) - C_rm * Vec3(0, 0, -9.81);
  // The library's default model is the exact specific force; the paper's misses ω×v.
  ctlio::imu::ImuAccelMeasurement(model, 0.0, dt, tau, f, cov).Evaluate(knots, r.data(), nullptr);
  Check(r.norm() < 1e-8, "accelerometer measurement (default model)", r.norm());
  ctlio::imu::ImuAccelMeasurement(model, 0.0, dt, tau, f, cov, 9.81,
                                  ctlio::imu::AccelModel::kBodyCentric)
      .Evaluate(knots, r.data(), nullptr);
  Check(r.norm() > 1.0, "accelerometer measurement (the paper's model)", r.norm());
}

// Three 0.1 s scans of 50 timed points and 200 Hz IMU samples, in memory.
class TinySource final : public ctlio::io::DataSource {
 public:
  TinySource() {
    for (int64_t t = kStart; t <= kStart + 3 * kScan; t += kScan / 20) {
      ctlio::io::ImuSample s;
      s.t_ns = t;
      s.gyro = ctlio::Vec3(0.01, -0.02, 0.3);
      s.accel = ctlio::Vec3(0.1, 0.2, 9.81);
      imu_.push_back(s);
    }
  }
  std::string Name() const override { return "tiny"; }
  size_t NumScans() const override { return 3; }
  bool Next(ctlio::io::ScanFrame* frame) override {
    if (next_ == 3) return false;
    const int64_t start = kStart + static_cast<int64_t>(next_) * kScan;
    *frame = ctlio::io::ScanFrame();
    frame->index = next_;
    frame->start_ns = start;
    frame->cloud.stamp_ns = start;
    for (int i = 0; i < 50; ++i) {
      const double a = 0.125 * i;
      frame->cloud.points.emplace_back(5 * std::cos(a), 5 * std::sin(a), 0.1 * (i % 5));
      frame->cloud.times_ns.push_back(start + i * (kScan / 50));
    }
    frame->end_ns = frame->cloud.times_ns.back();
    ctlio::io::TakeImuUntil(imu_, frame->end_ns, &cursor_, &frame->imu);
    ++next_;
    return true;
  }
  ctlio::SE3 ImuFromLidar() const override { return ctlio::SE3(); }

 private:
  static constexpr int64_t kStart = 1'600'000'000'000'000'000;
  static constexpr int64_t kScan = 100'000'000;
  std::vector<ctlio::io::ImuSample> imu_;
  size_t next_ = 0, cursor_ = 0;
};

void OpenBag(const std::string& folder) {
  const std::string bag = folder + "/tiny.bag";
  TinySource written;
  const size_t n = ctlio::io::WriteRosbag(written, bag);
  Check(n == 3, "scans written to the bag", static_cast<double>(n));
  try {
    const std::unique_ptr<ctlio::io::DataSource> read = ctlio::io::OpenDataset(bag);
    Check(read->Name() == "rosbag:" + bag, "OpenDataset opened it as a bag", 0.0);
    size_t scans = 0, points = 0, samples = 0;
    ctlio::io::ScanFrame frame;
    while (read->Next(&frame)) {
      ++scans;
      points += frame.cloud.size();
      samples += frame.imu.size();
    }
    Check(scans == 3 && points == 150, "scans and points read back", static_cast<double>(points));
    Check(samples > 0, "IMU samples read back", static_cast<double>(samples));
  } catch (const std::exception& e) {
    std::printf("consumer: OpenDataset(%s) failed: %s\n", bag.c_str(), e.what());
    ++failures;
  }
}

// ctlio::io_ros2 (and its zstd, lz4 and sqlite3 libraries): a zstd MCAP bag and an SQLite bag
// written and read back.
void RoundTripRos2Bags(const std::string& folder) {
  using namespace ctlio::io::ros2;
  for (const Ros2Storage storage : {Ros2Storage::kMcap, Ros2Storage::kSqlite3}) {
    const bool mcap = storage == Ros2Storage::kMcap;
    const std::string bag = folder + (mcap ? "/ros2_mcap" : "/ros2_sqlite");
    try {
      {
        Ros2BagWriter writer(bag, storage, mcap ? Ros2Compression::kZstd : Ros2Compression::kNone);
        const size_t imu = writer.AddTopic("/imu", "sensor_msgs/msg/Imu");
        writer.Write(imu, 2000, {4, 5, 6});
        writer.Write(imu, 1000, {1, 2, 3});
      }
      Ros2BagReader reader(bag);
      Ros2Message m;
      const bool first = reader.Next(&m) && m.log_time_ns == 1000 && m.data[0] == 1;
      const bool second = reader.Next(&m) && m.log_time_ns == 2000 && m.data[2] == 6;
      Check(first && second && !reader.Next(&m),
            mcap ? "ROS 2 MCAP bag read back in time order" : "ROS 2 SQLite bag read back", 0.0);
    } catch (const std::exception& e) {
      std::printf("consumer: ROS 2 bag %s failed: %s\n", bag.c_str(), e.what());
      ++failures;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer <folder for the bag>\n");
    return 2;
  }
  FitPose();
  EvaluateFactors();
  OpenBag(argv[1]);
  RoundTripRos2Bags(argv[1]);
  return failures == 0 ? 0 : 1;
}
