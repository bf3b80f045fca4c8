#include "ctlio/io/trajectory_io.h"

#include <fstream>
#include <iomanip>
#include <stdexcept>

#include "ctlio/io/checked_output.h"
#include "ctlio/io/ground_truth_check.h"
#include "ctlio/io/text_table.h"

namespace ctlio::io {
namespace {

void CheckIncreasing(const std::string& path, const TableRow& row,
                     const std::vector<StampedPose>& poses, int64_t t) {
  if (!poses.empty() && t <= poses.back().t_ns) {
    FailAt(path, row.line, "time " + FormatSecondsNs(t) + " s is not after the previous line's");
  }
}

Mat3 CheckedRotation(const std::string& path, const TableRow& row, const Mat3& C) {
  if ((C.transpose() * C - Mat3::Identity()).norm() > 1e-3 || C.determinant() < 0) {
    FailAt(path, row.line, "rotation block is not a rotation matrix");
  }
  return Eigen::Quaterniond(C).normalized().toRotationMatrix();
}

}  // namespace

std::vector<StampedPose> ReadTum(const std::string& path) {
  std::vector<StampedPose> poses;
  for (const auto& row : ReadTable(path, false)) {
    ExpectFields(path, row, 8);
    int64_t t = 0;
    if (!ParseSecondsNs(row.fields[0], &t)) {
      FailAt(path, row.line, "time '" + row.fields[0] + "' is not a number");
    }
    CheckIncreasing(path, row, poses, t);
    poses.push_back({t, CheckedGroundTruthPose(ToDouble(path, row, 7), ToDouble(path, row, 4),
                                               ToDouble(path, row, 5), ToDouble(path, row, 6),
                                               ToVec3(path, row, 1),
                                               path + ":" + std::to_string(row.line) + ": ")});
  }
  return poses;
}

void WriteTum(const std::string& path, const std::vector<StampedPose>& poses) {
  std::ofstream out = OpenForWriting(path);
  out << "# t x y z qx qy qz qw\n" << std::setprecision(17);
  for (const auto& p : poses) {
    const Eigen::Quaterniond q = p.pose.quaternion();
    const Vec3& r = p.pose.translation();
    out << FormatSecondsNs(p.t_ns) << ' ' << r.x() << ' ' << r.y() << ' ' << r.z() << ' ' << q.x()
        << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
  }
  CloseChecked(out, path);
}

std::vector<StampedPose> ReadKittiPoses(const std::string& path, const std::string& times_path) {
  std::vector<int64_t> times;
  if (!times_path.empty()) {
    for (const auto& row : ReadTable(times_path, false)) {
      ExpectFields(times_path, row, 1);
      int64_t t = 0;
      if (!ParseSecondsNs(row.fields[0], &t)) FailAt(times_path, row.line, "not a time");
      if (!times.empty() && t <= times.back()) FailAt(times_path, row.line, "time not increasing");
      times.push_back(t);
    }
  }
  std::vector<StampedPose> poses;
  const auto rows = ReadTable(path, false);
  if (!times_path.empty() && times.size() != rows.size()) {
    throw std::runtime_error(times_path + ": " + std::to_string(times.size()) + " times for " +
                             std::to_string(rows.size()) + " poses in " + path);
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& row = rows[i];
    ExpectFields(path, row, 12);
    Mat3 C;
    Vec3 r;
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) C(a, b) = ToDouble(path, row, 4 * a + b);
      r[a] = ToDouble(path, row, 4 * a + 3);
    }
    poses.push_back({times.empty() ? int64_t(i) * 100'000'000 : times[i],
                     SE3(CheckedRotation(path, row, C), r)});
  }
  return poses;
}

void WriteKittiPoses(const std::string& path, const std::vector<StampedPose>& poses) {
  std::ofstream out = OpenForWriting(path);
  out << std::setprecision(12);
  for (const auto& p : poses) {
    const Mat4 T = p.pose.Matrix();
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 4; ++b) out << T(a, b) << (a == 2 && b == 3 ? '\n' : ' ');
    }
  }
  CloseChecked(out, path);
}

std::vector<StampedPose> ReadTrajectory(const std::string& path,
                                        const std::string& kitti_times_path) {
  const auto rows = ReadTable(path, false);
  if (rows.empty()) throw std::runtime_error(path + ": no poses");
  if (rows.front().fields.size() == 12) return ReadKittiPoses(path, kitti_times_path);
  if (rows.front().fields.size() == 8) return ReadTum(path);
  FailAt(path, rows.front().line,
         "neither TUM (8 fields) nor KITTI (12 fields): " +
             std::to_string(rows.front().fields.size()) + " fields");
}

}  // namespace ctlio::io
