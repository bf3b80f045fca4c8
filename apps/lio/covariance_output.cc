#include "covariance_output.h"

#include <cstdio>
#include <fstream>
#include <map>

#include "ctlio/io/checked_output.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio::lioapp {

std::array<double, 21> UpperTriangle(const Mat6& S) {
  std::array<double, 21> out{};
  size_t k = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) out[k++] = S(i, j);
  }
  return out;
}

void WriteTrajectoryCovariance(const std::string& dir, const std::vector<lio::ScanResult>& scans,
                               OutputFiles* files) {
  const std::string path = dir + "/trajectory_covariance.csv";
  std::ofstream f = io::OpenForWriting(path);
  // ρ = [x y z], φ = [rx ry rz] (rotation vector about the world axes).
  const char* axes[6] = {"x", "y", "z", "rx", "ry", "rz"};
  f << "t";
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) f << ",c_" << axes[i] << '_' << axes[j];
  }
  f << '\n';
  char buffer[32];
  for (const lio::ScanResult& r : scans) {
    if (!r.has_pose_covariance || r.status == lio::ScanStatus::kFailed) continue;
    std::snprintf(buffer, sizeof(buffer), "%.9f", 1e-9 * double(r.t_ns));
    f << buffer;
    for (const double c : UpperTriangle(r.pose_covariance)) {
      std::snprintf(buffer, sizeof(buffer), ",%.9g", c);
      f << buffer;
    }
    f << '\n';
  }
  io::CloseChecked(f, path);
  files->Add(path,
             "each scan's 6x6 pose covariance: t + 21 upper-triangle entries, [rho; phi] left "
             "perturbation of T_world_lidar (docs/user-guide/outputs.md)");
}

std::array<double, 36> RosPoseCovariance(const Mat6& S, const SE3& T) {
  Mat6 G = Mat6::Identity();
  G.topRightCorner<3, 3>() = -so3::Hat(T.translation());
  const Mat6 R = G * S * G.transpose();
  std::array<double, 36> out{};
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) out[size_t(6 * i + j)] = R(i, j);
  }
  return out;
}

std::vector<std::array<double, 36>> RosPoseCovariances(const RunSummary& run) {
  std::map<int64_t, const Mat6*> by_time;
  for (const lio::ScanResult& r : run.scans) {
    if (r.has_pose_covariance) by_time[r.t_ns] = &r.pose_covariance;
  }
  std::vector<std::array<double, 36>> out;
  out.reserve(run.trajectory.size());
  for (const io::StampedPose& p : run.trajectory) {
    const auto it = by_time.find(p.t_ns);
    out.push_back(it == by_time.end() ? std::array<double, 36>{}
                                      : RosPoseCovariance(*it->second, p.pose));
  }
  return out;
}

}  // namespace ctlio::lioapp
