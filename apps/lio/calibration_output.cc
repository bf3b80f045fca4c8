#include "lio/calibration_output.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "ctlio/io/checked_output.h"

namespace ctlio::lioapp {

namespace {

// A coordinate's display unit: δ in ms, ρ in cm, φ in degrees (from SI: s, m, rad).
struct Unit {
  const char* name;
  double scale;
};
Unit DisplayUnit(const std::string& coordinate) {
  if (coordinate.rfind("time_offset_", 0) == 0) return {"ms", 1e3};
  if (coordinate.rfind("extrinsic_rho_", 0) == 0) return {"cm", 1e2};
  return {"deg", 180.0 / M_PI};
}

// "0.5 ms (calibration.write_max_sigma_s)": a threshold in the coordinate's display unit.
std::string Threshold(const std::string& coordinate, double threshold) {
  const Unit u = DisplayUnit(coordinate);
  const char* key = coordinate.rfind("time_offset_", 0) == 0     ? "write_max_sigma_s"
                    : coordinate.rfind("extrinsic_rho_", 0) == 0 ? "write_max_sigma_m"
                                                                 : "write_max_sigma_deg";
  std::ostringstream text;
  text << u.scale * threshold << ' ' << u.name << " (calibration." << key << ")";
  return text.str();
}

}  // namespace

const lio::ScanResult* LastCalibration(const RunSummary& run) {
  for (auto it = run.scans.rbegin(); it != run.scans.rend(); ++it) {
    if (!it->calibration.time_offset_s.empty() || it->calibration.has_extrinsic) return &*it;
  }
  return nullptr;
}

// Per coordinate (calibration order; the extrinsic as calibration.csv's left tangent at the
// start): how far the estimate moved from the middle scan of those with a free estimate to the
// last. Scans where a hold prior kept any coordinate (the held pass of the warm-up replay,
// hold_unobservable) do not count: there the value is the hold's, not an estimate.
static std::vector<double> SecondHalfMovement(const RunSummary& run) {
  std::vector<std::vector<double>> x;
  for (const lio::ScanResult& r : run.scans) {
    const auto& c = r.calibration;
    if (c.time_offset_s.empty() && !c.has_extrinsic) continue;
    if (std::find(c.held.begin(), c.held.end(), true) != c.held.end()) continue;
    std::vector<double> v = c.time_offset_s;
    if (c.has_extrinsic) {
      const Vec6 moved = (c.T_imu_lidar * run.initial_extrinsic.Inverse()).Log();
      v.insert(v.end(), moved.data(), moved.data() + 6);
    }
    x.push_back(std::move(v));
  }
  if (x.empty()) return {};
  const std::vector<double>& mid = x[x.size() / 2];
  const std::vector<double>& last = x.back();
  if (mid.size() != last.size()) return {};
  std::vector<double> movement(last.size());
  for (size_t i = 0; i < last.size(); ++i) movement[i] = std::abs(last[i] - mid[i]);
  return movement;
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
  if (last == nullptr) return;
  if (HasObservability(run)) {
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
    out << "\n";
  }
  out << "calibration_kept_at_start";
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
                                                           const lio::CalibrationOptions& options,
                                                           bool keep_uninformed_at_start) {
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
  const Vec6 moved = (r.T_imu_lidar * run.initial_extrinsic.Inverse()).Log();
  r.extrinsic_from_start = moved;
  const std::vector<double> fraction = UnobservableFraction(run);
  const std::vector<double> movement = SecondHalfMovement(run);
  const std::vector<std::string> names = CalibrationCoordinates(c);
  const size_t imus = r.time_offset_s.size();
  const std::vector<double> prior = options.PriorSigmas(static_cast<int>(imus), c.has_extrinsic);
  // Coordinate i: the estimate or the start by RecommendCalibration's rule (1–3); false: start.
  const auto choose = [&](size_t i, double estimate, double sigma, double start, double threshold) {
    CoordinateChoice k;
    k.name = names[i];
    k.estimate = estimate;
    k.sigma = sigma;
    k.start = start;
    k.threshold = threshold;
    k.prior_sigma = i < prior.size() ? prior[i] : NAN;
    if (i < fraction.size()) k.unobservable_fraction = fraction[i];
    // σ = 0 is what a scan without a covariance reports (a failed one): no σ, not a certain one.
    const bool has_sigma = std::isfinite(sigma) && sigma > 0.0;
    const double ratio = sigma / k.prior_sigma;
    const bool assessed = k.unobservable_fraction >= 0.0;
    const bool contradicted =
        assessed && k.unobservable_fraction > options.write_max_unobservable_fraction;
    if (i < movement.size() && has_sigma) k.drift_sigmas = movement[i] / sigma;
    const bool drifting =
        options.write_max_drift_sigmas > 0.0 && k.drift_sigmas > options.write_max_drift_sigmas;
    std::ostringstream why;
    if (!keep_uninformed_at_start) {
      k.estimate_written = true;
      why << "the estimate, as asked (--calibration_keep_unobservable=false)";
    } else if (!has_sigma) {
      why << "the start: the run reported no sigma for it (a failed covariance)";
    } else if (drifting) {
      why << "the start: the estimate moved " << std::setprecision(2) << k.drift_sigmas
          << " sigma over the second half of the run (more than "
             "calibration.write_max_drift_sigmas "
          << options.write_max_drift_sigmas << "): a drift its sigma does not show";
    } else if (sigma < threshold) {
      k.estimate_written = true;
      why << "the estimate: sigma below the threshold, " << Threshold(k.name, threshold);
    } else if (ratio <= options.write_max_sigma_ratio && !contradicted) {
      k.estimate_written = true;
      why << "the estimate: the data informed it, sigma " << std::setprecision(2) << ratio
          << " of the prior's (at most " << options.write_max_sigma_ratio
          << ", calibration.write_max_sigma_ratio)" << (assessed ? "" : "; no observability check");
    } else if (ratio <= options.write_max_sigma_ratio) {
      why << "the start: sigma " << std::setprecision(2) << ratio
          << " of the prior's, but flagged unobservable after more than "
          << std::lround(100.0 * options.write_max_unobservable_fraction)
          << "% of the scans (calibration.write_max_unobservable_fraction): a drift the "
             "window's sigma does not show";
    } else {
      why << "the start: sigma " << std::setprecision(2) << ratio
          << " of the prior's (above calibration.write_max_sigma_ratio "
          << options.write_max_sigma_ratio << ") and not below the threshold, "
          << Threshold(k.name, threshold) << ": the data did not inform it";
    }
    k.reason = why.str();
    k.written = k.estimate_written ? estimate : start;
    if (!k.estimate_written) r.kept_at_start.push_back(k.name);
    r.coordinates.push_back(k);
    return k.estimate_written;
  };
  for (size_t j = 0; j < imus; ++j) {
    const double start = j < run.initial_time_offsets.size() ? run.initial_time_offsets[j] : 0.0;
    const double sigma = j < c.time_offset_sigma_s.size() ? c.time_offset_sigma_s[j] : NAN;
    if (!choose(j, c.time_offset_s[j], sigma, start, options.write_max_sigma_s)) {
      r.time_offset_s[j] = start;
    }
  }
  if (r.has_extrinsic) {
    bool any = false;
    for (int i = 0; i < 6; ++i) {
      const double threshold =
          i < 3 ? options.write_max_sigma_m : M_PI / 180.0 * options.write_max_sigma_deg;
      if (!choose(imus + static_cast<size_t>(i), moved[i], c.extrinsic_sigma[i], 0.0, threshold)) {
        r.extrinsic_from_start[i] = 0.0;
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
  std::ofstream f = io::OpenForWriting(path);
  f << std::setprecision(6);
  f << "# Online calibration of " << run.method << " on " << run.source << " after "
    << 1e-9 * static_cast<double>(last->t_ns - run.scans.front().t_ns) << " s.\n"
    << "# Use it after the config the run used, --config my.yaml,calibration.yaml (later files\n"
    << "# win key by key), or paste the keys at the end into that config\n"
    << "# (docs/user-guide/calibration.md).\n#\n"
    << "# Per coordinate, top-down: the run's last estimate, its marginal sigma, the prior sigma\n"
    << "# the estimate started with, the value the run started from, the value written below and\n"
    << "# why. The estimate is written where its sigma is below the threshold of its kind\n"
    << "# (calibration.write_max_sigma_s, _deg, _m), or where the data informed it: sigma at most\n"
    << "# write_max_sigma_ratio of the prior's and flagged unobservable after at most\n"
    << "# write_max_unobservable_fraction of the scans. Else the start is kept, and also where\n"
    << "# the estimate moved by more than write_max_drift_sigmas sigma over the second half of\n"
    << "# the run (a drift its sigma does not show).\n";
  if (c.has_extrinsic) {
    f << "# The extrinsic's coordinates are [rho; phi] of T_imu_lidar = Exp([rho; phi]) * T_start\n"
      << "# (calibration.csv's), so its start is 0.\n";
  }
  // The truth per coordinate where the source knows it (simulator), in the coordinates' units.
  const size_t imus = c.time_offset_s.size();
  std::optional<Vec6> true_extrinsic;
  if (run.true_extrinsic) {
    true_extrinsic = (*run.true_extrinsic * run.initial_extrinsic.Inverse()).Log();
  }
  const auto truth = [&](size_t i) -> std::optional<double> {
    if (i < imus) {
      return i < run.true_time_offsets.size() ? run.true_time_offsets[i] : std::nullopt;
    }
    if (true_extrinsic) return (*true_extrinsic)[static_cast<int>(i - imus)];
    return std::nullopt;
  };
  for (size_t i = 0; i < recommended.coordinates.size(); ++i) {
    const CoordinateChoice& k = recommended.coordinates[i];
    const Unit u = DisplayUnit(k.name);
    f << "#\n# " << k.name << " [" << u.name << "]\n"
      << "#   estimate     " << u.scale * k.estimate << "\n"
      << "#   sigma        " << u.scale * k.sigma << "\n"
      << "#   prior sigma  " << u.scale * k.prior_sigma << "\n"
      << "#   start        " << u.scale * k.start << "\n";
    if (k.unobservable_fraction >= 0.0) {
      f << "#   flagged      unobservable after " << std::lround(100.0 * k.unobservable_fraction)
        << "% of the scans (the observability check)\n";
    }
    if (std::isfinite(k.drift_sigmas)) {
      f << "#   moved        " << std::setprecision(2) << k.drift_sigmas << std::setprecision(6)
        << " sigma over the second half of the run\n";
    }
    f << "#   written      " << u.scale * k.written << "\n"
      << "#   why          " << k.reason << "\n";
    if (const auto t = truth(i)) {
      f << "#   truth        " << u.scale * *t << " (the written value is off by "
        << u.scale * (k.written - *t) << ")\n";
    }
  }
  f << std::setprecision(9);
  if (imus > 0) {
    f << "calibration:\n  time_offset_s: [";
    for (size_t j = 0; j < recommended.time_offset_s.size(); ++j) {
      f << (j > 0 ? ", " : "") << recommended.time_offset_s[j];
    }
    f << "]\n";
  }
  if (c.has_extrinsic) {
    // The `extrinsic:` section (top level, beside `calibration:`), in the config's own keys:
    // rotation and translation, which win over an xyz_rpy of the config it is put after.
    const SE3& T = recommended.T_imu_lidar;
    if (run.true_extrinsic) {
      const Vec6 err = (T * run.true_extrinsic->Inverse()).Log();
      f << std::setprecision(3) << "# The extrinsic written is off the truth by "
        << 100.0 * err.head<3>().norm() << " cm, " << 180.0 / M_PI * err.tail<3>().norm()
        << " deg.\n"
        << std::setprecision(9);
    }
    f << "extrinsic:\n  rotation: [";
    const Mat3 R = T.rotation();
    for (int i = 0; i < 9; ++i) f << (i > 0 ? ", " : "") << R(i / 3, i % 3);
    const Vec3 p = T.translation();
    f << "]\n  translation: [" << p.x() << ", " << p.y() << ", " << p.z() << "]\n";
  }
  io::CloseChecked(f, path);
  return true;
}

}  // namespace ctlio::lioapp
