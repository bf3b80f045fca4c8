// SimulatedSource (lidar_inertial_sim.h): the simulator read as a data source, scan by scan.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "ctlio/sim/lidar_inertial_sim.h"

namespace ctlio::sim {
namespace {

// A scan ends at its last kept firing; ground truth holds a pose at exactly that time.
int64_t ScanEndNs(const LidarInertialSim& sim, size_t k) {
  const int last = sim.config().lidar.firings_per_revolution - 1;
  return sim.FiringTimeNs(k, last - last % sim.config().lidar.firing_decimation);
}

}  // namespace

SimulatedSource::SimulatedSource(const SimConfig& config, std::string name)
    : sim_(config), name_(std::move(name)) {}

bool SimulatedSource::Next(io::ScanFrame* frame) {
  if (next_ >= sim_.NumScans()) return false;
  frame->index = next_;
  frame->cloud = sim_.Scan(next_);
  frame->start_ns = frame->cloud.stamp_ns;
  frame->end_ns = ScanEndNs(sim_, next_);
  frame->imu.clear();
  io::TakeImuUntil(sim_.AllImu(), frame->end_ns, &imu_cursor_, &frame->imu);
  ++next_;
  return true;
}

std::vector<io::ImuInfo> SimulatedSource::Imus() const {
  std::vector<io::ImuInfo> out;
  for (size_t j = 0; j < sim_.NumImus(); ++j) {
    const ImuConfig& I = sim_.ImuConfigOf(j);
    io::ImuInfo info;
    info.name = "imu" + std::to_string(j);
    info.T_body_imu = I.body_from_imu;
    info.rate_hz = I.rate_hz;
    info.accel_sigma = I.accel_noise;
    info.gyro_sigma = I.gyro_noise;
    Vec6 b;
    b << I.accel_bias, I.gyro_bias;
    info.true_bias = b;
    if (I.stamp_offset_s != 0.0) info.true_time_offset_s = I.stamp_offset_s;
    out.push_back(info);
  }
  return out;
}

std::optional<std::vector<io::StampedPose>> SimulatedSource::GroundTruth() const {
  std::vector<int64_t> times;
  for (const auto& s : sim_.Imu()) times.push_back(s.t_ns);
  for (size_t k = 0; k < sim_.NumScans(); ++k) times.push_back(ScanEndNs(sim_, k));
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  std::vector<io::StampedPose> gt;
  gt.reserve(times.size());
  for (int64_t t : times) gt.push_back({t, sim_.WorldFromLidar(sim_.Seconds(t))});
  return gt;
}

}  // namespace ctlio::sim
