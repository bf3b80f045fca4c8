#include "ctlio/io/sim_folder.h"

#include <glog/logging.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <stdexcept>

#include "ctlio/factors/imu/saturating_ns.h"
#include "ctlio/io/checked_output.h"
#include "ctlio/io/extrinsic_check.h"
#include "ctlio/io/ground_truth_check.h"
#include "ctlio/io/point_fields.h"
#include "ctlio/io/point_time_check.h"
#include "ctlio/io/text_table.h"
#include "ctlio/io/trajectory_io.h"
#include "ctlio/io/warning_limiter.h"

namespace ctlio::io {
namespace fs = std::filesystem;

PointCloud ReadSimScan(const std::string& path, int64_t start_ns) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw std::runtime_error(path + ": file not found");
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() % 16 != 0) {
    throw std::runtime_error(path + ": size " + std::to_string(bytes.size()) +
                             " B is not a multiple of 16 B per point");
  }
  PointCloud c;
  c.stamp_ns = start_ns;
  const size_t n = bytes.size() / 16;
  c.points.reserve(n);
  c.times_ns.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    float v[3];
    uint32_t dt;
    std::memcpy(v, bytes.data() + 16 * i, 12);
    std::memcpy(&dt, bytes.data() + 16 * i + 12, 4);
    const Vec3 x(v[0], v[1], v[2]);
    if (!x.allFinite()) {  // recovery, as for every point-cloud file
      ++c.dropped_non_finite;
      continue;
    }
    c.points.push_back(x);
    c.times_ns.push_back(CheckedAddNs(start_ns, int64_t(dt), path));
  }
  return c;
}

void WriteSimScan(const std::string& path, const PointCloud& cloud) {
  std::ofstream out = OpenForWriting(path, std::ios::binary | std::ios::trunc);
  std::vector<char> buf(16 * cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    const float v[3] = {float(cloud.points[i].x()), float(cloud.points[i].y()),
                        float(cloud.points[i].z())};
    const int64_t dt = cloud.has_times() ? cloud.times_ns[i] - cloud.stamp_ns : 0;
    if (dt < 0 || dt > int64_t(std::numeric_limits<uint32_t>::max())) {
      throw std::runtime_error(path + ": point " + std::to_string(i) + " time outside the scan");
    }
    const uint32_t u = uint32_t(dt);
    std::memcpy(buf.data() + 16 * i, v, 12);
    std::memcpy(buf.data() + 16 * i + 12, &u, 4);
  }
  out.write(buf.data(), std::streamsize(buf.size()));
  CloseChecked(out, path);
}

namespace {

// A pose mapping {translation, quaternion_xyzw} of ctlio_sim.yaml; `what` names the key.
SE3 ReadPose(const YAML::Node& node, const std::string& what) {
  if (!node || !node.IsMap()) throw std::runtime_error(what + ": missing or not a mapping");
  const auto t = node["translation"].as<std::vector<double>>();
  const auto q = node["quaternion_xyzw"].as<std::vector<double>>();
  if (t.size() != 3 || q.size() != 4) throw std::runtime_error(what + ": wrong sizes");
  // A zero (or non-unit, or NaN) quaternion is no rotation: Eigen would silently give identity.
  // The check every reader of an extrinsic shares (extrinsic_check.h).
  return CheckedExtrinsic(q[3], q[0], q[1], q[2], Vec3(t[0], t[1], t[2]), what + ": ");
}

void EmitPose(YAML::Emitter& y, const std::string& key, const SE3& T) {
  const Eigen::Quaterniond q = T.quaternion();
  y << YAML::Key << key << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "translation" << YAML::Value << YAML::Flow
    << std::vector<double>{T.translation().x(), T.translation().y(), T.translation().z()};
  y << YAML::Key << "quaternion_xyzw" << YAML::Value << YAML::Flow
    << std::vector<double>{q.x(), q.y(), q.z(), q.w()};
  y << YAML::EndMap;
}

// The file of IMU j in a version-2 folder: imu.csv (as in version 1), imu1.csv, imu2.csv, ...
std::string ImuFileName(size_t j) {
  return j == 0 ? "imu.csv" : "imu" + std::to_string(j) + ".csv";
}

}  // namespace

SimFolderReader::SimFolderReader(const std::string& folder, int64_t max_imu_gap_error_ns)
    : warnings_(std::make_shared<WarningLimiter>(folder)), folder_(folder) {
  const fs::path dir(folder);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(folder + ": folder not found");
  const std::string meta_path = (dir / "ctlio_sim.yaml").string();
  if (!fs::is_regular_file(meta_path, ec)) throw std::runtime_error(meta_path + ": file not found");
  std::vector<std::string> imu_files;
  try {
    const YAML::Node meta = YAML::LoadFile(meta_path);
    if (!meta["format"] || meta["format"].as<std::string>() != "ctlio_sim") {
      throw std::runtime_error("key 'format' is not 'ctlio_sim'");
    }
    version_ = meta["version"] ? meta["version"].as<int>() : 1;
    if (version_ < 1 || version_ > 2) {
      throw std::runtime_error("version " + std::to_string(version_) +
                               " is not supported (1 or 2)");
    }
    gravity_ = meta["gravity"].as<double>();
    if (!(gravity_ > 0.0 && gravity_ < 100.0)) {
      throw std::runtime_error("gravity " + std::to_string(gravity_) + " is not in (0, 100) m/s²");
    }
    imu_from_lidar_ = ReadPose(meta["imu_from_lidar"], "imu_from_lidar");
    if (meta["true_imu_from_lidar"]) {
      true_imu_from_lidar_ = ReadPose(meta["true_imu_from_lidar"], "true_imu_from_lidar");
    }
    if (version_ == 1) {  // one IMU in imu.csv, the body frame
      imus_.push_back(ImuInfo{});
      imu_files.push_back("imu.csv");
    } else {
      const YAML::Node list = meta["imus"];
      if (!list || !list.IsSequence() || list.size() == 0) {
        throw std::runtime_error("version 2 needs 'imus', a non-empty list");
      }
      for (size_t j = 0; j < list.size(); ++j) {
        const YAML::Node n = list[j];
        const std::string what = "imus[" + std::to_string(j) + "]";
        ImuInfo info;
        info.name = n["name"] ? n["name"].as<std::string>() : "imu" + std::to_string(j);
        const std::string file = n["file"].as<std::string>();
        if (file.empty() || fs::path(file).is_absolute() || file.find("..") != std::string::npos) {
          throw std::runtime_error(what + ".file '" + file + "' must be a path inside the folder");
        }
        info.T_body_imu = ReadPose(n["body_from_imu"], what + ".body_from_imu");
        if (n["rate_hz"]) info.rate_hz = n["rate_hz"].as<double>();
        if (n["accel_noise"]) info.accel_sigma = n["accel_noise"].as<double>();
        if (n["gyro_noise"]) info.gyro_sigma = n["gyro_noise"].as<double>();
        if (!(info.rate_hz >= 0 && info.accel_sigma >= 0 && info.gyro_sigma >= 0)) {
          throw std::runtime_error(what + ": rate_hz, accel_noise and gyro_noise must be >= 0");
        }
        if (n["accel_bias"] && n["gyro_bias"]) {
          const auto ba = n["accel_bias"].as<std::vector<double>>();
          const auto bg = n["gyro_bias"].as<std::vector<double>>();
          if (ba.size() != 3 || bg.size() != 3) throw std::runtime_error(what + ": bias sizes");
          Vec6 b;
          b << ba[0], ba[1], ba[2], bg[0], bg[1], bg[2];
          info.true_bias = b;
        }
        if (n["true_time_offset_s"]) info.true_time_offset_s = n["true_time_offset_s"].as<double>();
        imus_.push_back(info);
        imu_files.push_back(file);
      }
    }
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(meta_path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(meta_path + ": " + e.what());
  }

  const std::string scans_path = (dir / "scans.csv").string();
  for (const auto& row : ReadTable(scans_path, true)) {
    ExpectFields(scans_path, row, 5);
    ScanEntry e{row.line, ToInt64(scans_path, row, 1), ToInt64(scans_path, row, 2),
                size_t(ToInt64(scans_path, row, 3)), (dir / row.fields[4]).string()};
    if (e.end_ns <= e.start_ns) FailAt(scans_path, row.line, "end_ns not after start_ns");
    if (ToInt64(scans_path, row, 3) < 0) FailAt(scans_path, row.line, "negative point count");
    if (!scans_.empty() && e.start_ns <= scans_.back().start_ns) {
      FailAt(scans_path, row.line,
             "scan out of order (start " + std::to_string(e.start_ns) + " ns not after " +
                 std::to_string(scans_.back().start_ns) + " ns on line " +
                 std::to_string(scans_.back().line) + ")");
    }
    scans_.push_back(e);
  }
  if (scans_.empty()) throw std::runtime_error(scans_path + ": no scans");

  std::vector<std::vector<ImuSample>> streams;
  for (const std::string& file : imu_files) {
    const std::string imu_path = (dir / file).string();
    std::vector<ImuSample> imu;
    std::vector<int> lines;
    for (const auto& row : ReadTable(imu_path, true)) {
      ExpectFields(imu_path, row, 7);
      ImuSample s;
      s.t_ns = ToInt64(imu_path, row, 0);
      s.gyro = ToVec3(imu_path, row, 1);
      s.accel = ToVec3(imu_path, row, 4);
      imu.push_back(s);
      lines.push_back(row.line);
    }
    if (imu.empty()) throw std::runtime_error(imu_path + ": no IMU samples");
    CheckImuStream(imu_path, lines, max_imu_gap_error_ns, &imu, warnings_.get());
    streams.push_back(std::move(imu));
  }
  imu_ = MergeImuStreams(streams);

  const std::string gt_path = (dir / "ground_truth.csv").string();
  if (fs::is_regular_file(gt_path, ec)) {
    for (const auto& row : ReadTable(gt_path, true)) {
      ExpectFields(gt_path, row, 8);
      const int64_t t = ToInt64(gt_path, row, 0);
      if (!ground_truth_.empty() && t <= ground_truth_.back().t_ns) {
        FailAt(gt_path, row.line, "ground-truth time not increasing");
      }
      ground_truth_.push_back(
          {t, CheckedGroundTruthPose(ToDouble(gt_path, row, 7), ToDouble(gt_path, row, 4),
                                     ToDouble(gt_path, row, 5), ToDouble(gt_path, row, 6),
                                     ToVec3(gt_path, row, 1),
                                     gt_path + ":" + std::to_string(row.line) + ": ")});
    }
  }
}

bool SimFolderReader::Next(ScanFrame* frame) {
  if (next_ >= scans_.size()) {
    warnings_->LogTotals();
    return false;
  }
  const ScanEntry& e = scans_[next_];
  frame->index = next_;
  frame->cloud = ReadSimScan(e.file, e.start_ns);
  if (frame->cloud.size() + frame->cloud.dropped_non_finite != e.points) {
    FailAt(folder_ + "/scans.csv", e.line,
           "lists " + std::to_string(e.points) + " points, " + e.file + " has " +
               std::to_string(frame->cloud.size() + frame->cloud.dropped_non_finite));
  }
  // Times that cannot be a sweep of the scan's length: the rule of every reader
  // (point_time_check.h), rescaled by a unit factor or replaced by azimuth times.
  const int64_t length = std::max<int64_t>(SaturatingSubNs(e.end_ns, e.start_ns), 1);
  const PointTimeCheck check = CheckPointTimes(&frame->cloud, length);
  if (check.verdict != PointTimeCheck::kSweep) {
    const bool azimuth = check.verdict == PointTimeCheck::kNotASweep;
    if (warnings_->Count(azimuth ? "per-point times not a sweep" : "per-point times rescaled",
                         e.file + ": " + check.reason)) {
      LOG(WARNING) << e.file << ": " << check.reason
                   << (azimuth ? "; times recovered from the azimuth instead" : "");
    }
    if (azimuth) FillTimesFromAzimuth(&frame->cloud, StampAt::kScanStart, length);
  }
  // Recovery as in the Newer College reader: points timed outside the scan's interval (± 10 % of
  // its length) are dropped with a warning naming the file.
  const int64_t tolerance = std::max<int64_t>(length / 10, 1);
  DropPointsOutside(e.file, SaturatingSubNs(e.start_ns, tolerance),
                    SaturatingAddNs(e.end_ns, tolerance), &frame->cloud, warnings_.get());
  frame->start_ns = e.start_ns;
  frame->end_ns = e.end_ns;
  frame->imu.clear();
  TakeImuUntil(imu_, e.end_ns, &imu_cursor_, &frame->imu);
  ++next_;
  return true;
}

std::optional<std::vector<StampedPose>> SimFolderReader::GroundTruth() const {
  if (ground_truth_.empty()) return std::nullopt;
  return ground_truth_;
}

size_t WriteSimFolder(DataSource& source, const std::string& folder, const std::string& config_yaml,
                      const std::function<void(size_t, size_t)>& progress,
                      bool write_ground_truth) {
  const fs::path dir(folder);
  fs::create_directories(dir / "scans");
  const std::vector<ImuInfo> imus = source.Imus();
  if (imus.empty()) throw std::runtime_error(source.Name() + ": no IMU to write");
  {
    YAML::Emitter y;
    y << YAML::BeginMap << YAML::Key << "format" << YAML::Value << "ctlio_sim";
    y << YAML::Key << "version" << YAML::Value << 2;
    y << YAML::Key << "source" << YAML::Value << source.Name();
    y << YAML::Key << "gravity" << YAML::Value << source.Gravity().value_or(9.81);
    EmitPose(y, "imu_from_lidar", source.ImuFromLidar());
    // Only when the nominal extrinsic is not the truth (a calibration experiment): files of the
    // usual datasets stay as they were.
    const std::optional<SE3> truth = source.TrueImuFromLidar();
    if (truth && (truth->Matrix() - source.ImuFromLidar().Matrix()).norm() > 0.0) {
      EmitPose(y, "true_imu_from_lidar", *truth);
    }
    y << YAML::Key << "imus" << YAML::Value << YAML::BeginSeq;
    for (size_t j = 0; j < imus.size(); ++j) {
      const ImuInfo& info = imus[j];
      y << YAML::BeginMap << YAML::Key << "name" << YAML::Value << info.name;
      y << YAML::Key << "file" << YAML::Value << ImuFileName(j);
      EmitPose(y, "body_from_imu", info.T_body_imu);
      y << YAML::Key << "rate_hz" << YAML::Value << info.rate_hz;
      y << YAML::Key << "accel_noise" << YAML::Value << info.accel_sigma;
      y << YAML::Key << "gyro_noise" << YAML::Value << info.gyro_sigma;
      if (info.true_bias) {
        const Vec6& b = *info.true_bias;
        y << YAML::Key << "accel_bias" << YAML::Value << YAML::Flow
          << std::vector<double>{b[0], b[1], b[2]};
        y << YAML::Key << "gyro_bias" << YAML::Value << YAML::Flow
          << std::vector<double>{b[3], b[4], b[5]};
      }
      if (info.true_time_offset_s) {
        y << YAML::Key << "true_time_offset_s" << YAML::Value << *info.true_time_offset_s;
      }
      y << YAML::EndMap;
    }
    y << YAML::EndSeq;
    if (!config_yaml.empty()) y << YAML::Key << "config" << YAML::Value << YAML::Load(config_yaml);
    y << YAML::EndMap;
    WriteTextFile((dir / "ctlio_sim.yaml").string(),
                  "# ctlio simulator dataset, layout: docs/user-guide/datasets-and-formats.md\n" +
                      std::string(y.c_str()) + "\n");
  }
  const std::string scans_path = (dir / "scans.csv").string();
  std::vector<std::string> imu_paths;
  std::vector<std::ofstream> imu_files;
  for (size_t j = 0; j < imus.size(); ++j) {
    imu_paths.push_back((dir / ImuFileName(j)).string());
    imu_files.push_back(OpenForWriting(imu_paths.back()));
    imu_files.back() << "t_ns,wx,wy,wz,ax,ay,az\n" << std::setprecision(17);
  }
  std::ofstream scans = OpenForWriting(scans_path);
  scans << "index,start_ns,end_ns,points,file\n";
  ScanFrame frame;
  size_t n = 0;
  while (source.Next(&frame)) {
    for (const ImuSample& s : frame.imu) {
      if (s.imu < 0 || size_t(s.imu) >= imus.size()) {
        throw std::runtime_error(source.Name() + ": IMU sample of IMU " + std::to_string(s.imu) +
                                 ", the source has " + std::to_string(imus.size()));
      }
      std::ofstream& imu = imu_files[size_t(s.imu)];
      imu << s.t_ns;
      for (int k = 0; k < 3; ++k) imu << ',' << s.gyro[k];
      for (int k = 0; k < 3; ++k) imu << ',' << s.accel[k];
      imu << '\n';
    }
    char name[32];
    std::snprintf(name, sizeof(name), "scans/%06zu.bin", n);
    WriteSimScan((dir / name).string(), frame.cloud);
    scans << n << ',' << frame.start_ns << ',' << frame.end_ns << ',' << frame.cloud.size() << ','
          << name << '\n';
    ++n;
    if (progress) progress(n, source.NumScans());
  }
  for (size_t j = 0; j < imus.size(); ++j) CloseChecked(imu_files[j], imu_paths[j]);
  CloseChecked(scans, scans_path);
  if (const auto gt = write_ground_truth ? source.GroundTruth() : std::nullopt) {
    const std::string gt_path = (dir / "ground_truth.csv").string();
    std::ofstream out = OpenForWriting(gt_path);
    out << "t_ns,x,y,z,qx,qy,qz,qw\n" << std::setprecision(17);
    for (const auto& p : *gt) {
      const Eigen::Quaterniond q = p.pose.quaternion();
      const Vec3& r = p.pose.translation();
      out << p.t_ns << ',' << r.x() << ',' << r.y() << ',' << r.z() << ',' << q.x() << ',' << q.y()
          << ',' << q.z() << ',' << q.w() << '\n';
    }
    CloseChecked(out, gt_path);
    WriteTum((dir / "ground_truth_tum.txt").string(), *gt);
  }
  return n;
}

std::vector<InputDefect> SimFolderReader::InputDefects() const { return warnings_->Defects(); }

}  // namespace ctlio::io
