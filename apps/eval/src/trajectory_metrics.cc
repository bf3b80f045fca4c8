#include "ctlio/eval/trajectory_metrics.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace ctlio::eval {

Similarity Umeyama(const std::vector<Vec3>& source, const std::vector<Vec3>& target,
                   bool with_scale) {
  const size_t n = source.size();
  if (n != target.size()) throw std::runtime_error("Umeyama: point sets differ in size");
  if (n < 3) throw std::runtime_error("Umeyama: need at least 3 point pairs");
  Vec3 mu_s = Vec3::Zero(), mu_t = Vec3::Zero();
  for (size_t i = 0; i < n; ++i) mu_s += source[i], mu_t += target[i];
  mu_s /= double(n);
  mu_t /= double(n);
  Mat3 sigma = Mat3::Zero();
  double var_s = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 ds = source[i] - mu_s;
    sigma += (target[i] - mu_t) * ds.transpose();
    var_s += ds.squaredNorm();
  }
  sigma /= double(n);
  var_s /= double(n);
  Eigen::JacobiSVD<Mat3> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 d = svd.singularValues();
  // Rank < 2 (all points on a line or one point) leaves the rotation undetermined.
  if (d[1] <= 1e-12 * std::max(1.0, d[0])) {
    throw std::runtime_error("Umeyama: degenerate (collinear) point configuration");
  }
  Vec3 s(1, 1, 1);
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) s[2] = -1;
  const Mat3 C = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  Similarity out;
  out.scale = with_scale ? d.dot(s) / var_s : 1.0;
  out.pose = SE3(C, mu_t - out.scale * C * mu_s);
  return out;
}

std::vector<std::pair<size_t, size_t>> Associate(const std::vector<io::StampedPose>& est,
                                                 const std::vector<io::StampedPose>& ref,
                                                 int64_t tolerance_ns) {
  std::vector<std::pair<size_t, size_t>> pairs;
  size_t j = 0;
  for (size_t i = 0; i < est.size(); ++i) {
    const int64_t t = est[i].t_ns;
    while (j + 1 < ref.size() && std::llabs(ref[j + 1].t_ns - t) <= std::llabs(ref[j].t_ns - t)) {
      ++j;
    }
    if (j >= ref.size()) break;
    if (std::llabs(ref[j].t_ns - t) > tolerance_ns) continue;
    if (!pairs.empty() && pairs.back().second == j) {
      // Keep the closer of two estimates that pick the same reference pose.
      const int64_t prev = std::llabs(est[pairs.back().first].t_ns - ref[j].t_ns);
      if (std::llabs(t - ref[j].t_ns) < prev) pairs.back().first = i;
      continue;
    }
    pairs.emplace_back(i, j);
  }
  return pairs;
}

AlignmentMode ParseAlignmentMode(const std::string& s) {
  if (s == "none") return AlignmentMode::kNone;
  if (s == "se3") return AlignmentMode::kSe3;
  if (s == "sim3") return AlignmentMode::kSim3;
  throw std::runtime_error("unknown alignment '" + s + "' (expected se3, sim3 or none)");
}

Statistics Summarise(const std::vector<double>& v) {
  Statistics s;
  s.count = v.size();
  if (v.empty()) return s;
  double sum = 0, sq = 0;
  for (double x : v) sum += x, sq += x * x;
  s.mean = sum / double(v.size());
  s.rmse = std::sqrt(sq / double(v.size()));
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  const size_t m = sorted.size() / 2;
  s.median = sorted.size() % 2 ? sorted[m] : 0.5 * (sorted[m - 1] + sorted[m]);
  s.min = sorted.front();
  s.max = sorted.back();
  return s;
}

AteResult ComputeAte(const std::vector<io::StampedPose>& est,
                     const std::vector<io::StampedPose>& ref, AlignmentMode mode) {
  if (est.size() != ref.size()) throw std::runtime_error("ComputeAte: unassociated inputs");
  if (est.size() < 3) throw std::runtime_error("ComputeAte: fewer than 3 associated poses");
  AteResult r;
  std::vector<Vec3> pe, pr;
  for (size_t i = 0; i < est.size(); ++i) {
    pe.push_back(est[i].pose.translation());
    pr.push_back(ref[i].pose.translation());
    r.times_ns.push_back(ref[i].t_ns);
  }
  if (mode != AlignmentMode::kNone) r.alignment = Umeyama(pe, pr, mode == AlignmentMode::kSim3);
  for (size_t i = 0; i < pe.size(); ++i) {
    r.estimate_aligned.push_back(r.alignment * pe[i]);
    r.errors.push_back((pr[i] - r.estimate_aligned.back()).norm());
  }
  r.reference = pr;
  r.translation = Summarise(r.errors);
  return r;
}

namespace {
RpeResult Rpe(const std::vector<io::StampedPose>& est, const std::vector<io::StampedPose>& ref,
              bool by_distance, double delta) {
  if (est.size() != ref.size()) throw std::runtime_error("RPE: unassociated inputs");
  if (!(delta > 0)) throw std::runtime_error("RPE: window must be positive");
  std::vector<double> path(ref.size(), 0.0);
  for (size_t i = 1; i < ref.size(); ++i) {
    path[i] = path[i - 1] + (ref[i].pose.translation() - ref[i - 1].pose.translation()).norm();
  }
  std::vector<double> te, re, pct;
  size_t j = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    j = std::max(j, i + 1);
    if (by_distance) {
      while (j < ref.size() && path[j] - path[i] < delta) ++j;
    } else {
      while (j < ref.size() && 1e-9 * double(ref[j].t_ns - ref[i].t_ns) < delta) ++j;
    }
    if (j >= ref.size()) break;
    const SE3 dref = ref[i].pose.Inverse() * ref[j].pose;
    const SE3 dest = est[i].pose.Inverse() * est[j].pose;
    const SE3 e = dref.Inverse() * dest;
    te.push_back(e.translation().norm());
    re.push_back(so3::Log(e.rotation()).norm() * 180.0 / M_PI);
    if (by_distance) pct.push_back(100.0 * te.back() / (path[j] - path[i]));
  }
  RpeResult r;
  std::ostringstream w;
  w << delta << (by_distance ? " m" : " s");
  r.window = w.str();
  r.translation = Summarise(te);
  r.rotation = Summarise(re);
  if (by_distance) r.translation_percent = Summarise(pct).mean;
  return r;
}
}  // namespace

RpeResult ComputeRpeDistance(const std::vector<io::StampedPose>& est,
                             const std::vector<io::StampedPose>& ref, double meters) {
  return Rpe(est, ref, true, meters);
}

RpeResult ComputeRpeTime(const std::vector<io::StampedPose>& est,
                         const std::vector<io::StampedPose>& ref, double seconds) {
  return Rpe(est, ref, false, seconds);
}

namespace {
std::string Num(double x) {
  char b[32];
  std::snprintf(b, sizeof(b), "%.9g", x);
  return std::isfinite(x) ? b : "null";
}
std::string StatsJson(const Statistics& s) {
  return "{\"count\": " + std::to_string(s.count) + ", \"rmse\": " + Num(s.rmse) +
         ", \"mean\": " + Num(s.mean) + ", \"median\": " + Num(s.median) +
         ", \"min\": " + Num(s.min) + ", \"max\": " + Num(s.max) + "}";
}
std::string Escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o;
}
}  // namespace

std::string ReportText(const Report& r) {
  std::ostringstream o;
  char b[256];
  o << "estimate:  " << r.estimate_path << " (" << r.estimate_poses << " poses)\n"
    << "reference: " << r.reference_path << " (" << r.reference_poses << " poses)\n"
    << "associated " << r.associated << " poses (tolerance " << r.tolerance_s << " s), alignment "
    << r.alignment;
  if (r.alignment == "sim3") o << " (scale " << Num(r.ate.alignment.scale) << ")";
  o << "\n";
  const auto& a = r.ate.translation;
  std::snprintf(b, sizeof(b), "ATE [m]   rmse %.6f  mean %.6f  median %.6f  min %.6f  max %.6f\n",
                a.rmse, a.mean, a.median, a.min, a.max);
  o << b;
  for (const auto& p : r.rpe) {
    std::snprintf(b, sizeof(b), "RPE %-8s trans rmse %.6f m  mean %.6f m", p.window.c_str(),
                  p.translation.rmse, p.translation.mean);
    o << b;
    if (p.window.back() == 'm') {
      std::snprintf(b, sizeof(b), " (%.4f %%)", p.translation_percent);
      o << b;
    }
    std::snprintf(b, sizeof(b), "  rot rmse %.6f deg  (%zu windows)\n", p.rotation.rmse,
                  p.translation.count);
    o << b;
  }
  return o.str();
}

std::string ReportJson(const Report& r) {
  std::ostringstream o;
  const Mat4 T = r.ate.alignment.pose.Matrix();
  o << "{\n  \"estimate\": \"" << Escape(r.estimate_path) << "\",\n  \"reference\": \""
    << Escape(r.reference_path) << "\",\n  \"estimate_poses\": " << r.estimate_poses
    << ",\n  \"reference_poses\": " << r.reference_poses << ",\n  \"associated\": " << r.associated
    << ",\n  \"tolerance_s\": " << Num(r.tolerance_s) << ",\n  \"alignment\": {\"mode\": \""
    << r.alignment << "\", \"scale\": " << Num(r.ate.alignment.scale) << ", \"matrix\": [";
  for (int i = 0; i < 4; ++i) {
    o << (i ? ", " : "") << "[";
    for (int j = 0; j < 4; ++j) o << (j ? ", " : "") << Num(T(i, j));
    o << "]";
  }
  o << "]},\n  \"ate_m\": " << StatsJson(r.ate.translation) << ",\n  \"rpe\": [";
  for (size_t k = 0; k < r.rpe.size(); ++k) {
    const auto& p = r.rpe[k];
    o << (k ? "," : "") << "\n    {\"window\": \"" << p.window
      << "\", \"translation_m\": " << StatsJson(p.translation)
      << ", \"rotation_deg\": " << StatsJson(p.rotation);
    if (p.window.back() == 'm') o << ", \"translation_percent\": " << Num(p.translation_percent);
    o << "}";
  }
  o << "\n  ]\n}\n";
  return o.str();
}

}  // namespace ctlio::eval
