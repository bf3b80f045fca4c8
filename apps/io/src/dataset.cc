#include "ctlio/io/dataset.h"

#include <glog/logging.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "ctlio/factors/imu/saturating_ns.h"
#include "ctlio/io/kitti.h"
#include "ctlio/io/newer_college.h"
#include "ctlio/io/sim_folder.h"
#include "ctlio/io/text_table.h"
#include "ctlio/io/warning_limiter.h"

namespace ctlio::io {

void TakeImuUntil(const std::vector<ImuSample>& imu, int64_t end_ns, size_t* cursor,
                  std::vector<ImuSample>* out) {
  while (*cursor < imu.size() && imu[*cursor].t_ns <= end_ns) out->push_back(imu[(*cursor)++]);
}

std::vector<ImuSample> MergeImuStreams(const std::vector<std::vector<ImuSample>>& streams) {
  std::vector<ImuSample> out;
  size_t total = 0;
  for (const auto& s : streams) total += s.size();
  out.reserve(total);
  for (size_t j = 0; j < streams.size(); ++j) {
    for (ImuSample s : streams[j]) {
      s.imu = int(j);
      out.push_back(s);
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const ImuSample& a, const ImuSample& b) { return a.t_ns < b.t_ns; });
  return out;
}

void RequireFirstImuInBodyFrame(const DataSource& source, const std::string& target) {
  const std::vector<ImuInfo> imus = source.Imus();
  if (imus.empty()) return;
  if (!imus.front().T_body_imu.Matrix().isIdentity(1e-12)) {
    throw std::runtime_error(target +
                             ": this layout holds one IMU in the body frame; the first IMU "
                             "of " +
                             source.Name() + " is mounted elsewhere (use the ctlio layout)");
  }
  if (imus.size() > 1) {
    LOG(WARNING) << target << ": this layout holds one IMU; only the first of the " << imus.size()
                 << " IMUs of " << source.Name() << " is written (the ctlio layout holds all)";
  }
}

size_t DropPointsOutside(const std::string& path, int64_t lo_ns, int64_t hi_ns, PointCloud* c,
                         WarningLimiter* warnings) {
  if (!c->has_times()) return 0;
  size_t kept = 0;
  const size_t n = c->size();
  for (size_t i = 0; i < n; ++i) {
    if (c->times_ns[i] < lo_ns || c->times_ns[i] > hi_ns) continue;
    c->points[kept] = c->points[i];
    c->times_ns[kept] = c->times_ns[i];
    if (c->intensity.size() == n) c->intensity[kept] = c->intensity[i];
    if (c->ring.size() == n) c->ring[kept] = c->ring[i];
    ++kept;
  }
  if (kept == n) return 0;
  if (warnings == nullptr ||
      warnings->Count("points outside the scan interval",
                      path + ": " + std::to_string(n - kept) + " of " + std::to_string(n) +
                          " points outside [" + FormatSecondsNs(lo_ns) + ", " +
                          FormatSecondsNs(hi_ns) + "] s")) {
    LOG(WARNING) << path << ": dropped " << n - kept << " of " << n
                 << " points whose time lies outside the scan interval [" << FormatSecondsNs(lo_ns)
                 << ", " << FormatSecondsNs(hi_ns) << "] s";
  }
  c->points.resize(kept);
  c->times_ns.resize(kept);
  if (c->intensity.size() == n) c->intensity.resize(kept);
  if (c->ring.size() == n) c->ring.resize(kept);
  return n - kept;
}

std::vector<InputDefect> DataSource::InputDefects() const { return {}; }

void CheckImuStream(const std::string& path, const std::vector<int>& lines,
                    int64_t max_gap_error_ns, std::vector<ImuSample>* imu,
                    WarningLimiter* warnings) {
  std::vector<ImuSample> kept;
  kept.reserve(imu->size());
  size_t duplicates = 0;
  WarningLimiter own(path);  // the first few of each kind in full, then totals
  WarningLimiter& limiter = warnings != nullptr ? *warnings : own;
  for (size_t i = 0; i < imu->size(); ++i) {
    const ImuSample& s = (*imu)[i];
    const int line = i < lines.size() ? lines[i] : 0;
    if (!kept.empty()) {
      const int64_t prev = kept.back().t_ns;
      if (s.t_ns == prev) {
        ++duplicates;
        if (limiter.Count("duplicate IMU time", path + ":" + std::to_string(line))) {
          LOG(WARNING) << path << ":" << line << ": duplicate IMU time " << s.t_ns
                       << " ns, sample dropped";
        }
        continue;
      }
      if (s.t_ns < prev) {
        FailAt(path, line,
               "IMU time goes backwards (" + std::to_string(s.t_ns) + " ns after " +
                   std::to_string(prev) + " ns)");
      }
      if (max_gap_error_ns > 0 && SaturatingSubNs(s.t_ns, prev) > max_gap_error_ns) {
        FailAt(path, line,
               "gap of " + std::to_string(1e-9 * double(SaturatingSubNs(s.t_ns, prev))) +
                   " s in the IMU (limit " + std::to_string(1e-9 * double(max_gap_error_ns)) +
                   " s, --max_imu_gap_error)");
      }
    }
    kept.push_back(s);
  }
  if (duplicates > 0) {
    LOG(WARNING) << path << ": dropped " << duplicates << " duplicate IMU sample(s)";
  }
  *imu = std::move(kept);
  // Gaps are reported, not fatal by default: the odometry bridges them with its motion prior.
  // A gap is a spacing above 3× the median spacing.
  std::vector<int64_t> dt;
  for (size_t i = 1; i < imu->size(); ++i)
    dt.push_back(SaturatingSubNs((*imu)[i].t_ns, (*imu)[i - 1].t_ns));
  if (dt.size() < 2) return;
  std::vector<int64_t> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const int64_t median = sorted[sorted.size() / 2];
  for (size_t i = 0; i < dt.size(); ++i) {
    if (dt[i] <= SaturatingAddNs(SaturatingAddNs(median, median), median)) continue;
    if (limiter.Count("IMU gap",
                      path + ":" + std::to_string(i + 1 < lines.size() ? lines[i + 1] : 0))) {
      LOG(WARNING) << path << ":" << (i + 1 < lines.size() ? lines[i + 1] : 0) << ": gap of "
                   << 1e-9 * double(dt[i]) << " s in the IMU (median spacing "
                   << 1e-9 * double(median) << " s); samples handed on";
    }
  }
  own.LogTotals();
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
    if (sec > INT64_MAX / 10000000000) return false;  // sec · 10⁹ would overflow anyway
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
    if (end != s.c_str() + s.size()) return false;
    return SecondsToNs(v, ns);
  }
  for (int k = frac_digits; k < 9; ++k) frac *= 10;
  int64_t v = 0;
  if (!SecNsecToNs(sec, frac, &v)) return false;
  *ns = neg ? -v : v;
  return true;
}

bool SecondsToNs(double s, int64_t* ns) {
  if (!(std::abs(s) < 9.2e9)) return false;  // also rejects NaN
  *ns = std::llround(s * 1e9);
  return true;
}

bool SecNsecToNs(int64_t sec, int64_t nsec, int64_t* ns) {
  if (nsec < 0 || nsec >= 1000000000) return false;
  int64_t s = 0;
  return !__builtin_mul_overflow(sec, int64_t(1000000000), &s) &&
         !__builtin_add_overflow(s, nsec, ns);
}

std::string FormatSecondsNs(int64_t ns) {
  char buf[48];
  const bool neg = ns < 0;
  const uint64_t a = neg ? uint64_t(-(ns + 1)) + 1 : uint64_t(ns);
  constexpr uint64_t kNsPerS = 1000000000;  // uint64_t, as PRIu64 expects (not unsigned long long)
  std::snprintf(buf, sizeof(buf), "%s%" PRIu64 ".%09" PRIu64, neg ? "-" : "", a / kNsPerS,
                a % kNsPerS);
  return buf;
}

namespace {
DatasetFileOpener& FileOpener() {
  static DatasetFileOpener opener = nullptr;
  return opener;
}
}  // namespace

void RegisterDatasetFileOpener(DatasetFileOpener opener) { FileOpener() = opener; }

std::unique_ptr<DataSource> OpenDataset(const std::string& path, int64_t max_imu_gap_error_ns) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // A ROS 2 bag is a folder with metadata.yaml (or one .mcap/.db3 file): the bag opener's.
  if (fs::is_regular_file(path, ec) || fs::is_regular_file(fs::path(path) / "metadata.yaml", ec)) {
    if (FileOpener() != nullptr) return FileOpener()(path, max_imu_gap_error_ns);
    throw std::runtime_error(path +
                             ": a file or ROS 2 bag, not a dataset folder (ROS 1 and ROS 2 bags "
                             "are opened when ctlio::io_rosbag is linked)");
  }
  if (!fs::is_directory(path, ec)) {
    throw std::runtime_error(path + ": dataset folder or bag not found");
  }
  if (fs::exists(fs::path(path) / "ctlio_sim.yaml")) {
    return std::make_unique<SimFolderReader>(path, max_imu_gap_error_ns);
  }
  if (fs::is_directory(fs::path(path) / "raw_format")) {
    NewerCollegeOptions options;
    options.max_imu_gap_error_ns = max_imu_gap_error_ns;
    return std::make_unique<NewerCollegeReader>(path, options);
  }
  if (fs::is_directory(fs::path(path) / "velodyne")) return std::make_unique<KittiReader>(path);
  throw std::runtime_error(path +
                           ": not a dataset folder (no ctlio_sim.yaml, raw_format/ or velodyne/) "
                           "nor a ROS 2 bag folder (no metadata.yaml)");
}

}  // namespace ctlio::io
