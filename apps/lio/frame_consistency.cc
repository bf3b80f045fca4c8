#include "lio/frame_consistency.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "ctlio/factors/imu/saturating_ns.h"
#include "ctlio/manifolds/so3.h"

namespace ctlio::lioapp {

namespace {

// A hole in the IMU stream longer than this leaves the window or span out (the gyro's attitude
// and the accelerometer's mean would be guesses there).
constexpr int64_t kMaxSampleGapNs = 50'000'000;

Mat3 Hat(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Calls fn(a, b, sample) for every piece [a, b) of [t0, t1) over which a sample holds (zero-order
// hold: sample k on [t_k, t_{k+1})). False if the samples do not cover [t0, t1] or leave a gap.
template <class Fn>
bool ForPieces(const std::deque<imu::ImuSample>& s, int64_t t0, int64_t t1, Fn&& fn) {
  auto it = std::upper_bound(s.begin(), s.end(), t0,
                             [](int64_t t, const imu::ImuSample& x) { return t < x.t_ns; });
  if (it == s.begin()) return false;
  for (--it; it != s.end() && it->t_ns < t1; ++it) {
    const auto next = it + 1;
    if (next == s.end() || next->t_ns - it->t_ns > kMaxSampleGapNs) return false;
    const int64_t a = std::max(it->t_ns, t0), b = std::min(next->t_ns, t1);
    if (b > a) fn(a, b, *it);
  }
  return true;
}

double Seconds(int64_t ns) { return 1e-9 * static_cast<double>(ns); }

double ThreadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// The gyro's rotation over [t0, t1) (zero-order hold).
bool GyroRotation(const std::deque<imu::ImuSample>& s, int64_t t0, int64_t t1, Mat3* R) {
  *R = Mat3::Identity();
  return ForPieces(s, t0, t1, [&](int64_t a, int64_t b, const imu::ImuSample& x) {
    *R = *R * so3::Exp(x.gyro * Seconds(b - a));
  });
}

// "(+z, +y, +x)" (true x, y, z = reading z, y, x) when M is within 0.4 of a signed permutation
// entry by entry; else "" (M is no clear relabelling of the axes).
std::string SignedPermutation(const Mat3& M) {
  std::string out = "(";
  int used = 0;
  for (int i = 0; i < 3; ++i) {
    int j;
    M.row(i).cwiseAbs().maxCoeff(&j);
    if (used & (1 << j)) return "";
    used |= 1 << j;
    const double sign = M(i, j) < 0 ? -1.0 : 1.0;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(M(i, k) - (k == j ? sign : 0.0)) > 0.4) return "";
    }
    out += std::string(i ? ", " : "") + (sign < 0 ? "-" : "+") + "xyz"[j];
  }
  return out + ")";
}

// Calls fn(P) for each of the 48 signed permutation matrices.
template <class Fn>
void ForEachSignedPermutation(Fn&& fn) {
  int perm[3] = {0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Mat3 P = Mat3::Zero();
      for (int i = 0; i < 3; ++i) P(i, perm[i]) = (signs >> i) & 1 ? -1.0 : 1.0;
      fn(P);
    }
  } while (std::next_permutation(perm, perm + 3));
}

// Residual sum of squares of the specific-force fit with M fixed and g refitted:
// g = N_gg⁻¹(v_g − N_gM·vec(M)).
double FixedMapSquares(const Eigen::Matrix<double, 12, 12>& N,
                       const Eigen::Matrix<double, 12, 1>& v, double s, const Mat3& M) {
  Eigen::Matrix<double, 12, 1> x;
  x.head<9>() = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(M.data());
  x.tail<3>() = N.bottomRightCorner<3, 3>().ldlt().solve(v.tail<3>() -
                                                         N.bottomLeftCorner<3, 9>() * x.head<9>());
  return std::max(0.0, s - 2.0 * x.dot(v) + x.dot(N * x));
}

}  // namespace

FrameConsistencyCheck::FrameConsistencyCheck(const SE3& T_robot_imu, int imu,
                                             const FrameConsistencyOptions& options,
                                             double clock_offset_s)
    : T_ri_(T_robot_imu),
      imu_(imu),
      options_(options),
      clock_offset_ns_(std::isfinite(clock_offset_s) ? std::llround(clock_offset_s * 1e9) : 0) {}

void FrameConsistencyCheck::AddImu(const imu::ImuSample& sample) {
  if (sample.imu != imu_ || !sample.gyro.allFinite() || !sample.accel.allFinite()) return;
  imu::ImuSample on_lidar_clock = sample;
  on_lidar_clock.t_ns = SaturatingAddNs(sample.t_ns, clock_offset_ns_);
  if (!samples_.empty() && on_lidar_clock.t_ns <= samples_.back().t_ns) return;
  samples_.push_back(on_lidar_clock);
  Process();
}

void FrameConsistencyCheck::AddPose(int64_t t_ns, const SE3& T_mr) {
  if (!poses_.empty() && t_ns <= poses_.back().t_ns) return;
  if (!T_mr.rotation().allFinite() || !T_mr.translation().allFinite()) return Break();
  poses_.push_back({t_ns, T_mr * T_ri_});
  Process();
}

void FrameConsistencyCheck::Break() {
  poses_.clear();
  next_window_ = next_span_ = 0;
}

// The first pose at least `span` after poses_[from] (poses_.size() if none).
size_t FrameConsistencyCheck::After(size_t from, double span) const {
  const int64_t t = poses_[from].t_ns + static_cast<int64_t>(span * 1e9);
  size_t i = from + 1;
  while (i < poses_.size() && poses_[i].t_ns < t) ++i;
  return i;
}

void FrameConsistencyCheck::Process() {
  if (samples_.empty()) return;
  const double start = ThreadCpuMs();
  const int64_t last = samples_.back().t_ns;
  while (next_window_ < poses_.size()) {
    const size_t m = After(next_window_, options_.half_window_s);
    if (m >= poses_.size()) break;
    const size_t e = After(m, options_.half_window_s);
    if (e >= poses_.size() || poses_[e].t_ns > last) break;
    Window(next_window_++, m, e);
  }
  while (next_span_ < poses_.size()) {
    const size_t e = After(next_span_, options_.rotation_span_s);
    if (e >= poses_.size() || poses_[e].t_ns > last) break;
    RotationSpan(next_span_++, e);
  }
  const size_t drop = std::min(next_window_, next_span_);
  poses_.erase(poses_.begin(), poses_.begin() + static_cast<std::ptrdiff_t>(drop));
  next_window_ -= drop;
  next_span_ -= drop;
  // Keep the last sample at or before the oldest pose still needed (it holds over its start).
  const int64_t keep = poses_.empty() ? last : poses_.front().t_ns;
  while (samples_.size() > 1 && samples_[1].t_ns <= keep) samples_.pop_front();
  cpu_ms_ += ThreadCpuMs() - start;
}

void FrameConsistencyCheck::Window(size_t first, size_t center, size_t end) {
  const Pose& P0 = poses_[first];
  const Pose& Pm = poses_[center];
  const Pose& P2 = poses_[end];
  const double T = Seconds(P2.t_ns - P0.t_ns), T1 = Seconds(Pm.t_ns - P0.t_ns),
               T2 = Seconds(P2.t_ns - Pm.t_ns);
  // 2·p[t₀, t_m, t₂m] = ∫ M(s) p̈(s) ds with the hat M(s) of area 1 (peak 2/T at t_m).
  const Vec3 b = 2.0 / T *
                 ((P2.T_mi.translation() - Pm.T_mi.translation()) / T2 -
                  (Pm.T_mi.translation() - P0.T_mi.translation()) / T1);
  Eigen::Matrix<double, 3, 12> A = Eigen::Matrix<double, 3, 12>::Zero();
  A.rightCols<3>().setIdentity();
  double area = 0.0;
  for (size_t j = first; j < end; ++j) {
    const Pose& Pa = poses_[j];
    const Pose& Pb = poses_[j + 1];
    // The gyro carries the attitude between the poses; its mismatch with the poses' relative
    // rotation (bias, noise) is spread evenly over the interval as a constant rate c.
    Mat3 G;
    if (!GyroRotation(samples_, Pa.t_ns, Pb.t_ns, &G)) return;
    const double Tj = Seconds(Pb.t_ns - Pa.t_ns);
    const Vec3 c =
        so3::Log(G.transpose() * Pa.T_mi.rotation().transpose() * Pb.T_mi.rotation()) / Tj;
    Mat3 Rg = Mat3::Identity();
    const bool ok =
        ForPieces(samples_, Pa.t_ns, Pb.t_ns, [&](int64_t a, int64_t e, const imu::ImuSample& x) {
          const double dt = Seconds(e - a), mid = Seconds(a - Pa.t_ns) + 0.5 * dt;
          const Mat3 R =
              Pa.T_mi.rotation() * Rg * so3::Exp(x.gyro * (0.5 * dt)) * so3::Exp(c * mid);
          Rg = Rg * so3::Exp(x.gyro * dt);
          // The hat is linear on the piece (pieces do not straddle t_m): exact midpoint weight.
          const double s = Seconds(a - P0.t_ns) + 0.5 * dt;
          const double k = s <= T1 ? 2.0 / T * s / T1 : 2.0 / T * (T - s) / T2;
          area += k * dt;
          for (int i = 0; i < 3; ++i) A.block<3, 3>(0, 3 * i) += (k * dt * x.accel[i]) * R;
        });
    if (!ok) return;
  }
  if (std::abs(area - 1.0) > 1e-3) return;
  N_ += A.transpose() * A;
  v_ += A.transpose() * b;
  s_ += b.squaredNorm();
  ++windows_;
}

void FrameConsistencyCheck::RotationSpan(size_t first, size_t end) {
  const Pose& Pa = poses_[first];
  const Pose& Pb = poses_[end];
  Mat3 G;
  if (!GyroRotation(samples_, Pa.t_ns, Pb.t_ns, &G)) return;
  const Vec3 theta_g = so3::Log(G);
  const Vec3 theta_p = so3::Log(Pa.T_mi.rotation().transpose() * Pb.T_mi.rotation());
  // θ_pose ≈ θ_gyro + δ × θ_gyro − T·b: residual r = θ_pose − θ_gyro = [−[θ_g]×, −T·I] [δ; b].
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>() = -Hat(theta_g);
  J.rightCols<3>() = -Seconds(Pb.t_ns - Pa.t_ns) * Mat3::Identity();
  Nr_ += J.transpose() * J;
  vr_ += J.transpose() * (theta_p - theta_g);
  sr_ += (theta_p - theta_g).squaredNorm();
  ++spans_;
}

FrameConsistency FrameConsistencyCheck::Result() const {
  FrameConsistency r;
  r.windows = windows_;
  r.rotation_spans = spans_;
  r.cpu_ms = cpu_ms_;
  if (windows_ >= options_.min_windows) {
    // Free fit: x = N⁺v (pseudo-inverse: a map direction nothing excited stays at its minimum
    // norm and contributes nothing to the residual).
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> eig(N_);
    const double cutoff = 1e-9 * eig.eigenvalues().maxCoeff();
    Eigen::Matrix<double, 12, 1> x = Eigen::Matrix<double, 12, 1>::Zero();
    for (int i = 0; i < 12; ++i) {
      if (eig.eigenvalues()[i] > cutoff) {
        x += eig.eigenvectors().col(i) * (eig.eigenvectors().col(i).dot(v_) / eig.eigenvalues()[i]);
      }
    }
    const double ss_free = std::max(0.0, s_ - 2.0 * x.dot(v_) + x.dot(N_ * x));
    const double ss_id = FixedMapSquares(N_, v_, s_, Mat3::Identity());
    r.identity_rms = std::sqrt(ss_id / (3.0 * windows_));
    r.free_rms = std::sqrt(ss_free / (3.0 * windows_));
    r.explained = ss_id > 0.0 ? (ss_id - ss_free) / ss_id : 0.0;
    r.map = Eigen::Map<const Mat3>(x.data());
    r.map_deviation = (r.map - Mat3::Identity()).norm();
    r.map_reading = SignedPermutation(r.map);
    double ss_best = -1.0;
    ForEachSignedPermutation([&](const Mat3& P) {
      if (P.isIdentity()) return;
      const double ss = FixedMapSquares(N_, v_, s_, P);
      if (ss_best < 0.0 || ss < ss_best) {
        ss_best = ss;
        r.best_relabelling = SignedPermutation(P);
      }
    });
    r.best_relabelling_rms = std::sqrt(ss_best / (3.0 * windows_));
  }
  if (spans_ >= options_.min_windows) {
    // δ with the bias eliminated (Schur complement), solved along the excited axes only.
    const Mat3 Nbb_inv = Nr_.bottomRightCorner<3, 3>().inverse();
    const Mat3 S = Nr_.topLeftCorner<3, 3>() -
                   Nr_.topRightCorner<3, 3>() * Nbb_inv * Nr_.bottomLeftCorner<3, 3>();
    const Vec3 rhs = vr_.head<3>() - Nr_.topRightCorner<3, 3>() * Nbb_inv * vr_.tail<3>();
    Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
    r.rotation_excitation = eig.eigenvalues();
    {
      const Vec6 y = Nr_.ldlt().solve(vr_);
      r.rotation_error_all = y.head<3>();
      r.rotation_rms_deg =
          std::sqrt(std::max(0.0, sr_ - 2.0 * y.dot(vr_) + y.dot(Nr_ * y)) / (3.0 * spans_)) *
          180.0 / M_PI;
    }
    for (int i = 0; i < 3; ++i) {
      if (eig.eigenvalues()[i] < options_.min_rotation_excitation) continue;
      ++r.excited_axes;
      r.rotation_error +=
          eig.eigenvectors().col(i) * (eig.eigenvectors().col(i).dot(rhs) / eig.eigenvalues()[i]);
    }
  }
  char text[1200];
  std::string found;
  if (r.windows >= options_.min_windows && r.identity_rms > options_.max_identity_rms) {
    std::snprintf(
        text, sizeof(text),
        "the accelerometer disagrees with the accelerations of the lidar trajectory: "
        "residual RMS %.3g m/s^2 over %d windows of %.1f s (threshold %.3g; clean "
        "simulated runs 0.002 to 0.14); a fitted 3x3 map M (f -> M f) leaves %.3g "
        "(|M - I| = %.2f%s%s): the accelerometer's sign or axes (a flipped or swapped "
        "column), the IMU's mounting (extrinsic rotation), a clock offset between IMU and "
        "lidar (calibration: estimate_time_offset), or a diverged estimate",
        r.identity_rms, r.windows, 2.0 * options_.half_window_s, options_.max_identity_rms,
        r.free_rms, r.map_deviation, r.map_reading.empty() ? "" : ", true (x, y, z) = reading ",
        r.map_reading.c_str());
    found = text;
  }
  const double deg = r.rotation_error.norm() * 180.0 / M_PI;
  if (r.excited_axes > 0 && deg > options_.max_rotation_deg) {
    const Vec3 axis = r.rotation_error.normalized();
    std::snprintf(text, sizeof(text),
                  "the gyro's rotations and the lidar trajectory's differ by a rotation of %.2f "
                  "deg about [%.2f %.2f %.2f] in the IMU frame (%d spans of %.1f s, %d of 3 axes "
                  "excited; threshold %.3g deg, clean simulated runs up to 1.28): the extrinsic "
                  "rotation (config extrinsic:, the "
                  "dataset's imu_from_lidar or /tf_static) is likely off by about that "
                  "(calibration.estimate_extrinsic: true estimates it), or the gyro's axes are "
                  "wrong",
                  deg, axis.x(), axis.y(), axis.z(), r.rotation_spans, options_.rotation_span_s,
                  r.excited_axes, options_.max_rotation_deg);
    found += std::string(found.empty() ? "" : "; ") + text;
  }
  r.warning = found;
  return r;
}

void WriteFrameConsistency(const FrameConsistency& r, std::ostream& out) {
  if (r.windows == 0 && r.rotation_spans == 0) return;
  out << "frame_windows " << r.windows << "\nframe_map_explained " << r.explained
      << "\nframe_identity_rms " << r.identity_rms << "\nframe_free_rms " << r.free_rms
      << "\nframe_map_deviation " << r.map_deviation << "\nframe_best_relabelling_rms "
      << r.best_relabelling_rms << "\nframe_best_relabelling \"" << r.best_relabelling
      << "\"\nframe_map";
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out << ' ' << r.map(i, j);
  }
  out << "\nframe_check_cpu_ms " << r.cpu_ms << "\nframe_rotation_spans " << r.rotation_spans
      << "\nframe_rotation_excited_axes " << r.excited_axes << "\nframe_rotation_excitation "
      << r.rotation_excitation.transpose() << "\nframe_rotation_error_all_deg "
      << r.rotation_error_all.transpose() * 180.0 / M_PI << "\nframe_rotation_rms_deg "
      << r.rotation_rms_deg << "\nframe_rotation_error_deg "
      << r.rotation_error.norm() * 180.0 / M_PI << "\n";
  if (!r.warning.empty()) out << "frame_inconsistency \"" << r.warning << "\"\n";
}

}  // namespace ctlio::lioapp
