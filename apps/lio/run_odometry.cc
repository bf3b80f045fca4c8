#include "run_odometry.h"

#include <sys/resource.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "ctlio/solvers/lio/lio_odometry.h"

namespace ctlio::lioapp {

// Process-wide high-water mark of the resident set (getrusage ru_maxrss, kB on Linux).
long PeakRssKb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return usage.ru_maxrss;
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double idx = p * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(idx));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (idx - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

AteResult EvaluateAte(const std::vector<io::StampedPose>& estimate,
                      const std::vector<io::StampedPose>& truth) {
  AteResult r;
  if (truth.size() < 2) return r;
  std::vector<Vec3> est, ref;
  for (const io::StampedPose& e : estimate) {
    const auto it =
        std::lower_bound(truth.begin(), truth.end(), e.t_ns,
                         [](const io::StampedPose& p, int64_t t) { return p.t_ns < t; });
    Vec3 p;
    if (it != truth.end() && std::llabs(it->t_ns - e.t_ns) <= 1000000) {
      p = it->pose.translation();
    } else if (it != truth.begin() && it != truth.end() && it->t_ns - (it - 1)->t_ns < 200000000) {
      const double s = double(e.t_ns - (it - 1)->t_ns) / double(it->t_ns - (it - 1)->t_ns);
      p = (1 - s) * (it - 1)->pose.translation() + s * it->pose.translation();
    } else if (it != truth.begin() && std::llabs((it - 1)->t_ns - e.t_ns) <= 1000000) {
      p = (it - 1)->pose.translation();
    } else {
      continue;
    }
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

RunSummary RunOdometry(io::DataSource& source, lio::OdometryConfig config,
                       const RunOptions& options, double failure_ate) {
  // The source knows its sensor setup; it overrides the config's.
  config.T_imu_lidar = source.ImuFromLidar();
  if (const auto g = source.Gravity()) config.gravity = *g;
  auto odometry = lio::MakeLioOdometry(config);
  RunSummary run;
  run.method = lio::LioMethodName(config.method);
  run.source = source.Name();
  const SE3 T_imu_lidar = config.T_imu_lidar;
  const size_t total = options.max_scans > 0
                           ? (source.NumScans() > 0 ? std::min(options.max_scans, source.NumScans())
                                                    : options.max_scans)
                           : source.NumScans();
  io::ScanFrame frame;
  std::vector<double> ms;
  size_t done = 0;
  while ((options.max_scans == 0 || done < options.max_scans) && source.Next(&frame)) {
    for (const io::ImuSample& s : frame.imu) odometry->AddImu(s);
    lio::LidarScan scan;
    scan.begin_ns = frame.start_ns;
    scan.end_ns = frame.end_ns;
    scan.points = std::move(frame.cloud.points);
    scan.times_ns = std::move(frame.cloud.times_ns);
    if (scan.times_ns.empty()) scan.times_ns.assign(scan.points.size(), scan.end_ns);
    const lio::ScanResult r = odometry->AddScan(scan);
    ++done;
    ms.push_back(r.milliseconds);
    switch (r.status) {
      case lio::ScanStatus::kFailed:
        if (odometry->initialised() || done > 1) {
          ++run.failed;
          if (run.first_failure.empty()) run.first_failure = r.message;
        }
        break;
      case lio::ScanStatus::kDegenerate:
        ++run.degenerate;
        break;
      case lio::ScanStatus::kImuGap:
        ++run.imu_gaps;
        break;
      default:
        break;
    }
    if (r.status != lio::ScanStatus::kFailed) {
      run.trajectory.push_back({r.t_ns, r.T_mr * T_imu_lidar});
    }
    run.scans.push_back(r);
    if (options.progress) options.progress(done, total, r);
  }
  // The first scan (map creation) is not a registration: keep it out of the latency figures.
  std::vector<double> reg(ms.begin() + std::min<size_t>(1, ms.size()), ms.end());
  run.median_ms = Percentile(reg, 0.5);
  run.p95_ms = Percentile(reg, 0.95);
  run.max_ms = reg.empty() ? 0.0 : *std::max_element(reg.begin(), reg.end());
  {
    std::vector<double> cpu, pre, assoc, solve, map, marg;
    for (size_t i = 1; i < run.scans.size(); ++i) {
      const lio::ScanResult& r = run.scans[i];
      cpu.push_back(r.cpu_ms);
      pre.push_back(r.ms_preprocess);
      assoc.push_back(r.ms_associate);
      solve.push_back(r.ms_solve);
      map.push_back(r.ms_map);
      marg.push_back(r.ms_marginalize);
    }
    run.median_cpu_ms = Percentile(cpu, 0.5);
    run.p95_cpu_ms = Percentile(cpu, 0.95);
    run.median_preprocess_ms = Percentile(pre, 0.5);
    run.median_associate_ms = Percentile(assoc, 0.5);
    run.median_solve_ms = Percentile(solve, 0.5);
    run.median_map_ms = Percentile(map, 0.5);
    run.median_marginalize_ms = Percentile(marg, 0.5);
  }
  run.peak_rss_kb = PeakRssKb();
  if (const auto truth = source.GroundTruth()) {
    run.ate = EvaluateAte(run.trajectory, *truth);
  }
  run.failure =
      run.failed > 0 || (run.ate && !(run.ate->rmse <= failure_ate)) || run.trajectory.size() < 2;
  return run;
}

void WriteTopViewSvg(const std::string& path, const std::vector<io::StampedPose>& estimate,
                     const std::vector<io::StampedPose>& truth, const Eigen::Matrix4d& alignment,
                     const std::string& title) {
  std::vector<Vec3> est, ref;
  for (const auto& p : estimate) {
    est.push_back(alignment.topLeftCorner<3, 3>() * p.pose.translation() +
                  alignment.topRightCorner<3, 1>());
  }
  const int64_t t0 = estimate.empty() ? 0 : estimate.front().t_ns;
  const int64_t t1 = estimate.empty() ? 0 : estimate.back().t_ns;
  for (const auto& p : truth) {
    if (p.t_ns >= t0 && p.t_ns <= t1) ref.push_back(p.pose.translation());
  }
  Eigen::Vector2d lo(1e18, 1e18), hi(-1e18, -1e18);
  for (const auto* v : {&est, &ref}) {
    for (const Vec3& p : *v) {
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
    }
  }
  const double span = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1e-3});
  const double size = 600, margin = 40, scale = (size - 2 * margin) / span;
  auto polyline = [&](const std::vector<Vec3>& v, const char* colour, double width) {
    std::ostringstream s;
    s << "<polyline fill='none' stroke='" << colour << "' stroke-width='" << width << "' points='";
    for (const Vec3& p : v) {
      s << margin + (p.x() - lo.x()) * scale << ',' << size - margin - (p.y() - lo.y()) * scale
        << ' ';
    }
    s << "'/>\n";
    return s.str();
  };
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write the plot");
  f << "<svg xmlns='http://www.w3.org/2000/svg' width='" << size << "' height='" << size + 30
    << "'>\n<rect width='100%' height='100%' fill='white'/>\n"
    << "<text x='10' y='20' font-family='sans-serif' font-size='14'>" << title
    << " (top view; grey: ground truth, red: estimate; frame " << span << " m)</text>\n"
    << polyline(ref, "#888888", 3) << polyline(est, "#d62728", 1.5) << "</svg>\n";
}

void WriteScanLog(const std::string& path, const RunSummary& run) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write the scan log");
  f << "# t_s status keypoints associations imu_residuals rounds solver_iterations final_cost "
       "ms ms_preprocess ms_associate ms_solve ms_map ms_marginalize cpu_ms x y z message\n";
  f << std::setprecision(12);
  for (const lio::ScanResult& r : run.scans) {
    const Vec3 p = r.T_mr.translation();
    f << 1e-9 * double(r.t_ns) << ' ' << lio::ScanStatusName(r.status) << ' ' << r.keypoints << ' '
      << r.associations << ' ' << r.imu_residuals << ' ' << r.rounds << ' ' << r.solver_iterations
      << ' ' << r.final_cost << ' ' << r.milliseconds << ' ' << r.ms_preprocess << ' '
      << r.ms_associate << ' ' << r.ms_solve << ' ' << r.ms_map << ' ' << r.ms_marginalize << ' '
      << r.cpu_ms << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' '
      << (r.message.empty() ? "-" : "\"" + r.message + "\"") << '\n';
  }
}

}  // namespace ctlio::lioapp
