#include "ctlio/io/euroc.h"

#include <Eigen/Geometry>
#include <stdexcept>

#include "ctlio/io/text_table.h"

namespace ctlio::io {
namespace {

// Every row of a EuRoC-style CSV: `fields` numbers, an integer ns time first, strictly increasing.
template <typename Row, typename Fill>
std::vector<Row> ReadTimedCsv(const std::string& path, size_t fields, Fill fill) {
  std::vector<Row> rows;
  for (const TableRow& t : ReadTable(path, /*skip_header=*/false)) {
    ExpectFields(path, t, fields);
    Row row;
    row.t_ns = ToInt64(path, t, 0);
    if (!rows.empty() && row.t_ns <= rows.back().t_ns) {
      FailAt(path, t.line, "timestamp not strictly increasing");
    }
    fill(path, t, &row);
    rows.push_back(row);
  }
  if (rows.empty()) throw std::runtime_error(path + ": no data rows");
  return rows;
}

}  // namespace

std::vector<imu::ImuSample> ReadEurocImuCsv(const std::string& path) {
  return ReadTimedCsv<imu::ImuSample>(
      path, 7, [](const std::string& p, const TableRow& t, imu::ImuSample* s) {
        s->gyro = ToVec3(p, t, 1);
        s->accel = ToVec3(p, t, 4);
      });
}

std::vector<GroundTruthState> ReadVicon2gtCsv(const std::string& path) {
  return ReadTimedCsv<GroundTruthState>(
      path, 17, [](const std::string& p, const TableRow& t, GroundTruthState* s) {
        const Eigen::Quaterniond q(ToDouble(p, t, 4), ToDouble(p, t, 5), ToDouble(p, t, 6),
                                   ToDouble(p, t, 7));  // w x y z
        s->x.C = q.normalized().toRotationMatrix();
        s->x.p = ToVec3(p, t, 1);
        s->x.v = ToVec3(p, t, 8);
        s->bias << ToVec3(p, t, 14), ToVec3(p, t, 11);  // [b_a; b_g]
      });
}

}  // namespace ctlio::io
