// Simulator speed (the target: a 20 s full-resolution sequence in < 30 s on one core).
// BM_FullSequence generates every scan and IMU sample of fast/00 in memory; BM_Scan one scan;
// BM_ScanWorld one scan in each world (box, street, corridor, park, indoor, quad, town, office).
#include <benchmark/benchmark.h>

#include "ctlio/sim/lidar_inertial_sim.h"

namespace {

void BM_FullSequence(benchmark::State& state) {
  for (auto _ : state) {
    ctlio::sim::SimulatedSource source(ctlio::sim::ExperimentConfig(ctlio::sim::Regime::kFast, 0));
    ctlio::io::ScanFrame frame;
    size_t points = 0;
    while (source.Next(&frame)) points += frame.cloud.size();
    benchmark::DoNotOptimize(points);
    state.counters["points"] = double(points);
  }
}
BENCHMARK(BM_FullSequence)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3);

void BM_Scan(benchmark::State& state) {
  const ctlio::sim::LidarInertialSim sim(
      ctlio::sim::ExperimentConfig(ctlio::sim::Regime::kFast, 0));
  size_t k = 0;
  for (auto _ : state) {
    auto cloud = sim.Scan(k++ % sim.NumScans());
    benchmark::DoNotOptimize(cloud.points.data());
  }
}
BENCHMARK(BM_Scan)->Unit(benchmark::kMillisecond);

// One full-resolution scan (128 beams × 1800 firings = 230,400 rays) per world, medium regime
// (guided along the path outside the box), sequence 0, scans taken in turn over the first 5 s.
void BM_ScanWorld(benchmark::State& state) {
  const auto world = static_cast<ctlio::sim::WorldKind>(state.range(0));
  ctlio::sim::SimConfig c = ctlio::sim::ExperimentConfig(ctlio::sim::Regime::kMedium, 0,
                                                         ctlio::sim::kExperimentSeed, world);
  c.duration_s = 5.0;
  const ctlio::sim::LidarInertialSim sim(c);
  size_t k = 0, points = 0;
  for (auto _ : state) {
    auto cloud = sim.Scan(k++ % sim.NumScans());
    points = cloud.size();
    benchmark::DoNotOptimize(cloud.points.data());
  }
  state.SetLabel(ctlio::sim::WorldName(world));
  state.counters["returns"] = double(points);
}
BENCHMARK(BM_ScanWorld)->DenseRange(0, 7)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
