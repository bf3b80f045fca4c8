#include "ctlio/io/newer_college.h"

#include <glog/logging.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <stdexcept>

#include "ctlio/factors/imu/saturating_ns.h"
#include "ctlio/io/checked_output.h"
#include "ctlio/io/ground_truth_check.h"
#include "ctlio/io/point_fields.h"
#include "ctlio/io/point_time_check.h"
#include "ctlio/io/text_table.h"
#include "ctlio/io/warning_limiter.h"

namespace ctlio::io {
namespace fs = std::filesystem;

namespace {
fs::path ScanDir(const fs::path& seq) {
  return seq / "raw_format" / "ouster_zip_files" / "ouster_scan";
}
fs::path ImuFile(const fs::path& seq) { return seq / "raw_format" / "ouster_imu" / "data.csv"; }
fs::path GtFile(const fs::path& seq) { return seq / "ground_truth" / "registered_poses.csv"; }

void RequireDir(const fs::path& p) {
  std::error_code ec;
  if (!fs::is_directory(p, ec)) throw std::runtime_error(p.string() + ": folder not found");
}

SE3 PoseFromRow(const std::string& path, const TableRow& row, size_t first) {
  const Vec3 r(ToDouble(path, row, first), ToDouble(path, row, first + 1),
               ToDouble(path, row, first + 2));
  return CheckedGroundTruthPose(ToDouble(path, row, first + 6), ToDouble(path, row, first + 3),
                                ToDouble(path, row, first + 4), ToDouble(path, row, first + 5), r,
                                path + ":" + std::to_string(row.line) + ": ");
}

int64_t StampFromSecNsec(const std::string& path, const TableRow& row, size_t k) {
  const int64_t sec = ToInt64(path, row, k), nsec = ToInt64(path, row, k + 1);
  int64_t ns = 0;
  if (sec < 0 || !SecNsecToNs(sec, nsec, &ns)) {
    FailAt(path, row.line, "sec/nsec out of range (0 <= sec, 0 <= nsec < 1e9, int64 ns)");
  }
  return ns;
}
}  // namespace

SE3 NewerCollegeImuFromLidar() {
  return SE3(Vec3(-1, -1, 1).asDiagonal().toDenseMatrix(), Vec3(-0.006253, 0.011775, 0.028535));
}

bool ParseNewerCollegeScanName(const std::string& name, int64_t* stamp_ns) {
  if (name.size() < 5 || name.substr(name.size() - 4) != ".pcd") return false;
  const std::string base = name.substr(0, name.size() - 4);
  const size_t b = base.rfind('_');
  if (b == std::string::npos || b == 0) return false;
  const size_t a = base.rfind('_', b - 1);
  if (a == std::string::npos) return false;
  const std::string sec = base.substr(a + 1, b - a - 1), nsec = base.substr(b + 1);
  // The nanoseconds are zero-padded to 9 digits (ROS stamps): "cloud_0_5.pcd" is not 5 ns.
  if (sec.empty() || sec.size() > 10 || nsec.size() != 9) return false;
  for (char c : sec + nsec) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  }
  return SecNsecToNs(std::strtoll(sec.c_str(), nullptr, 10),
                     std::strtoll(nsec.c_str(), nullptr, 10), stamp_ns);
}

NewerCollegeReader::NewerCollegeReader(const std::string& folder,
                                       const NewerCollegeOptions& options)
    : warnings_(std::make_shared<WarningLimiter>(folder)), folder_(folder), options_(options) {
  const fs::path seq(folder);
  RequireDir(seq);
  RequireDir(ScanDir(seq));
  for (const auto& e : fs::directory_iterator(ScanDir(seq))) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".pcd") continue;
    int64_t stamp = 0;
    if (!ParseNewerCollegeScanName(name, &stamp)) {
      throw std::runtime_error(e.path().string() +
                               ": scan file name is not <name>_<sec>_<nsec>.pcd (nsec: 9 digits)");
    }
    scans_.emplace_back(stamp, e.path().string());
  }
  if (scans_.empty()) throw std::runtime_error(ScanDir(seq).string() + ": no .pcd scans");
  // Recovery: order by stamp (directory listings are unordered); equal stamps are an error.
  std::sort(scans_.begin(), scans_.end());
  std::vector<int64_t> spacing;
  for (size_t i = 1; i < scans_.size(); ++i) {
    if (scans_[i].first == scans_[i - 1].first) {
      throw std::runtime_error(scans_[i].second + ": same stamp as " + scans_[i - 1].second);
    }
    spacing.push_back(scans_[i].first - scans_[i - 1].first);
  }
  if (!spacing.empty()) {
    std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
    nominal_period_ns_ = spacing[spacing.size() / 2];
  }

  const std::string imu_path = ImuFile(seq).string();
  const auto rows = ReadTable(imu_path, /*skip_header=*/true);
  std::vector<int> lines;
  imu_.reserve(rows.size());
  for (const auto& row : rows) {
    ExpectFields(imu_path, row, 9);
    ImuSample s;
    s.t_ns = StampFromSecNsec(imu_path, row, 1);
    s.gyro = ToVec3(imu_path, row, 3);
    s.accel = ToVec3(imu_path, row, 6);
    imu_.push_back(s);
    lines.push_back(row.line);
  }
  if (imu_.empty()) throw std::runtime_error(imu_path + ": no IMU samples");
  CheckImuStream(imu_path, lines, options_.max_imu_gap_error_ns, &imu_, warnings_.get());

  const std::string gt_path = GtFile(seq).string();
  std::error_code ec;
  if (!fs::is_regular_file(gt_path, ec)) {
    if (options_.require_ground_truth) throw std::runtime_error(gt_path + ": file not found");
    LOG(INFO) << gt_path << ": absent, running without ground truth";
    return;
  }
  for (const auto& row : ReadTable(gt_path, /*skip_header=*/true)) {
    ExpectFields(gt_path, row, 9);
    const int64_t t = StampFromSecNsec(gt_path, row, 0);
    if (!ground_truth_.empty() && t <= ground_truth_.back().t_ns) {
      FailAt(gt_path, row.line, "ground-truth time not increasing");
    }
    ground_truth_.push_back({t, PoseFromRow(gt_path, row, 2)});
  }
}

bool NewerCollegeReader::Next(ScanFrame* frame) {
  if (next_ >= scans_.size()) {
    warnings_->LogTotals();
    return false;
  }
  const auto& [stamp, path] = scans_[next_];
  // The scan's interval: from its stamp to the next scan's stamp (the last scan: one nominal
  // period, the median stamp spacing), with a tolerance for driver jitter.
  const int64_t next_stamp = next_ + 1 < scans_.size()
                                 ? scans_[next_ + 1].first
                                 : CheckedAddNs(stamp, nominal_period_ns_, path);
  const int64_t tolerance = std::max<int64_t>(nominal_period_ns_ / 10, 1);
  ReadOptions ro;
  ro.stamp_ns = stamp;
  ro.require_time = true;
  frame->index = next_;
  try {
    frame->cloud = ReadPcd(path, ro);
  } catch (const UnusableCloudError& e) {
    if (warnings_->Count("unusable scan", e.what())) {
      LOG(WARNING) << e.what() << "; handed on as an empty scan";
    }
    frame->cloud = PointCloud();
    frame->cloud.stamp_ns = stamp;
  }
  PointCloud& c = frame->cloud;
  // Times that cannot be a sweep (point_time_check.h, the rule of every reader): rescaled by a
  // unit factor, or replaced by azimuth times (the Ouster stamps the scan start).
  const PointTimeCheck check = CheckPointTimes(&c, std::max<int64_t>(nominal_period_ns_, 1));
  if (check.verdict != PointTimeCheck::kSweep) {
    const bool azimuth = check.verdict == PointTimeCheck::kNotASweep;
    if (warnings_->Count(azimuth ? "per-point times not a sweep" : "per-point times rescaled",
                         path + ": " + check.reason)) {
      LOG(WARNING) << path << ": " << check.reason
                   << (azimuth ? "; times recovered from the azimuth instead" : "");
    }
    if (azimuth) FillTimesFromAzimuth(&c, StampAt::kScanStart, nominal_period_ns_);
  }
  // Recovery: points whose time lies outside [stamp − tolerance, next stamp + tolerance] cannot be
  // placed on the trajectory between this scan and its neighbours; they are dropped, with a word.
  DropPointsOutside(path, SaturatingSubNs(stamp, tolerance), SaturatingAddNs(next_stamp, tolerance),
                    &c, warnings_.get());
  frame->start_ns = stamp;
  frame->end_ns = stamp;
  for (int64_t t : c.times_ns) frame->end_ns = std::max(frame->end_ns, t);
  if (frame->end_ns <= stamp) {
    // Recovery (the ctlio layout's scans carry their interval in scans.csv): without usable points
    // (empty, all non-finite) or with all points at the stamp the file gives no interval; the
    // scan gets its nominal one, up to the next stamp. An empty scan is reported degenerate by the
    // odometry.
    if (warnings_->Count("scan without an interval", path)) {
      LOG(WARNING) << path << ": " << c.size() << " usable points (" << c.dropped_non_finite
                   << " non-finite), none after the stamp; scan interval set to ["
                   << FormatSecondsNs(stamp) << ", " << FormatSecondsNs(next_stamp) << ") s";
    }
    frame->end_ns = std::max(stamp + 1, next_stamp - 1);
  }
  frame->imu.clear();
  TakeImuUntil(imu_, frame->end_ns, &imu_cursor_, &frame->imu);
  ++next_;
  return true;
}

std::optional<std::vector<StampedPose>> NewerCollegeReader::GroundTruth() const {
  if (ground_truth_.empty()) return std::nullopt;
  return ground_truth_;
}

size_t WriteNewerCollege(DataSource& source, const std::string& folder,
                         const std::function<void(size_t, size_t)>& progress,
                         bool write_ground_truth) {
  // The layout has no place for the extrinsic and the reader assumes the published one: a folder
  // written with another would be read wrongly without a word, so it is refused.
  const SE3 T = source.ImuFromLidar(), published = NewerCollegeImuFromLidar();
  if ((T.Matrix() - published.Matrix()).cwiseAbs().maxCoeff() > 1e-9) {
    throw std::runtime_error(folder +
                             ": the Newer College layout carries no extrinsic and is read with the "
                             "published T_imu_lidar; this source has another one (use the ctlio "
                             "layout, or the published extrinsic)");
  }
  RequireFirstImuInBodyFrame(source, folder + " (Newer College layout)");
  const fs::path seq(folder);
  fs::create_directories(ScanDir(seq));
  fs::create_directories(ImuFile(seq).parent_path());
  std::ofstream imu = OpenForWriting(ImuFile(seq).string());
  imu << "counter,sec,nsec,wx,wy,wz,ax,ay,az\n" << std::setprecision(17);
  size_t counter = 0, n = 0;
  ScanFrame frame;
  while (source.Next(&frame)) {
    for (const ImuSample& s : frame.imu) {
      if (s.imu != 0) continue;  // the layout holds one IMU: the first (Imus()[0])
      imu << counter++ << ',' << s.t_ns / 1000000000 << ',' << s.t_ns % 1000000000;
      for (int k = 0; k < 3; ++k) imu << ',' << s.gyro[k];
      for (int k = 0; k < 3; ++k) imu << ',' << s.accel[k];
      imu << '\n';
    }
    char name[64];
    std::snprintf(name, sizeof(name), "cloud_%lld_%09lld.pcd",
                  static_cast<long long>(frame.start_ns / 1000000000),
                  static_cast<long long>(frame.start_ns % 1000000000));
    WritePcd((ScanDir(seq) / name).string(), frame.cloud);
    ++n;
    if (progress) progress(n, source.NumScans());
  }
  CloseChecked(imu, ImuFile(seq).string());
  if (const auto gt = write_ground_truth ? source.GroundTruth() : std::nullopt) {
    fs::create_directories(GtFile(seq).parent_path());
    std::ofstream out = OpenForWriting(GtFile(seq).string());
    out << "#sec,nsec,x,y,z,qx,qy,qz,qw\n" << std::setprecision(17);
    for (const auto& p : *gt) {
      const Eigen::Quaterniond q = p.pose.quaternion();
      const Vec3& r = p.pose.translation();
      out << p.t_ns / 1000000000 << ',' << p.t_ns % 1000000000 << ',' << r.x() << ',' << r.y()
          << ',' << r.z() << ',' << q.x() << ',' << q.y() << ',' << q.z() << ',' << q.w() << '\n';
    }
    CloseChecked(out, GtFile(seq).string());
  }
  return n;
}

std::vector<InputDefect> NewerCollegeReader::InputDefects() const { return warnings_->Defects(); }

}  // namespace ctlio::io
