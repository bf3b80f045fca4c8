#include "ctlio/factors/imu/imu_data.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace ctlio::imu {
namespace {

[[noreturn]] void Fail(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

// Splits one CSV row and parses every field: the first as int64, the rest as
// finite doubles.
void ParseRow(const std::string& path, int line_number, const std::string& line,
              std::size_t expected_fields, std::int64_t* t_ns, std::vector<double>* values) {
  std::vector<std::string> fields;
  std::stringstream ss(line);
  std::string field;
  while (std::getline(ss, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  if (fields.size() != expected_fields) {
    Fail(path, line_number,
         "expected " + std::to_string(expected_fields) + " comma-separated fields, got " +
             std::to_string(fields.size()));
  }
  {
    const char* begin = fields[0].c_str();
    char* end = nullptr;
    errno = 0;
    const long long t = std::strtoll(begin, &end, 10);
    while (end != nullptr && (*end == ' ' || *end == '\t' || *end == '\r')) ++end;
    if (end == begin || *end != '\0' || errno == ERANGE) {
      Fail(path, line_number, "field 1 is not an integer timestamp in ns: '" + fields[0] + "'");
    }
    *t_ns = t;
  }
  values->clear();
  for (std::size_t i = 1; i < fields.size(); ++i) {
    const char* begin = fields[i].c_str();
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    while (end != nullptr && (*end == ' ' || *end == '\t' || *end == '\r')) ++end;
    if (end == begin || *end != '\0' || !std::isfinite(v)) {
      Fail(path, line_number,
           "field " + std::to_string(i + 1) + " is not a finite number: '" + fields[i] + "'");
    }
    values->push_back(v);
  }
}

template <typename Row>
std::vector<Row> ReadCsv(const std::string& path, std::size_t expected_fields,
                         void (*fill)(const std::vector<double>&, Row*)) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::vector<Row> rows;
  std::string line;
  int line_number = 0;
  std::vector<double> values;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    Row row;
    ParseRow(path, line_number, line, expected_fields, &row.t_ns, &values);
    if (!rows.empty() && row.t_ns <= rows.back().t_ns) {
      Fail(path, line_number, "timestamp not strictly increasing");
    }
    fill(values, &row);
    rows.push_back(row);
  }
  if (rows.empty()) throw std::runtime_error(path + ": no data rows");
  return rows;
}

}  // namespace

std::vector<ImuSample> ReadEurocImuCsv(const std::string& path) {
  return ReadCsv<ImuSample>(path, 7, [](const std::vector<double>& v, ImuSample* s) {
    s->gyro = Vec3(v[0], v[1], v[2]);
    s->accel = Vec3(v[3], v[4], v[5]);
  });
}

std::vector<GroundTruthState> ReadVicon2gtCsv(const std::string& path) {
  return ReadCsv<GroundTruthState>(path, 17, [](const std::vector<double>& v, GroundTruthState* s) {
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);  // w x y z
    s->x.C = q.normalized().toRotationMatrix();
    s->x.p = Vec3(v[0], v[1], v[2]);
    s->x.v = Vec3(v[7], v[8], v[9]);
    s->bias << v[13], v[14], v[15], v[10], v[11], v[12];  // [b_a; b_g]
  });
}

void IntegrateInterval(const std::vector<ImuSample>& samples, std::int64_t t0_ns,
                       std::int64_t t1_ns, PreintegratedImu* pim, std::int64_t max_gap_ns) {
  if (!(t1_ns > t0_ns)) throw std::runtime_error("IntegrateInterval: empty interval");
  if (samples.empty() || samples.front().t_ns > t0_ns || samples.back().t_ns < t1_ns) {
    throw std::runtime_error("IntegrateInterval: IMU samples do not cover [" +
                             std::to_string(t0_ns) + ", " + std::to_string(t1_ns) + "] ns");
  }
  // Last sample at or before t0.
  auto it = std::upper_bound(samples.begin(), samples.end(), t0_ns,
                             [](std::int64_t t, const ImuSample& s) { return t < s.t_ns; });
  std::size_t k = static_cast<std::size_t>(std::distance(samples.begin(), it)) - 1;
  std::int64_t t = t0_ns;
  while (t < t1_ns) {
    const std::int64_t next = k + 1 < samples.size() ? samples[k + 1].t_ns : t1_ns;
    if (next - samples[k].t_ns > max_gap_ns) {
      throw std::runtime_error("IntegrateInterval: gap of " +
                               std::to_string(next - samples[k].t_ns) + " ns in IMU data at " +
                               std::to_string(samples[k].t_ns));
    }
    const std::int64_t end = std::min(next, t1_ns);
    if (end > t) pim->Integrate(samples[k].accel, samples[k].gyro, 1e-9 * (end - t));
    t = end;
    ++k;
  }
}

}  // namespace ctlio::imu
