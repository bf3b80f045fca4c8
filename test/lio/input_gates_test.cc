// Plausibility gates on the odometry's input (solvers/lio/input_checks.h), applied by LioOdometry
// itself: physically impossible IMU samples, a frozen IMU while the lidar moves, an accelerometer
// in the wrong units, points timed outside their scan's interval, unbounded iteration counts, the
// `input:` config section — each shown to fire through LioOdometry, and good data shown untouched.
// The runner (RunOdometry) only totals and reports what the odometry found.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <functional>

#include "common/sim_lio.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/input_checks.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "lio/run_odometry.h"

namespace ctlio::lio {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

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
  ASSERT_TRUE(CheckImuRange(s, o));
  EXPECT_THAT(*CheckImuRange(s, o), HasSubstr("not finite"));
  s.gyro.x() = 0;
  s.accel.z() = 200;
  EXPECT_THAT(*CheckImuRange(s, o), HasSubstr("max_accel"));

  std::vector<ImuSample> still(20);
  for (auto& x : still) x.accel = Vec3(0.1, -0.2, 9.8);
  EXPECT_FALSE(CheckGravityMagnitude(still, 9.81, 0.2));
  for (auto& x : still) x.accel /= 9.81;  // accelerometer in g
  ASSERT_TRUE(CheckGravityMagnitude(still, 9.81, 0.2));
  EXPECT_THAT(*CheckGravityMagnitude(still, 9.81, 0.2), HasSubstr("units"));
  EXPECT_THAT(*CheckGravityMagnitude(still, 9.81, 0.2), HasSubstr("g, not m/s²"));
  EXPECT_TRUE(CheckGravityMagnitude({}, 9.81, 0.2));
  // Issue 40: any other magnitude (19.5 m/s²: a window in motion, as when overlapping scan times
  // put it there) names the motion first, not only the units.
  for (auto& x : still) x.accel = Vec3(0.1, -0.2, 19.5);
  ASSERT_TRUE(CheckGravityMagnitude(still, 9.81, 0.2));
  EXPECT_THAT(*CheckGravityMagnitude(still, 9.81, 0.2),
              HasSubstr("the platform accelerates in the window"));
  EXPECT_THAT(*CheckGravityMagnitude(still, 9.81, 0.2), Not(HasSubstr("g, not m/s²")));
}

TEST(InputChecks, ConstantImuScanTimesAndMotion) {
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
  scan.points = {Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0), Vec3(4, 0, 0)};
  scan.times_ns = {100, 995, 2000, 2011};
  EXPECT_EQ(DropPointsOutside(990, 2010, &scan), 2u);
  EXPECT_EQ(scan.times_ns, (std::vector<int64_t>{995, 2000}));
  EXPECT_EQ(scan.points[0].x(), 2.0);

  InputCheckOptions o;
  EXPECT_FALSE(PoseMoved(SE3(), SE3(Mat3::Identity(), Vec3(0.01, 0, 0)), o));
  EXPECT_TRUE(PoseMoved(SE3(), SE3(Mat3::Identity(), Vec3(0.1, 0, 0)), o));
}

// Iteration limits are part of the options' Validate(): every config that reaches LioOdometry is
// checked, however it was made.
TEST(InputChecks, IterationLimitsAreCheckedByEveryConfig) {
  OdometryConfig c;
  c.frontend.max_iterations = 1'000'000;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  EXPECT_THROW(LioOdometry{c}, std::invalid_argument);
  c.frontend.max_iterations = 100;
  c.frontend.solver_iterations = 1001;
  EXPECT_THROW(LioOdometry{c}, std::invalid_argument);
  c.frontend.solver_iterations = 1000;
  EXPECT_NO_THROW(c.Validate());
  c.input.max_gyro = -1;
  EXPECT_THROW(LioOdometry{c}, std::invalid_argument);
}

TEST(InputChecks, ConfigSectionIsPartOfTheOdometryConfig) {
  const OdometryConfig c = OdometryConfigFromYaml(
      YAML::Load("method: singer_lio\ninput:\n  max_gyro: 20\n  max_imu_gap_error: 0.1\n"
                 "per_method:\n  imu_input: {window: {knots: 3}}\n"),
      "c.yaml");
  EXPECT_EQ(c.input.max_gyro, 20.0);
  EXPECT_EQ(c.input.max_imu_gap_error, 0.1);
  EXPECT_EQ(c.ForMethod(LioMethod::kImuInput).input.max_gyro, 20.0);  // the data's, every method
  EXPECT_EQ(c.input.max_accel, InputCheckOptions().max_accel);
  auto error = [](const std::string& yaml) {
    try {
      OdometryConfigFromYaml(YAML::Load(yaml), "c.yaml");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error("input:\n  max_gyro: -1\n"), HasSubstr("max_gyro"));
  EXPECT_THAT(error("input:\n  max_gyro: fast\n"), HasSubstr("c.yaml:2"));
  EXPECT_THAT(error("input:\n  max_gyr: 1\n"), HasSubstr("c.yaml:2"));
  EXPECT_THAT(error("input:\n  max_gyr: 1\n"), HasSubstr("input.max_gyr"));
  EXPECT_THAT(error("lidar_frontend:\n  max_iterations: 101\n"), HasSubstr("max_iterations"));
  EXPECT_THAT(error("per_method:\n  imu_input:\n    input: {max_gyro: 1}\n"),
              HasSubstr("cannot be set per method"));
}

sim::SimConfig Tiny(double duration_s = 1.0) {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 0);
  c.duration_s = duration_s;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 8;
  return c;
}

OdometryConfig Config() { return testing::SimLioConfig(); }

// The simulator (Tiny, `duration_s`) fed straight into LioOdometry (no runner), with the IMU
// samples and the scans edited on the way; edit_scan gets the scan's index and the previous
// scan's end.
std::vector<ScanResult> RunLibrary(
    OdometryConfig config, double duration_s, const std::function<void(ImuSample*)>& edit_imu = {},
    const std::function<void(size_t, int64_t, LidarScan*)>& edit_scan = {}) {
  sim::SimulatedSource source(Tiny(duration_s));
  config.T_imu_lidar = source.ImuFromLidar();
  if (const auto g = source.Gravity()) config.gravity = *g;
  LioOdometry odometry(config);
  std::vector<ScanResult> results;
  int64_t previous_end = 0;
  io::ScanFrame f;
  while (source.Next(&f)) {
    for (ImuSample s : f.imu) {
      if (edit_imu) edit_imu(&s);
      odometry.AddImu(s);
    }
    LidarScan scan = lioapp::TakeLidarScan(&f);
    if (edit_scan) edit_scan(results.size(), previous_end, &scan);
    previous_end = scan.end_ns;
    results.push_back(odometry.AddScan(scan));
  }
  return results;
}

void ExpectSamePoses(const std::vector<ScanResult>& a, const std::vector<ScanResult>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].status, b[i].status) << "scan " << i;
    EXPECT_TRUE(a[i].T_mr.Matrix() == b[i].T_mr.Matrix()) << "scan " << i;
  }
}

// Good data pass every gate untouched: nothing rejected, dropped or suspected, no note, and the
// estimates equal bit for bit those with gates that cannot fire.
TEST(InputGates, GoodDataIsUntouched) {
  OdometryConfig open = Config();
  open.input.max_gyro = open.input.max_accel = 1e300;
  open.input.gravity_tolerance = 0.999;
  open.input.constant_imu_duration = 1e300;
  open.input.scan_time_tolerance = 999;
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput}) {
    OdometryConfig gated = Config(), loose = open;
    gated.method = loose.method = m;
    const std::vector<ScanResult> results = RunLibrary(gated, 0.6);
    ASSERT_EQ(results.size(), 6u);
    for (const ScanResult& r : results) {
      EXPECT_EQ(r.imu_rejected, 0);
      EXPECT_EQ(r.points_dropped, 0);
      EXPECT_TRUE(r.status == ScanStatus::kOk || r.status == ScanStatus::kInitialising)
          << ScanStatusName(r.status) << ": " << r.message;
      EXPECT_EQ(r.message, "");
    }
    ExpectSamePoses(results, RunLibrary(loose, 0.6));
  }
}

TEST(InputGates, ImpossibleGyroSampleIsRejectedAndReported) {
  const std::vector<ScanResult> good = RunLibrary(Config(), 0.6);
  int n = 0;
  const std::vector<ScanResult> results = RunLibrary(Config(), 0.6, [&](ImuSample* s) {
    if (++n == 100) s->gyro.x() = 1e30;
  });
  int rejected = 0;
  for (size_t i = 0; i < results.size(); ++i) {
    rejected += results[i].imu_rejected;
    if (results[i].imu_rejected > 0) {
      EXPECT_THAT(results[i].message, HasSubstr("input.max_gyro"));
      EXPECT_THAT(results[i].message, HasSubstr("rejected"));
    }
    EXPECT_NE(results[i].status, ScanStatus::kFailed) << results[i].message;
    // The hole of one sample is bridged by the previous one: the estimate stays within half the
    // sequence's ATE bound (6 cm) of the unedited run (measured: 1.5 cm on these sparse scans).
    EXPECT_LT((results[i].T_mr.translation() - good[i].T_mr.translation()).norm(), 0.03);
  }
  EXPECT_EQ(rejected, 1);
}

TEST(InputGates, FrozenImuWhileTheLidarMovesIsSuspect) {
  // From 0.3 s (after the still start that initialises gravity) the IMU repeats one sample.
  ImuSample frozen;
  bool have = false;
  const auto freeze = [&](ImuSample* s) {
    if (s->t_ns > Tiny().start_ns + 300'000'000) {
      if (!have) frozen = *s, have = true;
      const int64_t t = s->t_ns;
      *s = frozen;
      s->t_ns = t;
    }
  };
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput, LioMethod::kLidarOnly}) {
    OdometryConfig c = Config();
    c.method = m;
    have = false;
    const std::vector<ScanResult> results = RunLibrary(c, 1.0, freeze);
    int suspect = 0;
    for (const ScanResult& r : results) {
      if (r.status != ScanStatus::kSuspect) continue;
      ++suspect;
      EXPECT_THAT(r.message, HasSubstr("IMU output constant"));
    }
    if (m == LioMethod::kLidarOnly) {
      EXPECT_EQ(suspect, 0);  // no IMU in the estimate: nothing to suspect
    } else {
      EXPECT_GT(suspect, 0) << LioMethodName(m);
    }
  }
}

TEST(InputGates, AccelerometerInGFailsInitialisationNamingTheUnits) {
  for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput}) {
    OdometryConfig c = Config();
    c.method = m;
    const std::vector<ScanResult> results =
        RunLibrary(c, 0.6, [](ImuSample* s) { s->accel /= 9.81; });
    for (const ScanResult& r : results) {
      EXPECT_EQ(r.status, ScanStatus::kFailed);
      EXPECT_THAT(r.message, HasSubstr("units"));
    }
  }
}

TEST(InputGates, PointsOutsideTheScanIntervalAreDroppedAndCounted) {
  const std::vector<ScanResult> good = RunLibrary(Config(), 0.6);
  // 50 copies of points 50 ms before the previous scan's end and 30 ms after this scan's end:
  // beyond the 10 ms tolerance, dropped before anything sees them (estimates bit-identical).
  const auto far = [](size_t i, int64_t previous_end, LidarScan* s) {
    if (i == 0) return;
    for (int k = 0; k < 50; ++k) {
      s->points.push_back(s->points[k]);
      s->times_ns.push_back(previous_end - 50'000'000);
    }
    for (int k = 0; k < 30; ++k) {
      s->points.push_back(s->points[k]);
      s->times_ns.push_back(s->end_ns + 30'000'000);
    }
  };
  const std::vector<ScanResult> results = RunLibrary(Config(), 0.6, {}, far);
  for (size_t i = 1; i < results.size(); ++i) {
    EXPECT_EQ(results[i].points_dropped, 80) << "scan " << i;
    EXPECT_THAT(results[i].message, HasSubstr("input.scan_time_tolerance"));
  }
  ExpectSamePoses(results, good);
  // Within the tolerance (driver jitter) the points are kept and clamped onto the interval.
  const auto jitter = [](size_t i, int64_t previous_end, LidarScan* s) {
    if (i == 0) return;
    s->times_ns[0] = previous_end - 5'000'000;
  };
  for (const ScanResult& r : RunLibrary(Config(), 0.6, {}, jitter)) {
    EXPECT_EQ(r.points_dropped, 0);
  }
}

// The simulator with its IMU samples edited on the way, for the runner's report.
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

TEST(InputGates, RunnerTotalsWhatTheOdometryFound) {
  int n = 0;
  EditedImuSource source(Tiny(), [&](io::ImuSample* s) {
    if (++n == 100) s->gyro.x() = 1e30;
  });
  const lioapp::RunSummary run = lioapp::RunOdometry(source, Config());
  EXPECT_EQ(run.imu_rejected, 1);
  EXPECT_THAT(run.first_input_warning, HasSubstr("max_gyro"));
  ASSERT_TRUE(run.ate);
  EXPECT_LT(run.ate->rmse, 0.06);  // the same bound as the unedited sequence
  EXPECT_FALSE(run.failure);

  io::ImuSample frozen;
  bool have = false;
  EditedImuSource still(Tiny(), [&](io::ImuSample* s) {
    if (s->t_ns > Tiny().start_ns + 300'000'000) {
      if (!have) frozen = *s, have = true;
      const int64_t t = s->t_ns;
      *s = frozen;
      s->t_ns = t;
    }
  });
  const lioapp::RunSummary frozen_run = lioapp::RunOdometry(still, Config());
  EXPECT_GT(frozen_run.constant_imu_scans, 0);
  EXPECT_TRUE(frozen_run.failure);  // never "ok"
  EXPECT_THAT(frozen_run.first_input_warning, HasSubstr("constant"));
}

TEST(InputGates, RunWithoutEstimatesFailsWithoutAte) {
  EditedImuSource g(Tiny(), [](io::ImuSample* s) { s->accel /= 9.81; });
  const lioapp::RunSummary run = lioapp::RunOdometry(g, Config());
  EXPECT_TRUE(run.failure);
  EXPECT_THAT(run.first_failure, HasSubstr("units"));
  EXPECT_FALSE(run.ate);  // no estimate, no ATE (not 0.0000)
  // The gyro in deg/s: the run fails, and a run without estimates has no ATE.
  EditedImuSource deg(Tiny(), [](io::ImuSample* s) { s->gyro *= 180.0 / M_PI; });
  const lioapp::RunSummary deg_run = lioapp::RunOdometry(deg, Config());
  EXPECT_TRUE(deg_run.failure);
  if (deg_run.trajectory.size() < 3) EXPECT_FALSE(deg_run.ate);
}

// Issue 40: too few IMU samples for the gravity initialisation is named as a rate (or a late
// start), not as "accelerometer units or axes" or a platform that is not still.
TEST(InputGates, TooFewImuSamplesForGravityNameTheRateNotTheUnits) {
  struct Case {
    double rate_hz, clock_offset_s;
    std::string expected;
  };
  for (const Case& k :
       {Case{20.0, 0.0, "the IMU rate (about 20 Hz) is too low"},
        Case{10.0, 0.0, "the IMU rate is too low (a single sample"},
        Case{200.0, 0.08, "the IMU starts only 0.0196 s before the first scan end"}}) {
    for (const LioMethod m : {LioMethod::kSingerLio, LioMethod::kImuInput}) {
      SCOPED_TRACE(k.expected);
      sim::SimConfig sc = Tiny(0.5);
      sc.imu.rate_hz = k.rate_hz;
      sc.imu.clock_offset_s = k.clock_offset_s;
      sim::SimulatedSource source(sc);
      OdometryConfig c = Config();
      c.method = m;
      c.T_imu_lidar = source.ImuFromLidar();
      LioOdometry odometry(c);
      io::ScanFrame f;
      ASSERT_TRUE(source.Next(&f));
      for (const ImuSample& s : f.imu) odometry.AddImu(s);
      LidarScan scan = lioapp::TakeLidarScan(&f);
      const ScanResult r = odometry.AddScan(scan);
      EXPECT_EQ(r.status, ScanStatus::kFailed);
      EXPECT_THAT(r.message, HasSubstr(k.expected));
      EXPECT_THAT(r.message, ::testing::Not(HasSubstr("units")));
      EXPECT_THAT(r.message, ::testing::Not(HasSubstr("not still")));
    }
  }
}

}  // namespace
}  // namespace ctlio::lio
