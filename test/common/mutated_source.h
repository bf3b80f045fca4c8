// A short simulated sequence with its frames passed through a mutation: how the run checks and the
// IMU consistency tests (test/lio) make a defective recording from a clean one.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/io/dataset.h"
#include "ctlio/manifolds/types.h"
#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::testing {

// Tuning index 100 of the medium regime in the box, 3 s, 16 beams, every 4th firing.
inline sim::SimConfig ShortMediumSequence() {
  sim::SimConfig c =
      sim::ExperimentConfig(sim::Regime::kMedium, 100, sim::kExperimentSeed, sim::WorldKind::kBox);
  c.duration_s = 3.0;
  c.lidar.beams = 16;
  c.lidar.firing_decimation = 4;
  return c;
}

// The simulated source with each frame passed through `mutate` (false: the frame is dropped from
// the recording; its IMU samples go with the next frame, as a reader would hand them on).
class MutatedSource : public io::DataSource {
 public:
  MutatedSource(const sim::SimConfig& c, std::function<bool(io::ScanFrame*)> mutate)
      : source_(c, "sim:mutated"), mutate_(std::move(mutate)) {}
  std::string Name() const override { return source_.Name(); }
  size_t NumScans() const override { return 0; }
  bool Next(io::ScanFrame* frame) override {
    std::vector<io::ImuSample> carried;
    while (source_.Next(frame)) {
      carried.insert(carried.end(), frame->imu.begin(), frame->imu.end());
      frame->imu = carried;  // what `mutate_` sees (and may change) is what is handed on
      if (mutate_(frame)) return true;
    }
    return false;
  }
  SE3 ImuFromLidar() const override { return source_.ImuFromLidar(); }
  std::optional<std::vector<io::StampedPose>> GroundTruth() const override {
    return source_.GroundTruth();
  }
  std::optional<double> Gravity() const override { return source_.Gravity(); }
  std::vector<io::ImuInfo> Imus() const override { return source_.Imus(); }

 private:
  sim::SimulatedSource source_;
  std::function<bool(io::ScanFrame*)> mutate_;
};

// `c` with every IMU sample's specific force passed through `mutate`.
inline MutatedSource AccelMutatedSource(const sim::SimConfig& c,
                                        std::function<Vec3(const Vec3&)> mutate) {
  return MutatedSource(c, [mutate](io::ScanFrame* frame) {
    for (io::ImuSample& s : frame->imu) s.accel = mutate(s.accel);
    return true;
  });
}

// The accelerometer faults the run checks are tested on, the clean reading first.
inline std::vector<std::pair<std::string, std::function<Vec3(const Vec3&)>>> AccelerometerFaults() {
  return {
      {"clean", [](const Vec3& f) { return f; }},
      {"sign flipped", [](const Vec3& f) { return Vec3(-f); }},
      {"x and z swapped", [](const Vec3& f) { return Vec3(f.z(), f.y(), f.x()); }},
  };
}

}  // namespace ctlio::testing
