// ctlio_simulate: writes one sequence of the lidar-inertial simulator (SPEC §6) as a dataset
// folder, in ctlio's own layout (default) or the Newer College 2020 layout, with ground truth.
//
//   ctlio_simulate --regime=fast --index=3 --output=/tmp/fast_03 [--layout=newer_college]
//                  [--firing_decimation=4] [--duration=20] [--body_centric] [--pillars=4]
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <random>
#include <sstream>

#include "ctlio/io/newer_college.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/sim/lidar_inertial_sim.h"

DEFINE_string(output, "", "Dataset folder to write (required)");
DEFINE_string(layout, "ctlio", "Folder layout: ctlio | newer_college");
DEFINE_string(regime, "fast", "Motion regime: slow | medium | fast");
DEFINE_int32(index, 0, "Sequence index within the regime (the experiment uses 0..19)");
DEFINE_uint64(seed, ctlio::sim::kExperimentSeed, "Experiment seed (documented default)");
DEFINE_double(duration, 20.0, "Sequence length [s]");
DEFINE_int32(firing_decimation, 1, "Keep every n-th lidar firing (1 = full resolution)");
DEFINE_int32(beams, 128, "Lidar beams");
DEFINE_bool(body_centric, false, "Generate the paper's body-centric accelerometer (no ω×v)");
DEFINE_double(bias_walk_accel, 0.0, "Accelerometer bias random walk [m/s²/√s]");
DEFINE_double(bias_walk_gyro, 0.0, "Gyro bias random walk [rad/s/√s]");
DEFINE_int32(pillars, 0, "Interior 1 m × 1 m pillars placed at random (seeded) in the room");
DEFINE_bool(ground_truth, true, "Write the ground-truth trajectory");
DEFINE_bool(newer_college_extrinsic, false,
            "Use the Newer College lidar→IMU extrinsic instead of identity (always used with "
            "--layout=newer_college, which cannot carry another)");

int main(int argc, char** argv) {
  gflags::SetUsageMessage("Write a simulated lidar-inertial dataset folder");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  if (FLAGS_output.empty()) {
    std::cerr << "--output is required\n";
    return 2;
  }
  try {
    using namespace ctlio;
    const sim::Regime regime = sim::ParseRegime(FLAGS_regime);
    sim::SimConfig config = sim::ExperimentConfig(regime, FLAGS_index, FLAGS_seed);
    // inf wrote 0 scans with exit 0, nan failed in vector::reserve.
    if (!(FLAGS_duration > 0.0 && FLAGS_duration <= 3600.0)) {
      throw std::runtime_error("--duration must be in (0, 3600] s");
    }
    if (FLAGS_firing_decimation < 1 || FLAGS_beams < 1) {
      throw std::runtime_error("--firing_decimation and --beams must be >= 1");
    }
    config.duration_s = FLAGS_duration;
    config.lidar.firing_decimation = FLAGS_firing_decimation;
    config.lidar.beams = FLAGS_beams;
    config.imu.body_centric = FLAGS_body_centric;
    config.imu.accel_bias_walk = FLAGS_bias_walk_accel;
    config.imu.gyro_bias_walk = FLAGS_bias_walk_gyro;
    // The Newer College layout carries no extrinsic and is read with the published one.
    if (FLAGS_newer_college_extrinsic || FLAGS_layout == "newer_college") {
      config.imu_from_lidar = io::NewerCollegeImuFromLidar();
    }
    std::mt19937_64 rng(FLAGS_seed + 17);
    std::uniform_real_distribution<double> u(-40.0, 40.0);
    for (int i = 0; i < FLAGS_pillars; ++i) {
      const Vec3 c(u(rng), u(rng), 0.0);
      if (c.head<2>().norm() < 5.0) {  // keep the start area free
        --i;
        continue;
      }
      config.room.obstacles.push_back({c + Vec3(-0.5, -0.5, 0), c + Vec3(0.5, 0.5, 10)});
    }

    std::ostringstream yaml;
    yaml << "{regime: " << FLAGS_regime << ", index: " << FLAGS_index << ", seed: " << FLAGS_seed
         << ", duration_s: " << FLAGS_duration << ", firing_decimation: " << FLAGS_firing_decimation
         << ", beams: " << FLAGS_beams
         << ", body_centric: " << (FLAGS_body_centric ? "true" : "false")
         << ", pillars: " << FLAGS_pillars << ", axes: [";
    for (int j = 0; j < 6; ++j) {
      yaml << (j ? ", " : "") << "[" << config.motion.axes[j].amplitude << ", "
           << config.motion.axes[j].frequency << "]";
    }
    yaml << "]}";

    const auto t0 = std::chrono::steady_clock::now();
    std::ostringstream name;
    name << "sim:" << FLAGS_regime << "/" << FLAGS_index;
    sim::SimulatedSource source(config, name.str());
    // Progress on stderr, about every 5 % of the scans.
    auto progress = [&](size_t done, size_t total) {
      if (done != total && done % std::max<size_t>(1, total / 20) != 0) return;
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "scan %zu/%zu (%3.0f %%)  %.1f s\n", done, total,
                   100.0 * double(done) / double(std::max<size_t>(total, 1)), s);
    };
    size_t n = 0;
    if (FLAGS_layout == "ctlio") {
      n = io::WriteSimFolder(source, FLAGS_output, yaml.str(), progress, FLAGS_ground_truth);
    } else if (FLAGS_layout == "newer_college") {
      n = io::WriteNewerCollege(source, FLAGS_output, progress, FLAGS_ground_truth);
    } else {
      throw std::runtime_error("unknown --layout '" + FLAGS_layout + "'");
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    LOG(INFO) << "wrote " << n << " scans to " << FLAGS_output << " in " << s << " s";
  } catch (const std::exception& e) {
    std::cerr << "ctlio_simulate: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
