#include "run_outputs.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "ctlio/io/checked_output.h"

namespace ctlio::lioapp {

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
  // Square frame around the data with a "nice" tick step (1, 2 or 5 × 10^k m).
  const double span = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1e-3}) * 1.1;
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  lo = centre - Eigen::Vector2d::Constant(span / 2);
  const double raw_step = span / 5, mag = std::pow(10.0, std::floor(std::log10(raw_step)));
  const double step = raw_step / mag < 2 ? 2 * mag : raw_step / mag < 5 ? 5 * mag : 10 * mag;
  // Title wrapped into lines of at most 80 characters so that it is never cut off.
  std::vector<std::string> lines(1);
  std::istringstream words(title);
  for (std::string w; words >> w;) {
    if (!lines.back().empty() && lines.back().size() + 1 + w.size() > 80) lines.emplace_back();
    while (w.size() > 80) {  // a word longer than a line (a long path) is cut
      lines.back() += w.substr(0, 80);
      lines.emplace_back();
      w.erase(0, 80);
    }
    lines.back() += (lines.back().empty() ? "" : " ") + w;
  }
  const double left = 70, top = 30 + 18.0 * double(lines.size()), size = 520;
  const double scale = size / span;
  auto X = [&](double x) { return left + (x - lo.x()) * scale; };
  auto Y = [&](double y) { return top + size - (y - lo.y()) * scale; };
  auto polyline = [&](const std::vector<Vec3>& v, const char* colour, double width) {
    std::ostringstream s;
    s << "<polyline fill='none' stroke='" << colour << "' stroke-width='" << width << "' points='";
    for (const Vec3& p : v) s << X(p.x()) << ',' << Y(p.y()) << ' ';
    s << "'/>\n";
    return s.str();
  };
  std::ofstream f = io::OpenForWriting(path);
  f << "<svg xmlns='http://www.w3.org/2000/svg' width='" << left + size + 30 << "' height='"
    << top + size + 60 << "' font-family='sans-serif'>\n<rect width='100%' height='100%' "
    << "fill='white'/>\n";
  for (size_t i = 0; i < lines.size(); ++i) {
    f << "<text x='10' y='" << 22 + 18 * i << "' font-size='14'>" << lines[i] << "</text>\n";
  }
  f << "<rect x='" << left << "' y='" << top << "' width='" << size << "' height='" << size
    << "' fill='none' stroke='black'/>\n";
  for (double v = std::ceil(lo.x() / step) * step; v <= lo.x() + span; v += step) {
    f << "<text x='" << X(v) << "' y='" << top + size + 16 << "' font-size='11' "
      << "text-anchor='middle'>" << (std::abs(v) < 1e-9 * step ? 0.0 : v) << "</text>\n";
  }
  for (double v = std::ceil(lo.y() / step) * step; v <= lo.y() + span; v += step) {
    f << "<text x='" << left - 5 << "' y='" << Y(v) + 4 << "' font-size='11' "
      << "text-anchor='end'>" << (std::abs(v) < 1e-9 * step ? 0.0 : v) << "</text>\n";
  }
  f << "<text x='" << left + size / 2 << "' y='" << top + size + 34
    << "' font-size='12' text-anchor='middle'>x [m]</text>\n<text x='15' y='" << top + size / 2
    << "' font-size='12'>y [m]</text>\n"
    << polyline(ref, "#888888", 3) << polyline(est, "#d62728", 1.5) << "<text x='" << left + 10
    << "' y='" << top + 18 << "' font-size='12' fill='#888888'>ground truth</text>\n<text x='"
    << left + 10 << "' y='" << top + 34
    << "' font-size='12' fill='#d62728'>estimate (scan poses, aligned)</text>\n</svg>\n";
  io::CloseChecked(f, path);
}

void WriteScanLog(const std::string& path, const RunSummary& run) {
  std::ofstream f = io::OpenForWriting(path);
  // Two notions (evaluation.txt and the summary use the same names): status `degenerate` (the
  // lidar did not fix the pose: degenerate_scans) and degen_dirs > 0 (the lidar term had a
  // degenerate direction, whatever the status: degenerate_direction_scans).
  f << "# status degenerate: the lidar did not fix the pose (evaluation.txt degenerate_scans); "
       "degen_dirs > 0: the lidar term had a degenerate direction, whatever the status "
       "(evaluation.txt degenerate_direction_scans)\n";
  f << "# t_s status keypoints associations imu_residuals rounds solver_iterations final_cost "
       "ms ms_preprocess ms_associate ms_solve ms_map ms_marginalize cpu_ms x y z imu_rejected "
       "points_dropped degen_t_min degen_r_min degen_dirs degen_dir degen_lidar_info "
       "degen_prior_info accel_chi2 accel_dof gyro_chi2 gyro_dof correction_m correction_rad "
       "message\n";
  f << std::setprecision(12);
  for (size_t i = 0; i < run.scans.size(); ++i) {
    const lio::ScanResult& r = run.scans[i];
    const Vec3 p = r.T_mr.translation();
    f << 1e-9 * double(r.t_ns) << ' ' << lio::ScanStatusName(r.status) << ' ' << r.keypoints << ' '
      << r.associations << ' ' << r.imu_residuals << ' ' << r.rounds << ' ' << r.solver_iterations
      << ' ' << r.final_cost << ' ' << r.milliseconds << ' ' << r.ms_preprocess << ' '
      << r.ms_associate << ' ' << r.ms_solve << ' ' << r.ms_map << ' ' << r.ms_marginalize << ' '
      << r.cpu_ms << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << r.imu_rejected << ' '
      << r.points_dropped << ' ';
    const lio::DegeneracyReport& d = r.degeneracy;
    if (d.analysed) {
      f << d.translation_eigenvalues[0] << ' ' << d.rotation_eigenvalues[0] << ' '
        << d.num_degenerate() << ' ' << d.DirectionString() << ' ';
      if (d.num_degenerate() > 0) {
        f << d.lidar_information << ' ' << d.prior_information << ' ';
      } else {
        f << "- - ";
      }
    } else {
      f << "- - - - - - ";
    }
    f << r.accel_chi2 << ' ' << r.accel_dof << ' ' << r.gyro_chi2 << ' ' << r.gyro_dof << ' '
      << r.correction_m << ' ' << r.correction_rad << ' '
      << (r.message.empty() ? "-" : "\"" + r.message + "\"") << '\n';
  }
  io::CloseChecked(f, path);
}

}  // namespace ctlio::lioapp
