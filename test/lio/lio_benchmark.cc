// Per-scan latency of Singer-LIO and the baseline on simulated 128-beam scans (SPEC §6), single
// thread: each benchmark iteration runs one full scan (preprocess, association rounds, solves,
// map update) on a sequence simulated in memory. The first 5 scans (map building) are run
// outside the timing. Report: median of the per-scan times (Google Benchmark's median over
// repetitions) and the app's own p95/peak memory (ctlio_odometry's evaluation.txt).
#include <benchmark/benchmark.h>

#include "common/test_paths.h"
#include "ctlio/sim/lidar_inertial_sim.h"
#include "ctlio/solvers/lio/lio_odometry.h"

namespace {

using namespace ctlio;

void RunScans(benchmark::State& state, lio::LioMethod method, int beams, int decimation) {
  sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 0);
  c.duration_s = 4.0;
  c.lidar.beams = beams;
  c.lidar.firing_decimation = decimation;
  sim::SimulatedSource source(c);
  lio::OdometryConfig config =
      lio::LoadOdometryConfig(ctlio::testing::SourceDir() + "/data/sim_lio.yaml");
  config.method = method;
  auto odometry = lio::MakeLioOdometry(config);
  std::vector<io::ScanFrame> frames;
  io::ScanFrame f;
  while (source.Next(&f)) frames.push_back(f);
  size_t k = 0;
  auto feed = [&](size_t i) {
    for (const auto& x : frames[i].imu) {
      lio::ImuSample s;
      s.t_ns = x.t_ns;
      s.gyro = x.gyro;
      s.accel = x.accel;
      odometry->AddImu(s);
    }
    lio::LidarScan scan;
    scan.begin_ns = frames[i].start_ns;
    scan.end_ns = frames[i].end_ns;
    scan.points = frames[i].cloud.points;
    scan.times_ns = frames[i].cloud.times_ns;
    return odometry->AddScan(scan);
  };
  for (; k < 5; ++k) feed(k);
  for (auto _ : state) {
    if (k >= frames.size()) {
      state.SkipWithError("sequence exhausted");
      break;
    }
    const auto r = feed(k++);
    benchmark::DoNotOptimize(r);
  }
}

void BM_SingerLio128(benchmark::State& s) { RunScans(s, lio::LioMethod::kSingerLio, 128, 1); }
void BM_ImuInput128(benchmark::State& s) { RunScans(s, lio::LioMethod::kImuInput, 128, 1); }
BENCHMARK(BM_SingerLio128)->Unit(benchmark::kMillisecond)->Iterations(20);
BENCHMARK(BM_ImuInput128)->Unit(benchmark::kMillisecond)->Iterations(20);

}  // namespace

BENCHMARK_MAIN();
