#include "lio/calibration_output.h"

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

void WriteCalibrationLog(const std::string& path, const RunSummary& run) {
  const lio::ScanResult* last = LastCalibration(run);
  const size_t imus = last != nullptr ? last->calibration.time_offset_s.size() : 0;
  std::ofstream f = io::OpenForWriting(path);
  f << "t_s";
  for (size_t j = 0; j < imus; ++j) {
    f << ",time_offset_" << j << "_s,time_offset_" << j << "_sigma_s";
  }
  // (The extrinsic's columns follow here.)
  f << "\n" << std::setprecision(10);
  for (const lio::ScanResult& r : run.scans) {
    const auto& c = r.calibration;
    if (c.time_offset_s.size() != imus || imus == 0) continue;
    f << 1e-9 * static_cast<double>(r.t_ns);
    for (size_t j = 0; j < imus; ++j) {
      const double sigma = j < c.time_offset_sigma_s.size() ? c.time_offset_sigma_s[j] : NAN;
      f << ',' << c.time_offset_s[j] << ',' << sigma;
    }
    f << "\n";
  }
  io::CloseChecked(f, path);
}

bool WriteCalibrationYaml(const std::string& path, const RunSummary& run) {
  const lio::ScanResult* last = LastCalibration(run);
  if (last == nullptr) return false;
  const auto& c = last->calibration;
  std::ofstream f = io::OpenForWriting(path);
  f << std::setprecision(9);
  f << "# Online calibration of " << run.method << " on " << run.source << " after "
    << 1e-9 * static_cast<double>(last->t_ns - run.scans.front().t_ns) << " s.\n"
    << "# Paste into the odometry config (README \"Online calibration\").\n";
  if (!c.time_offset_s.empty()) {
    for (size_t j = 0; j < c.time_offset_s.size(); ++j) {
      f << "# IMU " << j << ": time offset " << 1e3 * c.time_offset_s[j] << " ms, sigma "
        << (j < c.time_offset_sigma_s.size() ? 1e3 * c.time_offset_sigma_s[j] : NAN) << " ms";
      if (j < run.true_time_offsets.size() && run.true_time_offsets[j]) {
        f << ", truth " << 1e3 * *run.true_time_offsets[j] << " ms, error "
          << 1e3 * (c.time_offset_s[j] - *run.true_time_offsets[j]) << " ms";
      }
      f << "\n";
    }
  }
  f << "calibration:\n";
  if (!c.time_offset_s.empty()) {
    f << "  time_offset_s: [";
    for (size_t j = 0; j < c.time_offset_s.size(); ++j) {
      f << (j > 0 ? ", " : "") << c.time_offset_s[j];
    }
    f << "]\n";
  }
  // (The extrinsic's snippet follows here.)
  io::CloseChecked(f, path);
  return true;
}

}  // namespace ctlio::lioapp
