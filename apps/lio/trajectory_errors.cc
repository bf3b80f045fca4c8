#include "trajectory_errors.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <optional>
#include <vector>

#include "ctlio/eval/trajectory_metrics.h"
#include "ctlio/io/checked_output.h"

namespace ctlio::lioapp {

namespace {

// The truth at time t: the position (a pose within 1 ms, else interpolated linearly between poses
// less than 0.2 s apart) and the rotation of the nearest pose. False if t is not covered.
bool TruthAt(const std::vector<io::StampedPose>& truth, int64_t t, Vec3* p, Mat3* C) {
  const auto it = std::lower_bound(truth.begin(), truth.end(), t,
                                   [](const io::StampedPose& q, int64_t x) { return q.t_ns < x; });
  if (it != truth.end() && std::llabs(it->t_ns - t) <= 1000000) {
    *p = it->pose.translation();
    *C = it->pose.rotation();
  } else if (it != truth.begin() && it != truth.end() && it->t_ns - (it - 1)->t_ns < 200000000) {
    const double s = double(t - (it - 1)->t_ns) / double(it->t_ns - (it - 1)->t_ns);
    *p = (1 - s) * (it - 1)->pose.translation() + s * it->pose.translation();
    *C = (s < 0.5 ? (it - 1) : it)->pose.rotation();
  } else if (it != truth.begin() && std::llabs((it - 1)->t_ns - t) <= 1000000) {
    *p = (it - 1)->pose.translation();
    *C = (it - 1)->pose.rotation();
  } else {
    return false;
  }
  return true;
}

}  // namespace

AteResult EvaluateAte(const std::vector<io::StampedPose>& estimate,
                      const std::vector<io::StampedPose>& truth) {
  AteResult r;
  if (truth.size() < 2) return r;
  std::vector<Vec3> est, ref;
  for (const io::StampedPose& e : estimate) {
    Vec3 p;
    Mat3 C;
    if (!TruthAt(truth, e.t_ns, &p, &C)) continue;
    est.push_back(e.pose.translation());
    ref.push_back(p);
  }
  r.pairs = est.size();
  if (est.size() < 3) return r;
  Eigen::Matrix3Xd A(3, est.size()), B(3, est.size());
  for (size_t i = 0; i < est.size(); ++i) {
    A.col(i) = est[i];
    B.col(i) = ref[i];
  }
  // SE(3) alignment (no scale): Umeyama (1991) as implemented by Eigen.
  const Eigen::Matrix4d T = Eigen::umeyama(A, B, false);
  r.alignment = T;
  double sum2 = 0.0;
  for (size_t i = 0; i < est.size(); ++i) {
    const double e =
        (T.topLeftCorner<3, 3>() * A.col(i) + T.topRightCorner<3, 1>() - B.col(i)).norm();
    sum2 += e * e;
    r.mean += e;
    r.max = std::max(r.max, e);
  }
  r.rmse = std::sqrt(sum2 / double(est.size()));
  r.mean /= double(est.size());
  return r;
}

std::optional<double> DriftPer100m(const std::vector<io::StampedPose>& estimate,
                                   const std::vector<io::StampedPose>& truth) {
  std::vector<io::StampedPose> est, ref;
  for (const io::StampedPose& e : estimate) {
    Vec3 p;
    Mat3 C;
    if (!TruthAt(truth, e.t_ns, &p, &C)) continue;
    est.push_back(e);
    ref.push_back({e.t_ns, SE3(C, p)});
  }
  double path = 0.0;
  for (size_t i = 1; i < ref.size(); ++i) {
    path += (ref[i].pose.translation() - ref[i - 1].pose.translation()).norm();
  }
  if (path < 1.0) return std::nullopt;
  return eval::ComputeRpeDistance(est, ref, std::min(kDriftWindow, 0.5 * path)).translation_percent;
}

void WritePoseErrors(const std::string& path, const std::vector<io::StampedPose>& estimate,
                     const std::vector<io::StampedPose>& truth, const Eigen::Matrix4d& alignment) {
  std::ofstream f = io::OpenForWriting(path);
  f << "t_s,est_x,est_y,est_z,ref_x,ref_y,ref_z,position_error_m,rotation_error_deg\n";
  f << std::setprecision(12);
  const Mat3 A = alignment.topLeftCorner<3, 3>();
  const Vec3 a = alignment.topRightCorner<3, 1>();
  bool first = true;
  Mat3 C_e0, C_t0;
  for (const io::StampedPose& e : estimate) {
    Vec3 p;
    Mat3 C;
    if (!TruthAt(truth, e.t_ns, &p, &C)) continue;
    if (first) {
      C_e0 = e.pose.rotation();
      C_t0 = C;
      first = false;
    }
    const Vec3 q = A * e.pose.translation() + a;
    // Rotation drift since the first pose: independent of the position-only alignment, which
    // leaves the rotation free on a short, nearly straight path.
    const Mat3 dC_truth = C_t0.transpose() * C, dC_est = C_e0.transpose() * e.pose.rotation();
    const double angle = Eigen::AngleAxisd(dC_truth.transpose() * dC_est).angle();
    f << 1e-9 * double(e.t_ns) << ',' << q.x() << ',' << q.y() << ',' << q.z() << ',' << p.x()
      << ',' << p.y() << ',' << p.z() << ',' << (q - p).norm() << ',' << angle * 180.0 / M_PI
      << '\n';
  }
  io::CloseChecked(f, path);
}

namespace {

// The truth pose at exactly (within 1 ms) t, if there is one.
std::optional<SE3> TruthPoseAt(const std::vector<io::StampedPose>& truth, int64_t t) {
  const auto it = std::lower_bound(truth.begin(), truth.end(), t,
                                   [](const io::StampedPose& q, int64_t x) { return q.t_ns < x; });
  if (it != truth.end() && std::llabs(it->t_ns - t) <= 1000000) return it->pose;
  if (it != truth.begin() && std::llabs((it - 1)->t_ns - t) <= 1000000) return (it - 1)->pose;
  return std::nullopt;
}

}  // namespace

PoseNees EvaluatePoseNees(const std::vector<lio::ScanResult>& scans,
                          const std::vector<io::StampedPose>& truth, const SE3& T_imu_lidar) {
  PoseNees out;
  std::optional<SE3> T_wm;
  const SE3 T_lidar_imu = T_imu_lidar.Inverse();
  for (const lio::ScanResult& r : scans) {
    if (r.status == lio::ScanStatus::kFailed) continue;
    const std::optional<SE3> T_wl = TruthPoseAt(truth, r.t_ns);
    if (!T_wl) continue;
    if (!T_wm) {  // the first estimate: T_mr = T_mr(first)
      T_wm = *T_wl * T_lidar_imu * r.T_mr.Inverse();
      continue;
    }
    if (!r.has_pose_covariance) continue;
    const SE3 T_mr_true = T_wm->Inverse() * *T_wl * T_lidar_imu;
    const Vec6 e = (T_mr_true * r.T_mr.Inverse()).Log();
    const Mat6& S = r.pose_covariance;
    out.pose.push_back(e.dot(S.ldlt().solve(e)));
    out.translation.push_back(
        e.head<3>().dot(S.topLeftCorner<3, 3>().ldlt().solve(Vec3(e.head<3>()))));
    out.rotation.push_back(
        e.tail<3>().dot(S.bottomRightCorner<3, 3>().ldlt().solve(Vec3(e.tail<3>()))));
    for (int i = 0; i < 6; ++i) {
      if (std::abs(e[i]) <= 3.0 * std::sqrt(S(i, i))) ++out.inside_3sigma[size_t(i)];
    }
  }
  return out;
}

}  // namespace ctlio::lioapp
