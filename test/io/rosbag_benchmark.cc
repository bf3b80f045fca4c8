// Bag reading speed: RosbagSource (decode PointCloud2 + Imu, group the IMU by scan) against a plain
// sequential read of the same file, both from the page cache (the file was just written), on a
// simulated full-resolution sequence (128 beams, 10 Hz, ~230 000 returns a scan) written as an
// Ouster-style bag. Reports MB/s (bytes of the bag file) and points/s.
//
//   build/test/io/rosbag_benchmark [--benchmark_repetitions=5]
//   CTLIO_BENCH_BAG=run.bag build/test/io/rosbag_benchmark   (any Ouster-style bag instead)
//
// peak_rss_MB (getrusage, process-wide high-water mark) shows that reading streams: it stays far
// below the bag's size.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include "common/temp_dir.h"
#include "ctlio/io/rosbag_source.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::io {
namespace {

const std::string& BagPath() {
  static const std::string path = []() -> std::string {
    if (const char* given = std::getenv("CTLIO_BENCH_BAG")) return given;
    const auto d = testing::FreshTempDir("rosbag_benchmark");
    sim::SimConfig c = sim::ExperimentConfig(sim::Regime::kMedium, 0);
    c.duration_s = 1.0;
    c.start_ns = 1'000'000'000;
    sim::SimulatedSource source(c);
    const std::string p = (d / "full_resolution.bag").string();
    WriteRosbag(source, p);
    return p;
  }();
  return path;
}

void PlainSequentialRead(benchmark::State& state) {
  const std::string& path = BagPath();
  std::vector<char> buffer(1 << 20);
  size_t bytes = 0;
  for (auto _ : state) {
    std::ifstream in(path, std::ios::binary);
    while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0) {
      bytes += size_t(in.gcount());
      benchmark::DoNotOptimize(buffer.data());
    }
  }
  state.SetBytesProcessed(int64_t(bytes));
}

void RosbagSourceRead(benchmark::State& state) {
  const std::string& path = BagPath();
  const auto file_bytes = std::filesystem::file_size(path);
  size_t points = 0, scans = 0;
  for (auto _ : state) {
    RosbagSource source(path);
    ScanFrame f;
    while (source.Next(&f)) {
      points += f.cloud.size();
      ++scans;
    }
  }
  state.SetBytesProcessed(int64_t(file_bytes * state.iterations()));
  state.counters["points/s"] = benchmark::Counter(double(points), benchmark::Counter::kIsRate);
  state.counters["scans/s"] = benchmark::Counter(double(scans), benchmark::Counter::kIsRate);
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["peak_rss_MB"] = double(usage.ru_maxrss) / 1024.0;
  state.counters["bag_MB"] = double(file_bytes) / 1e6;
}

BENCHMARK(PlainSequentialRead)->Unit(benchmark::kMillisecond);
BENCHMARK(RosbagSourceRead)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ctlio::io

BENCHMARK_MAIN();
