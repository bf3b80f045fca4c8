#include "ctlio/sim/extrinsic_error.h"

#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace ctlio::sim {

namespace {

std::runtime_error Bad(const std::string& text, const std::string& why) {
  return std::runtime_error("extrinsic error '" + text + "': " + why +
                            " (syntax <angle>deg[@ax:ay:az],<distance>m[@dx:dy:dz], e.g. "
                            "3deg,0.10m)");
}

double ParseNumber(const std::string& s, const std::string& text) {
  size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (s.empty() || used != s.size() || !std::isfinite(v))
    throw Bad(text, "'" + s + "' is no number");
  return v;
}

// "a:b:c" → unit vector.
Vec3 ParseDirection(const std::string& s, const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ':')) v.push_back(ParseNumber(item, text));
  if (v.size() != 3) throw Bad(text, "direction '" + s + "' needs three components x:y:z");
  const Vec3 d(v[0], v[1], v[2]);
  if (!(d.norm() > 0.0)) throw Bad(text, "direction '" + s + "' is zero");
  return d.normalized();
}

// One "<value><unit>[@x:y:z]" item.
void ParseItem(const std::string& item, const std::string& text, ExtrinsicError* e) {
  const size_t at = item.find('@');
  const std::string magnitude = item.substr(0, at);
  std::optional<Vec3> direction;
  if (at != std::string::npos) direction = ParseDirection(item.substr(at + 1), text);
  const auto ends_with = [&](const std::string& unit) {
    return magnitude.size() > unit.size() &&
           magnitude.compare(magnitude.size() - unit.size(), unit.size(), unit) == 0;
  };
  if (ends_with("deg")) {
    e->rotation_deg = ParseNumber(magnitude.substr(0, magnitude.size() - 3), text);
    if (e->rotation_deg < 0.0) throw Bad(text, "negative angle");
    e->rotation_axis = direction;
  } else if (ends_with("m")) {
    e->translation_m = ParseNumber(magnitude.substr(0, magnitude.size() - 1), text);
    if (e->translation_m < 0.0) throw Bad(text, "negative distance");
    e->translation_direction = direction;
  } else {
    throw Bad(text, "'" + item + "' has no unit deg or m");
  }
}

Vec3 RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec3 v;
  do {
    v = Vec3(n(rng), n(rng), n(rng));
  } while (v.norm() < 1e-9);
  return v.normalized();
}

}  // namespace

ExtrinsicError ParseExtrinsicError(const std::string& text) {
  ExtrinsicError e;
  if (text.empty()) return e;
  std::stringstream ss(text);
  std::string item;
  int items = 0;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    ParseItem(item, text, &e);
    ++items;
  }
  if (items == 0 || items > 2) throw Bad(text, "expected one angle and/or one distance");
  return e;
}

SE3 NominalExtrinsic(const SE3& truth, const ExtrinsicError& error, uint64_t seed, int index) {
  if (error.IsZero()) return truth;
  std::seed_seq seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32), 0xE4711u,
                    static_cast<uint32_t>(index)};
  std::mt19937_64 rng(seq);
  const Vec3 axis = RandomUnit(rng);  // drawn always, so the direction does not depend on
  const Vec3 dir = RandomUnit(rng);   // whether the axis was given
  const Vec3 a = error.rotation_axis.value_or(axis);
  const Vec3 d = error.translation_direction.value_or(dir);
  const Mat3 C = so3::Exp(error.rotation_deg * M_PI / 180.0 * a) * truth.rotation();
  return SE3(C, truth.translation() + error.translation_m * d);
}

ExtrinsicErrorSize MeasureExtrinsicError(const SE3& estimate, const SE3& truth) {
  ExtrinsicErrorSize s;
  s.rotation_deg =
      so3::Log(estimate.rotation() * truth.rotation().transpose()).norm() * 180.0 / M_PI;
  s.translation_m = (estimate.translation() - truth.translation()).norm();
  return s;
}

SigmaCoverage CoveredBySigma(const SE3& estimate, const SE3& truth, const Vec6& sigma, double k) {
  const Vec6 d = (truth * estimate.Inverse()).Log();
  SigmaCoverage c;
  c.translation = (d.head<3>().cwiseAbs().array() <= k * sigma.head<3>().array()).all();
  c.rotation = (d.tail<3>().cwiseAbs().array() <= k * sigma.tail<3>().array()).all();
  return c;
}

}  // namespace ctlio::sim
