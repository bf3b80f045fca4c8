// Plausibility gates on the odometry's input (solvers/lio/input_checks.h) and how the runner
// applies them: physically impossible IMU samples, a frozen IMU while the lidar moves, an
// accelerometer in the wrong units, points timed before the previous scan, no ATE without an
// estimate, unbounded iteration counts, the `input:` config section.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <functional>

#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/input_checks.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

using ::testing::HasSubstr;

TEST(InputChecks, ImuRangeAndGravityMagnitude) {
  InputCheckOptions o;
  ImuSample s;
  s.accel = Vec3(0, 0, 9.81);
  s.gyro = Vec3(0.1, 0, 0);
  EXPECT_FALSE(CheckImuRange(s, o));
  s.gyro.x() = 1e30;
  ASSERT_TRUE(CheckImuRange(s, o));
  EXPECT_THAT(*CheckImuRange(s, o), HasSubstr("max_gyro"));
  s.gyro.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(CheckImuRange(s, o));
  s.gyro.x() = 0;
  s.accel.z() = 200;
  EXPECT_THAT(*CheckImuRange(s, o), HasSubstr("max_accel"));

  std::vector<ImuSample> still(20);
  for (auto& x : still) x.accel = Vec3(0.1, -0.2, 9.8);
  EXPECT_FALSE(CheckGravityMagnitude(still, 9.81, 0.2));
  for (auto& x : still) x.accel /= 9.81;  // accelerometer in g
  ASSERT_TRUE(CheckGravityMagnitude(still, 9.81, 0.2));
  EXPECT_THAT(*CheckGravityMagnitude(still, 9.81, 0.2), HasSubstr("units"));
  EXPECT_TRUE(CheckGravityMagnitude({}, 9.81, 0.2));
}

TEST(InputChecks, ConstantImuScanTimesAndLimits) {
  ConstantImuDetector d;
  ImuSample s;
  for (int i = 0; i <= 100; ++i) {
    s.t_ns = i * 5'000'000;
    d.Add(s);
  }
  EXPECT_NEAR(d.ConstantSeconds(), 0.5, 1e-12);
  s.t_ns += 5'000'000;
  s.gyro.x() = 1e-6;  // any change restarts the run
  d.Add(s);
  EXPECT_EQ(d.ConstantSeconds(), 0.0);

  LidarScan scan;
  scan.points = {Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0)};
  scan.times_ns = {100, 995, 2000};
  EXPECT_EQ(DropPointsBefore(1000, 10, &scan), 1u);
  EXPECT_EQ(scan.times_ns, (std::vector<int64_t>{995, 2000}));
  EXPECT_EQ(scan.points[0].x(), 2.0);

  InputCheckOptions o;
  EXPECT_FALSE(PoseMoved(SE3(), SE3(Mat3::Identity(), Vec3(0.01, 0, 0)), o));
  EXPECT_TRUE(PoseMoved(SE3(), SE3(Mat3::Identity(), Vec3(0.1, 0, 0)), o));

  OdometryConfig c;
  c.frontend.max_iterations = 1'000'000;
  EXPECT_THROW(ValidateIterationLimits(c), std::invalid_argument);
}

TEST(InputChecks, ConfigSectionIsReadAndRemoved) {
  YAML::Node root =
      YAML::Load("method: singer_lio\ninput:\n  max_gyro: 20\n  max_imu_gap_error: 0.1\n");
  const InputCheckOptions o = TakeInputCheckOptions(&root, "c.yaml");
  EXPECT_EQ(o.max_gyro, 20.0);
  EXPECT_EQ(o.max_imu_gap_error, 0.1);
  EXPECT_FALSE(root["input"]);
  EXPECT_NO_THROW(OdometryConfigFromYaml(root, "c.yaml"));
  YAML::Node bad = YAML::Load("input:\n  max_gyro: -1\n");
  EXPECT_THROW(TakeInputCheckOptions(&bad, "c.yaml"), std::runtime_error);
  YAML::Node unknown = YAML::Load("input:\n  max_gyr: 1\n");
  try {
    TakeInputCheckOptions(&unknown, "c.yaml");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("c.yaml:2"));
    EXPECT_THAT(e.what(), HasSubstr("input.max_gyr"));
  }
}

// The simulator with its IMU samples edited on the way.
class EditedImuSource : public io::DataSource {
 public:
  EditedImuSource(const sim::SimConfig& c, std::function<void(io::ImuSample*)> edit)
      : sim_(c), edit_(std::move(edit)) {}
  std::string Name() const override { return "edited:" + sim_.Name(); }
  size_t NumScans() const override { return sim_.NumScans(); }
  bool Next(io::ScanFrame* f) override {
    if (!sim_.Next(f)) return false;
    for (auto& s : f->imu) edit_(&s);
    return true;
  }
  SE3 ImuFromLidar() const override { return sim_.ImuFromLidar(); }
  std::optional<std::vector<io::StampedPose>> GroundTruth() const override {
    return sim_.GroundTruth();
  }
  std::optional<double> Gravity() const override { return sim_.Gravity(); }

 private:
  sim::SimulatedSource sim_;
  std::function<void(io::ImuSample*)> edit_;
};

sim::SimConfig Tiny() {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 0);
  c.duration_s = 1.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  return c;
}

OdometryConfig Config() {
  return LoadOdometryConfig(std::string(CTLIO_SOURCE_DIR) + "/data/sim_lio.yaml");
}

TEST(InputGates, ImpossibleGyroSampleIsRejectedAndCounted) {
  int n = 0;
  EditedImuSource source(Tiny(), [&](io::ImuSample* s) {
    if (++n == 100) s->gyro.x() = 1e30;
  });
  const lioapp::RunSummary run = lioapp::RunOdometry(source, Config());
  EXPECT_EQ(run.imu_rejected, 1);
  EXPECT_THAT(run.first_input_warning, HasSubstr("max_gyro"));
  ASSERT_TRUE(run.ate);
  EXPECT_LT(run.ate->rmse, 0.06);  // the same bound as the unedited sequence
}

TEST(InputGates, FrozenImuWhileTheLidarMovesIsAFailureNotOk) {
  io::ImuSample frozen;
  bool have = false;
  EditedImuSource source(Tiny(), [&](io::ImuSample* s) {
    if (s->t_ns > 300'000'000) {  // after the still start (gravity initialised)
      if (!have) frozen = *s, have = true;
      const int64_t t = s->t_ns;
      *s = frozen;
      s->t_ns = t;
    }
  });
  const lioapp::RunSummary run = lioapp::RunOdometry(source, Config());
  EXPECT_GT(run.constant_imu_scans, 0);
  EXPECT_TRUE(run.failure);
  EXPECT_THAT(run.first_input_warning, HasSubstr("constant"));
  size_t suspect = 0;
  for (bool b : run.suspect) suspect += b;
  EXPECT_EQ(suspect, size_t(run.constant_imu_scans));
}

TEST(InputGates, AccelerometerInGIsRejectedAtInitialisation) {
  EditedImuSource source(Tiny(), [](io::ImuSample* s) { s->accel /= 9.81; });
  try {
    lioapp::RunOdometry(source, Config());
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("units"));
  }
  // The gyro in deg/s: the run fails, and a run without estimates has no ATE (not 0.0000).
  EditedImuSource deg(Tiny(), [](io::ImuSample* s) { s->gyro *= 180.0 / M_PI; });
  const lioapp::RunSummary run = lioapp::RunOdometry(deg, Config());
  EXPECT_TRUE(run.failure);
  if (run.trajectory.size() < 3) EXPECT_FALSE(run.ate);
}

}  // namespace
}  // namespace ctlio::lio
