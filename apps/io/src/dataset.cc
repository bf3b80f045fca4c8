#include "ctlio/io/dataset.h"

#include <glog/logging.h>

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "ctlio/io/kitti.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/io/text_table.h"

namespace ctlio::io {

void TakeImuUntil(const std::vector<ImuSample>& imu, int64_t end_ns, size_t* cursor,
                  std::vector<ImuSample>* out) {
  while (*cursor < imu.size() && imu[*cursor].t_ns <= end_ns) out->push_back(imu[(*cursor)++]);
}

void CheckImuStream(const std::string& path, const std::vector<int>& lines, int64_t max_gap_ns,
                    std::vector<ImuSample>* imu) {
  std::vector<ImuSample> kept;
  kept.reserve(imu->size());
  size_t duplicates = 0;
  for (size_t i = 0; i < imu->size(); ++i) {
    const ImuSample& s = (*imu)[i];
    const int line = i < lines.size() ? lines[i] : 0;
    if (!kept.empty()) {
      const int64_t prev = kept.back().t_ns;
      if (s.t_ns == prev) {
        ++duplicates;
        LOG(WARNING) << path << ":" << line << ": duplicate IMU time " << s.t_ns
                     << " ns, sample dropped";
        continue;
      }
      if (s.t_ns < prev) {
        FailAt(path, line,
               "IMU time goes backwards (" + std::to_string(s.t_ns) + " ns after " +
                   std::to_string(prev) + " ns)");
      }
      if (max_gap_ns > 0 && s.t_ns - prev > max_gap_ns) {
        FailAt(path, line,
               "gap of " + std::to_string(1e-9 * double(s.t_ns - prev)) + " s in the IMU (limit " +
                   std::to_string(1e-9 * double(max_gap_ns)) + " s)");
      }
    }
    kept.push_back(s);
  }
  if (duplicates > 0) {
    LOG(WARNING) << path << ": dropped " << duplicates << " duplicate IMU sample(s)";
  }
  *imu = std::move(kept);
}

bool ParseSecondsNs(const std::string& s, int64_t* ns) {
  if (s.empty()) return false;
  size_t i = 0;
  bool neg = false;
  if (s[0] == '-' || s[0] == '+') {
    neg = s[0] == '-';
    i = 1;
  }
  int64_t sec = 0, frac = 0;
  int digits = 0, frac_digits = 0;
  for (; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i, ++digits) {
    if (sec > (INT64_MAX / 10 - 10) / 1000000000) return false;
    sec = sec * 10 + (s[i] - '0');
  }
  if (i < s.size() && s[i] == '.') {
    for (++i; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i, ++frac_digits) {
      if (frac_digits < 9) frac = frac * 10 + (s[i] - '0');
    }
  }
  if (i != s.size() || digits + frac_digits == 0) {
    // Not plain decimal (e.g. 1.5e9): accept through double as a last resort.
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || !std::isfinite(v)) return false;
    *ns = std::llround(v * 1e9);
    return true;
  }
  for (int k = frac_digits; k < 9; ++k) frac *= 10;
  *ns = (neg ? -1 : 1) * (sec * 1000000000 + frac);
  return true;
}

std::string FormatSecondsNs(int64_t ns) {
  char buf[48];
  const bool neg = ns < 0;
  const uint64_t a = neg ? uint64_t(-(ns + 1)) + 1 : uint64_t(ns);
  std::snprintf(buf, sizeof(buf), "%s%" PRIu64 ".%09" PRIu64, neg ? "-" : "", a / 1000000000ULL,
                a % 1000000000ULL);
  return buf;
}

std::unique_ptr<DataSource> OpenDataset(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw std::runtime_error(folder + ": folder not found");
  if (fs::exists(fs::path(folder) / "ctlio_sim.yaml")) {
    return std::make_unique<SimFolderReader>(folder);
  }
  if (fs::is_directory(fs::path(folder) / "raw_format")) {
    return std::make_unique<NewerCollegeReader>(folder);
  }
  if (fs::is_directory(fs::path(folder) / "velodyne")) return std::make_unique<KittiReader>(folder);
  throw std::runtime_error(folder +
                           ": not a dataset folder (no ctlio_sim.yaml, raw_format/ or velodyne/)");
}

}  // namespace ctlio::io
