#include "lio/calibration_output.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>

#include "ctlio/io/checked_output.h"

namespace ctlio::lioapp {

const lio::ScanResult* LastCalibration(const RunSummary& run) {
  for (auto it = run.scans.rbegin(); it != run.scans.rend(); ++it) {
    if (!it->calibration.time_offset_s.empty() || it->calibration.has_extrinsic) return &*it;
  }
  return nullptr;
}

std::vector<std::string> CalibrationCoordinates(const lio::ScanResult::CalibrationEstimate& c) {
  std::vector<std::string> names;
  for (size_t j = 0; j < c.time_offset_s.size(); ++j) {
    names.push_back("time_offset_" + std::to_string(j));
  }
  if (c.has_extrinsic) {
    for (const char* a : {"x", "y", "z"}) names.push_back(std::string("extrinsic_rho_") + a);
    for (const char* a : {"x", "y", "z"}) names.push_back(std::string("extrinsic_phi_") + a);
  }
  return names;
}

void WriteCoordinateObservability(const lio::ScanResult::CalibrationEstimate& c, size_t i,
                                  std::ostream& out) {
  if (i < c.observability.size() && i < c.unobservable.size()) {
    out << c.observability[i] << ',' << (c.unobservable[i] ? "unobservable" : "observable");
  } else {
    out << "nan,-";
  }
}

void WriteObservabilitySummary(const RunSummary& run,
                               const std::optional<RecommendedCalibration>& recommended,
                               std::ostream& out) {
  const lio::ScanResult* last = LastCalibration(run);
  if (last == nullptr || !HasObservability(run)) return;
  const std::vector<std::string> names = CalibrationCoordinates(last->calibration);
  const std::vector<double> fraction = UnobservableFraction(run);
  const auto& c = last->calibration;
  out << "calibration_unobservable_final";
  bool none = true;
  for (size_t i = 0; i < names.size() && i < c.unobservable.size(); ++i) {
    if (!c.unobservable[i]) continue;
    out << ' ' << names[i];
    none = false;
  }
  out << (none ? " -\n" : "\n") << "calibration_information_final";
  for (size_t i = 0; i < names.size() && i < c.observability.size(); ++i) {
    out << ' ' << names[i] << '=' << c.observability[i];
  }
  out << "\ncalibration_unobservable_fraction";
  for (size_t i = 0; i < names.size() && i < fraction.size(); ++i) {
    out << ' ' << names[i] << '=' << fraction[i];
  }
  out << "\ncalibration_kept_at_start";
  if (!recommended || recommended->kept_at_start.empty()) {
    out << " -";
  }
  if (recommended) {
    for (const std::string& name : recommended->kept_at_start) {
      out << ' ' << name;
    }
  }
  out << "\n";
}

std::optional<RecommendedCalibration> RecommendCalibration(const RunSummary& run,
                                                           bool keep_unobservable_at_start) {
  const lio::ScanResult* last = LastCalibration(run);
  if (last == nullptr) {
    return std::nullopt;
  }
  const auto& c = last->calibration;
  RecommendedCalibration r;
  r.time_offset_s = c.time_offset_s;
  r.has_extrinsic = c.has_extrinsic;
  r.T_imu_lidar = c.has_extrinsic ? c.T_imu_lidar : run.initial_extrinsic;
  // calibration.csv's coordinates: T = Exp([ρ; φ])·T_start (PoseManifold's left tangent).
  r.extrinsic_from_start = (r.T_imu_lidar * run.initial_extrinsic.Inverse()).Log();
  const std::vector<double> fraction =
      keep_unobservable_at_start ? UnobservableFraction(run) : std::vector<double>();
  const std::vector<std::string> names = CalibrationCoordinates(c);
  if (fraction.size() != names.size()) {
    return r;  // not assessed (the check off)
  }
  const auto keep = [&](size_t i) {
    if (!(fraction[i] > kKeepAtStartUnobservableFraction)) {
      return false;
    }
    r.kept_at_start.push_back(names[i]);
    return true;
  };
  const size_t imus = r.time_offset_s.size();
  for (size_t j = 0; j < imus; ++j) {
    if (keep(j)) {
      r.time_offset_s[j] = j < run.initial_time_offsets.size() ? run.initial_time_offsets[j] : 0.0;
    }
  }
  if (r.has_extrinsic) {
    bool any = false;
    for (size_t i = 0; i < 6; ++i) {
      if (keep(imus + i)) {
        r.extrinsic_from_start[static_cast<int>(i)] = 0.0;
        any = true;
      }
    }
    if (any) {
      r.T_imu_lidar = SE3::Exp(r.extrinsic_from_start) * run.initial_extrinsic;
    }
  }
  return r;
}

bool HasObservability(const RunSummary& run) {
  for (const lio::ScanResult& r : run.scans) {
    if (!r.calibration.observability.empty()) return true;
  }
  return false;
}

std::vector<double> UnobservableFraction(const RunSummary& run) {
  std::vector<double> fraction;
  int assessed = 0;
  for (const lio::ScanResult& r : run.scans) {
    const auto& u = r.calibration.unobservable;
    if (u.empty()) continue;
    if (fraction.empty()) fraction.assign(u.size(), 0.0);
    if (u.size() != fraction.size()) continue;
    ++assessed;
    for (size_t i = 0; i < u.size(); ++i) fraction[i] += u[i] ? 1.0 : 0.0;
  }
  for (double& x : fraction) x /= std::max(assessed, 1);
  return fraction;
}

void WriteCalibrationLog(const std::string& path, const RunSummary& run,
                         const std::vector<lio::ScanResult>* scans) {
  const lio::ScanResult* last = LastCalibration(run);
  const size_t imus = last != nullptr ? last->calibration.time_offset_s.size() : 0;
  std::ofstream f = io::OpenForWriting(path);
  f << "t_s";
  for (size_t j = 0; j < imus; ++j) {
    f << ",time_offset_" << j << "_s,time_offset_" << j << "_sigma_s";
  }
  // The extrinsic as its deviation from the starting (configured) value in the tangent of its
  // marginal σ: T_rl = Exp([ρ; φ])·T_rl,start (PoseManifold's left perturbation), φ in degrees.
  const bool extrinsic = last != nullptr && last->calibration.has_extrinsic;
  static const char* kAxes[] = {"x", "y", "z"};
  if (extrinsic) {
    for (const char* a : kAxes)
      f << ",extrinsic_rho_" << a << "_m,extrinsic_rho_" << a << "_sigma_m";
    for (const char* a : kAxes) {
      f << ",extrinsic_phi_" << a << "_deg,extrinsic_phi_" << a << "_sigma_deg";
    }
  }
  // Observability from the measurements alone (calibration_observability.h), per coordinate in
  // the order above: ν over the horizon and whether it is below the threshold.
  const std::vector<std::string> coordinates =
      last != nullptr ? CalibrationCoordinates(last->calibration) : std::vector<std::string>();
  const bool observability = HasObservability(run);
  if (observability) {
    for (const std::string& c : coordinates) f << ',' << c << "_information," << c << "_status";
  }
  // Which coordinates a hold prior kept at their value in the scan's solve (the held pass of a
  // warm-up replay, hold_unobservable): without these the plot cannot tell a held estimate from
  // a converged one. Decided over run.scans as well, so that calibration_live.csv (whose scans a
  // held pass never holds) gets the same columns as calibration.csv.
  const auto holds = [](const std::vector<lio::ScanResult>& results) {
    return std::any_of(results.begin(), results.end(),
                       [](const lio::ScanResult& r) { return !r.calibration.held.empty(); });
  };
  const std::vector<lio::ScanResult>& rows = scans != nullptr ? *scans : run.scans;
  const bool held = holds(run.scans) || (scans != nullptr && holds(*scans));
  if (held) {
    for (const std::string& c : coordinates) f << ',' << c << "_held";
  }
  f << "\n" << std::setprecision(10);
  for (const lio::ScanResult& r : rows) {
    const auto& c = r.calibration;
    if (c.time_offset_s.size() != imus || (imus == 0 && !extrinsic)) continue;
    if (extrinsic && !c.has_extrinsic) continue;
    f << 1e-9 * static_cast<double>(r.t_ns);
    for (size_t j = 0; j < imus; ++j) {
      const double sigma = j < c.time_offset_sigma_s.size() ? c.time_offset_sigma_s[j] : NAN;
      f << ',' << c.time_offset_s[j] << ',' << sigma;
    }
    if (extrinsic) {
      const Vec6 d = (c.T_imu_lidar * run.initial_extrinsic.Inverse()).Log();
      const double deg = 180.0 / M_PI;
      // No σ yet (the initialising scan, or a failed covariance): NaN, not a confident zero.
      const Vec6 sigma = c.extrinsic_sigma.isZero() ? Vec6::Constant(NAN) : c.extrinsic_sigma;
      for (int i = 0; i < 3; ++i) f << ',' << d[i] << ',' << sigma[i];
      for (int i = 3; i < 6; ++i) f << ',' << deg * d[i] << ',' << deg * sigma[i];
    }
    if (observability) {
      // Not assessed (the initialising scan): NaN and "-".
      for (size_t i = 0; i < coordinates.size(); ++i) {
        f << ',';
        WriteCoordinateObservability(c, i, f);
      }
    }
    if (held) {
      for (size_t i = 0; i < coordinates.size(); ++i) {
        f << ',' << (i < c.held.size() && c.held[i] ? 1 : 0);
      }
    }
    f << "\n";
  }
  io::CloseChecked(f, path);
}

bool WriteCalibrationYaml(const std::string& path, const RunSummary& run,
                          const RecommendedCalibration& recommended) {
  const lio::ScanResult* last = LastCalibration(run);
  if (last == nullptr) {
    return false;
  }
  const auto& c = last->calibration;
  const std::vector<std::string> names = CalibrationCoordinates(c);
  const std::vector<double> fraction = UnobservableFraction(run);
  std::ofstream f = io::OpenForWriting(path);
  f << std::setprecision(9);
  f << "# Online calibration of " << run.method << " on " << run.source << " after "
    << 1e-9 * static_cast<double>(last->t_ns - run.scans.front().t_ns) << " s.\n"
    << "# Paste into the odometry config (docs/user-guide/calibration.md).\n";
  if (!recommended.kept_at_start.empty()) {
    f << "# NOT CALIBRATED (unobservable after more than "
      << 100.0 * kKeepAtStartUnobservableFraction
      << "% of the scans: the motion did not excite them), kept at the value the run started "
         "from:";
    for (const std::string& name : recommended.kept_at_start) {
      const auto at = std::find(names.begin(), names.end(), name) - names.begin();
      f << ' ' << name << " (" << std::lround(100.0 * fraction[static_cast<size_t>(at)]) << "%)";
    }
    f << ".\n# Calibrate them on a recording that rotates about every axis "
         "(docs/user-guide/calibration.md).\n";
  }
  for (size_t j = 0; j < c.time_offset_s.size(); ++j) {
    f << "# IMU " << j << ": time offset estimate " << 1e3 * c.time_offset_s[j] << " ms, sigma "
      << (j < c.time_offset_sigma_s.size() ? 1e3 * c.time_offset_sigma_s[j] : NAN) << " ms";
    if (j < run.true_time_offsets.size() && run.true_time_offsets[j]) {
      f << ", truth " << 1e3 * *run.true_time_offsets[j] << " ms, error "
        << 1e3 * (c.time_offset_s[j] - *run.true_time_offsets[j]) << " ms";
    }
    if (recommended.time_offset_s[j] != c.time_offset_s[j]) {
      f << "; written: " << 1e3 * recommended.time_offset_s[j] << " ms (the start)";
    }
    f << "\n";
  }
  if (!c.time_offset_s.empty()) {
    f << "calibration:\n  time_offset_s: [";
    for (size_t j = 0; j < recommended.time_offset_s.size(); ++j) {
      f << (j > 0 ? ", " : "") << recommended.time_offset_s[j];
    }
    f << "]\n";
  }
  io::CloseChecked(f, path);
  if (!c.has_extrinsic) return true;
  // The `extrinsic:` section (top level, beside `calibration:`), in the config's own keys.
  std::ofstream e(path, std::ios::app);
  const Vec6 d = (c.T_imu_lidar * run.initial_extrinsic.Inverse()).Log();
  const Vec6& s = c.extrinsic_sigma;
  const double deg = 180.0 / M_PI;
  e << std::setprecision(9) << "# Extrinsic T_imu_lidar estimate: moved by rho = [" << d[0] << ", "
    << d[1] << ", " << d[2] << "] m, phi = [" << deg * d[3] << ", " << deg * d[4] << ", "
    << deg * d[5] << "] deg from the start; sigma [" << s[0] << ", " << s[1] << ", " << s[2]
    << "] m, [" << deg * s[3] << ", " << deg * s[4] << ", " << deg * s[5] << "] deg";
  if (run.true_extrinsic) {
    const Vec6 err = (c.T_imu_lidar * run.true_extrinsic->Inverse()).Log();
    const Vec6 t = (*run.true_extrinsic * run.initial_extrinsic.Inverse()).Log();
    e << "; error vs truth " << 100.0 * err.head<3>().norm() << " cm, "
      << deg * err.tail<3>().norm() << " deg\n# Extrinsic truth from the start: rho = [" << t[0]
      << ", " << t[1] << ", " << t[2] << "] m, phi = [" << deg * t[3] << ", " << deg * t[4] << ", "
      << deg * t[5] << "] deg";
  }
  const SE3& T = recommended.T_imu_lidar;
  const Vec6& w = recommended.extrinsic_from_start;
  if (w != d) {
    e << "\n# Written (the unobservable axes at the start): rho = [" << w[0] << ", " << w[1] << ", "
      << w[2] << "] m, phi = [" << deg * w[3] << ", " << deg * w[4] << ", " << deg * w[5]
      << "] deg from the start";
    if (run.true_extrinsic) {
      const Vec6 err = (T * run.true_extrinsic->Inverse()).Log();
      e << "; error vs truth " << 100.0 * err.head<3>().norm() << " cm, "
        << deg * err.tail<3>().norm() << " deg";
    }
  }
  e << "\nextrinsic:\n  rotation: [";
  const Mat3 R = T.rotation();
  for (int i = 0; i < 9; ++i) e << (i > 0 ? ", " : "") << R(i / 3, i % 3);
  const Vec3 p = T.translation();
  e << "]\n  translation: [" << p.x() << ", " << p.y() << ", " << p.z() << "]\n";
  io::CloseChecked(e, path);
  return true;
}

}  // namespace ctlio::lioapp
