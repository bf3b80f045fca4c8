#include "ctlio/io/kitti.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "ctlio/factors/imu/saturating_ns.h"
#include "ctlio/io/point_fields.h"
#include "ctlio/io/point_time_check.h"
#include "ctlio/io/text_table.h"
#include "ctlio/io/trajectory_io.h"
#include "ctlio/io/warning_limiter.h"

namespace ctlio::io {
namespace fs = std::filesystem;
namespace {

// "<dir>/<stem>.txt" and then every "<dir>/<stem>_*.txt", sorted.
std::vector<std::string> FindTxts(const fs::path& dir, const std::string& stem) {
  std::vector<std::string> others;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(stem + "_", 0) == 0 && e.path().extension() == ".txt") {
      others.push_back(e.path().string());
    }
  }
  std::sort(others.begin(), others.end());
  std::vector<std::string> found;
  if (fs::is_regular_file(dir / (stem + ".txt"))) found.push_back((dir / (stem + ".txt")).string());
  found.insert(found.end(), others.begin(), others.end());
  return found;
}

std::string FindTxt(const fs::path& dir, const std::string& stem) {
  const auto found = FindTxts(dir, stem);
  return found.empty() ? "" : found.front();
}

}  // namespace

KittiReader::KittiReader(const std::string& folder)
    : warnings_(std::make_shared<WarningLimiter>(folder)), folder_(folder) {
  const fs::path dir(folder);
  std::error_code ec;
  if (!fs::is_directory(dir / "velodyne", ec)) {
    throw std::runtime_error((dir / "velodyne").string() + ": folder not found");
  }
  for (const auto& e : fs::directory_iterator(dir / "velodyne")) {
    if (e.path().extension() == ".bin") scans_.push_back(e.path().string());
  }
  std::sort(scans_.begin(), scans_.end());  // zero-padded indices: name order = time order
  if (scans_.empty()) throw std::runtime_error((dir / "velodyne").string() + ": no .bin scans");
  const bool xyz =
      scans_.front().size() > 8 && scans_.front().substr(scans_.front().size() - 8) == "_xyz.bin";
  floats_per_point_ = xyz ? 3 : 4;

  const std::string times_path = FindTxt(dir, "times");
  if (times_path.empty()) throw std::runtime_error(folder + ": no times.txt");
  for (const auto& row : ReadTable(times_path, false)) {
    ExpectFields(times_path, row, 1);
    int64_t t = 0;
    if (!ParseSecondsNs(row.fields[0], &t)) FailAt(times_path, row.line, "not a time");
    if (!times_.empty() && t <= times_.back()) {
      FailAt(times_path, row.line, "scan time not increasing (scans out of order)");
    }
    times_.push_back(t);
  }
  if (times_.size() < scans_.size()) {
    throw std::runtime_error(times_path + ": " + std::to_string(times_.size()) + " times for " +
                             std::to_string(scans_.size()) + " scans");
  }
  for (const auto& s : scans_) {
    const fs::path p = dir / "velodyne_times" / fs::path(s).filename();
    point_times_.push_back(fs::is_regular_file(p, ec) ? p.string() : "");
  }

  const std::string poses_path = FindTxt(dir, "poses");
  if (!poses_path.empty()) {
    std::vector<StampedPose> cam = ReadKittiPoses(poses_path);
    SE3 Tr;  // velodyne → cam0, from the first calib*.txt with a "Tr:" line
    bool have_tr = false;
    for (const std::string& calib_path : FindTxts(dir, "calib")) {
      if (have_tr) break;
      for (const auto& row : ReadTable(calib_path, false)) {
        if (row.fields.empty() || row.fields[0] != "Tr:") continue;
        ExpectFields(calib_path, row, 13);
        Mat3 C;
        Vec3 r;
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) C(a, b) = ToDouble(calib_path, row, 1 + 4 * a + b);
          r[a] = ToDouble(calib_path, row, 1 + 4 * a + 3);
        }
        Tr = SE3(Eigen::Quaterniond(C).normalized().toRotationMatrix(), r);
        have_tr = true;
      }
    }
    if (!have_tr) {
      LOG(WARNING) << folder << ": no calib.txt, ground truth left in the cam0 frame";
    }
    for (size_t i = 0; i < cam.size() && i < times_.size(); ++i) {
      ground_truth_.push_back({times_[i], Tr.Inverse() * cam[i].pose * Tr});
    }
  }
}

bool KittiReader::Next(ScanFrame* frame) {
  if (next_ >= scans_.size()) {
    warnings_->LogTotals();
    return false;
  }
  const int64_t stamp = times_[next_];
  constexpr int64_t kPeriod = 100'000'000;  // HDL-64E at 10 Hz
  frame->index = next_;
  const std::string& path = scans_[next_];
  try {
    frame->cloud = ReadKittiBin(path, floats_per_point_, point_times_[next_], stamp);
  } catch (const UnusableCloudError& e) {
    if (warnings_->Count("unusable scan", e.what())) {
      LOG(WARNING) << e.what() << "; handed on as an empty scan";
    }
    frame->cloud = PointCloud();
    frame->cloud.stamp_ns = stamp;
  }
  auto& c = frame->cloud;
  bool from_azimuth = point_times_[next_].empty();
  if (!from_azimuth) {
    // The rules of every reader (point_time_check.h): times that cannot be a 0.1 s sweep are
    // rescaled by a unit factor or replaced by azimuth times; points timed more than a period
    // from the stamp are dropped (they used to stretch the scan over seconds).
    const PointTimeCheck check = CheckPointTimes(&c, kPeriod);
    if (check.verdict != PointTimeCheck::kSweep) {
      from_azimuth = check.verdict == PointTimeCheck::kNotASweep;
      if (warnings_->Count(
              from_azimuth ? "per-point times not a sweep" : "per-point times rescaled",
              point_times_[next_] + ": " + check.reason)) {
        LOG(WARNING) << point_times_[next_] << ": " << check.reason
                     << (from_azimuth ? "; times recovered from the azimuth instead" : "");
      }
    }
    if (!from_azimuth) {
      DropPointsOutside(point_times_[next_], SaturatingSubNs(stamp, kPeriod + kPeriod / 10),
                        SaturatingAddNs(stamp, kPeriod + kPeriod / 10), &c, warnings_.get());
    }
  }
  if (from_azimuth) {
    static bool logged = false;
    if (!logged && point_times_[next_].empty()) {
      LOG(INFO) << folder_ << ": no per-point times, filled from the azimuth (see kitti.h)";
      logged = true;
    }
    // KITTI stamps a sweep when the scanner faces forward (azimuth 0): the sweep begins half a
    // revolution earlier, facing backwards.
    c.times_ns.resize(c.size());
    // The sweep [stamp − P/2, stamp + P/2) must be representable (a stamp near the int64 limits).
    const int64_t sweep_begin = CheckedAddNs(stamp, -kPeriod / 2, path);
    CheckedAddNs(sweep_begin, kPeriod, path);
    for (size_t i = 0; i < c.size(); ++i) {
      c.times_ns[i] = sweep_begin + AzimuthOffsetNs(c.points[i], M_PI, kPeriod);
    }
  }
  frame->start_ns = c.times_ns.empty()
                        ? stamp
                        : std::min(stamp, *std::min_element(c.times_ns.begin(), c.times_ns.end()));
  c.stamp_ns = frame->start_ns;
  frame->end_ns = c.times_ns.empty() ? frame->start_ns
                                     : *std::max_element(c.times_ns.begin(), c.times_ns.end());
  if (frame->end_ns <= frame->start_ns) {
    // Recovery shared with the other layouts: without usable points (empty, all non-finite) or
    // with all points at one time the scan gets its nominal interval, up to the next stamp.
    if (warnings_->Count("scan without an interval", path)) {
      LOG(WARNING) << path << ": " << c.size() << " usable points (" << c.dropped_non_finite
                   << " non-finite), all at one time; scan interval set to its nominal 0.1 s";
    }
    const int64_t nominal_end = CheckedAddNs(stamp, kPeriod, path);
    const int64_t next_stamp = next_ + 1 < times_.size() ? times_[next_ + 1] : nominal_end;
    frame->end_ns = std::max(frame->start_ns + 1, std::min(nominal_end, next_stamp - 1));
  }
  frame->imu.clear();
  ++next_;
  return true;
}

std::optional<std::vector<StampedPose>> KittiReader::GroundTruth() const {
  if (ground_truth_.empty()) return std::nullopt;
  return ground_truth_;
}

std::vector<InputDefect> KittiReader::InputDefects() const { return warnings_->Defects(); }

}  // namespace ctlio::io
