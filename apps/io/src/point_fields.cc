#include "ctlio/io/point_fields.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "ctlio/io/point_layout_check.h"

namespace ctlio::io {
namespace {

bool IsIntegerType(uint8_t t) { return t >= kInt8 && t <= kUInt32; }
bool IsFloatType(uint8_t t) { return t == kFloat32 || t == kFloat64; }

const PointField* Find(const std::vector<PointField>& fields, const std::string& name) {
  for (const PointField& f : fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

double UnitToNs(TimeUnit u) {
  switch (u) {
    case TimeUnit::kSeconds:
      return 1e9;
    case TimeUnit::kMilliseconds:
      return 1e6;
    case TimeUnit::kMicroseconds:
      return 1e3;
    case TimeUnit::kNanoseconds:
      return 1.0;
  }
  return 1.0;
}

const char* UnitName(TimeUnit u) {
  switch (u) {
    case TimeUnit::kSeconds:
      return "s";
    case TimeUnit::kMilliseconds:
      return "ms";
    case TimeUnit::kMicroseconds:
      return "us";
    case TimeUnit::kNanoseconds:
      return "ns";
  }
  return "?";
}

// The driver conventions of the header, matched on name and datatype. Returns false when `f` is
// not a time field of any known driver; throws when its name is one but its datatype is not.
bool MatchConvention(const PointField& f, const std::vector<PointField>& fields, TimeConvention* c,
                     const std::string& fail_prefix) {
  auto wrong = [&](const std::string& expected) {
    throw std::runtime_error(fail_prefix + "time field '" + f.name + "' is " +
                             FieldDatatypeName(f.datatype) + ", expected " + expected +
                             " (fields found: " + DescribeFields(fields) + ")");
  };
  c->field = f.name;
  if (f.name == "t") {
    if (!IsIntegerType(f.datatype)) wrong("an integer (ns since the stamp, Ouster)");
    c->unit = TimeUnit::kNanoseconds;
    c->reference = TimeReference::kRelativeToStamp;
    c->stamp_at = StampAt::kScanStart;
    c->driver = "Ouster";
    return true;
  }
  if (f.name == "offset_time") {
    if (!IsIntegerType(f.datatype)) wrong("an integer (ns since the stamp, Livox)");
    c->unit = TimeUnit::kNanoseconds;
    c->reference = TimeReference::kRelativeToStamp;
    c->stamp_at = StampAt::kScanStart;
    c->driver = "Livox CustomPoint";
    return true;
  }
  if (f.name == "time") {
    if (!IsFloatType(f.datatype)) wrong("float32 or float64 (s since the stamp, Velodyne)");
    c->unit = TimeUnit::kSeconds;
    c->reference = TimeReference::kRelativeToStamp;
    c->stamp_at = StampAt::kScanEnd;
    c->driver = "Velodyne";
    return true;
  }
  if (f.name == "timestamp") {
    if (f.datatype != kFloat64)
      wrong("float64 (absolute time: s for Hesai/Robosense, ns for Livox)");
    c->reference = TimeReference::kAbsolute;
    if (Find(fields, "tag") && Find(fields, "line")) {
      c->unit = TimeUnit::kNanoseconds;
      c->stamp_at = StampAt::kScanStart;
      c->driver = "Livox driver 2";
    } else {
      c->unit = TimeUnit::kSeconds;
      c->stamp_at = StampAt::kScanStart;
      c->driver = "Hesai/Robosense";
    }
    return true;
  }
  c->field.clear();
  return false;
}

}  // namespace

size_t FieldDatatypeSize(uint8_t t) {
  switch (t) {
    case kInt8:
    case kUInt8:
      return 1;
    case kInt16:
    case kUInt16:
      return 2;
    case kInt32:
    case kUInt32:
    case kFloat32:
      return 4;
    case kFloat64:
      return 8;
    default:
      return 0;
  }
}

std::string FieldDatatypeName(uint8_t t) {
  static const char* names[] = {"",      "int8",   "uint8",   "int16",  "uint16",
                                "int32", "uint32", "float32", "float64"};
  if (t >= kInt8 && t <= kFloat64) return names[t];
  return "type " + std::to_string(int(t));
}

std::string DescribeFields(const std::vector<PointField>& fields) {
  std::string s;
  for (const PointField& f : fields) {
    if (!s.empty()) s += ' ';
    s += f.name + ":" + FieldDatatypeName(f.datatype);
    if (f.count != 1) s += "[" + std::to_string(f.count) + "]";
  }
  return s.empty() ? "(none)" : s;
}

TimeUnit ParseTimeUnit(const std::string& s) {
  if (s == "s") return TimeUnit::kSeconds;
  if (s == "ms") return TimeUnit::kMilliseconds;
  if (s == "us") return TimeUnit::kMicroseconds;
  if (s == "ns") return TimeUnit::kNanoseconds;
  throw std::invalid_argument("time unit '" + s + "' (expected s, ms, us or ns)");
}

TimeReference ParseTimeReference(const std::string& s) {
  if (s == "relative") return TimeReference::kRelativeToStamp;
  if (s == "absolute") return TimeReference::kAbsolute;
  throw std::invalid_argument("time reference '" + s + "' (expected relative or absolute)");
}

StampAt ParseStampAt(const std::string& s) {
  if (s == "start") return StampAt::kScanStart;
  if (s == "end") return StampAt::kScanEnd;
  throw std::invalid_argument("stamp position '" + s + "' (expected start or end)");
}

std::string DescribeConvention(const TimeConvention& c) {
  if (c.field.empty()) return "no per-point time field";
  return "'" + c.field + "' (" + UnitName(c.unit) +
         (c.reference == TimeReference::kAbsolute ? " absolute" : " since the stamp") +
         ", stamp at scan " + (c.stamp_at == StampAt::kScanStart ? "start" : "end") + ", " +
         c.driver + ")";
}

PointLayout DetectPointLayout(const std::vector<PointField>& fields, uint32_t point_step,
                              const TimeFieldOptions& options, const std::string& where) {
  const std::string found = " (fields found: " + DescribeFields(fields) + ")";
  auto fail = [&](const std::string& what) { throw std::runtime_error(where + what + found); };
  PointLayout layout;
  layout.point_step = point_step;
  if (point_step > 0) {
    CheckPointFields(fields, point_step, where);  // the geometry check every layout shares
  } else {
    for (const PointField& f : fields) {
      if (FieldDatatypeSize(f.datatype) == 0)
        fail("field '" + f.name + "' has an unknown datatype");
    }
  }
  auto coordinate = [&](const char* name, PointField* out) {
    const PointField* f = Find(fields, name);
    if (!f) fail(std::string("no '") + name + "' field");
    if (!IsFloatType(f->datatype) || f->count != 1) {
      fail(std::string("field '") + name + "' must be one float32 or float64");
    }
    *out = *f;
  };
  coordinate("x", &layout.x);
  coordinate("y", &layout.y);
  coordinate("z", &layout.z);
  if (const PointField* f = Find(fields, "intensity"); f && f->count == 1) layout.intensity = *f;
  if (const PointField* f = Find(fields, "ring"); f && f->count == 1) layout.ring = *f;

  TimeConvention c;
  if (options.field == "none") {
    // Explicitly ignored: azimuth recovery.
  } else if (!options.field.empty()) {
    const PointField* f = Find(fields, options.field);
    if (!f) fail("no time field '" + options.field + "' (given as the time field)");
    if (f->count != 1) fail("time field '" + f->name + "' has count " + std::to_string(f->count));
    // Start from the driver convention if the name matches one, then apply the override.
    if (!MatchConvention(*f, fields, &c, where)) {
      c.field = f->name;
      c.unit = IsFloatType(f->datatype) ? TimeUnit::kSeconds : TimeUnit::kNanoseconds;
      c.reference = TimeReference::kRelativeToStamp;
      c.stamp_at = StampAt::kScanStart;
    }
    c.driver = "given";
    layout.time = *f;
  } else {
    for (const char* name : {"t", "offset_time", "time", "timestamp"}) {
      const PointField* f = Find(fields, name);
      if (!f) continue;
      if (f->count != 1) fail("time field '" + f->name + "' has count " + std::to_string(f->count));
      if (MatchConvention(*f, fields, &c, where)) {
        layout.time = *f;
        break;
      }
    }
  }
  if (options.unit) c.unit = *options.unit;
  if (options.reference) c.reference = *options.reference;
  if (options.stamp_at) c.stamp_at = *options.stamp_at;
  if (layout.time && (options.unit || options.reference || options.stamp_at)) {
    c.driver += ", overridden";
  }
  layout.convention = c;
  return layout;
}

double ReadFieldValue(const uint8_t* p, uint8_t datatype) {
  auto load = [p](auto v) {
    std::memcpy(&v, p, sizeof(v));  // fields need not be aligned
    return static_cast<double>(v);
  };
  switch (datatype) {
    case kInt8:
      return load(int8_t{});
    case kUInt8:
      return load(uint8_t{});
    case kInt16:
      return load(int16_t{});
    case kUInt16:
      return load(uint16_t{});
    case kInt32:
      return load(int32_t{});
    case kUInt32:
      return load(uint32_t{});
    case kFloat32:
      return load(float{});
    case kFloat64:
      return load(double{});
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

bool PointTimeNs(const PointLayout& layout, const uint8_t* p, int64_t stamp_ns, int64_t* t_ns) {
  const PointField& f = *layout.time;
  const TimeConvention& c = layout.convention;
  const int64_t base = c.reference == TimeReference::kAbsolute ? 0 : stamp_ns;
  int64_t v = 0;
  if (IsIntegerType(f.datatype) && c.unit == TimeUnit::kNanoseconds) {
    // Exact: no detour through double for integer nanoseconds (every integer type fits in double
    // exactly up to 32 bits).
    v = int64_t(ReadFieldValue(p + f.offset, f.datatype));
  } else {
    const double ns = ReadFieldValue(p + f.offset, f.datatype) * UnitToNs(c.unit);
    // Not finite or outside int64 nanoseconds (±292 years): not a time.
    if (!(std::abs(ns) < 9.2e18)) return false;
    v = std::llround(ns);
  }
  return !__builtin_add_overflow(base, v, t_ns);
}

void DecodePoints(const uint8_t* data, size_t n, const PointLayout& layout, int64_t stamp_ns,
                  const std::string& where, PointCloud* out) {
  out->points.reserve(out->points.size() + n);
  if (layout.time) out->times_ns.reserve(out->times_ns.size() + n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = data + i * layout.point_step;
    const Vec3 x(ReadFieldValue(p + layout.x.offset, layout.x.datatype),
                 ReadFieldValue(p + layout.y.offset, layout.y.datatype),
                 ReadFieldValue(p + layout.z.offset, layout.z.datatype));
    if (!x.allFinite()) {
      ++out->dropped_non_finite;
      continue;
    }
    out->points.push_back(x);
    if (layout.time) {
      int64_t t = 0;
      if (!PointTimeNs(layout, p, stamp_ns, &t)) {
        throw std::runtime_error(where + "point " + std::to_string(i) +
                                 ": time is not finite or outside int64 ns");
      }
      out->times_ns.push_back(t);
    }
    if (layout.intensity) {
      const double v = ReadFieldValue(p + layout.intensity->offset, layout.intensity->datatype);
      // A double beyond float's range (or NaN) must not be converted: undefined behaviour.
      out->intensity.push_back(std::abs(v) <= std::numeric_limits<float>::max() ? float(v) : NAN);
    }
    if (layout.ring) {
      const double v = ReadFieldValue(p + layout.ring->offset, layout.ring->datatype);
      if (!(v >= 0.0 && v <= 65535.0)) {  // also false for NaN: never cast it to an integer
        throw std::runtime_error(where + "point " + std::to_string(i) + ": ring " +
                                 std::to_string(v) + " is not in [0, 65535]");
      }
      out->ring.push_back(uint16_t(v));
    }
  }
}

namespace {
void StoreValue(uint8_t* p, uint8_t datatype, double v, bool exact_int, int64_t iv) {
  auto store = [p](auto x) { std::memcpy(p, &x, sizeof(x)); };
  const double r = exact_int ? double(iv) : v;
  switch (datatype) {
    case kInt8:
      return store(int8_t(std::llround(r)));
    case kUInt8:
      return store(uint8_t(std::llround(r)));
    case kInt16:
      return store(int16_t(std::llround(r)));
    case kUInt16:
      return store(uint16_t(std::llround(r)));
    case kInt32:
      return store(int32_t(exact_int ? iv : std::llround(r)));
    case kUInt32:
      return store(uint32_t(exact_int ? iv : std::llround(r)));
    case kFloat32:
      return store(float(r));
    case kFloat64:
      return store(r);
    default:
      return;
  }
}
}  // namespace

std::vector<uint8_t> EncodePoints(const PointCloud& cloud, const std::vector<PointField>& fields,
                                  uint32_t point_step, const TimeConvention& convention) {
  const size_t n = cloud.size();
  std::vector<uint8_t> data(n * point_step, 0);
  if (cloud.has_times() && cloud.times_ns.size() != n) {
    throw std::runtime_error("EncodePoints: times_ns and points differ in size");
  }
  for (size_t i = 0; i < n; ++i) {
    uint8_t* p = data.data() + i * point_step;
    for (const PointField& f : fields) {
      uint8_t* q = p + f.offset;
      if (f.name == "x" || f.name == "y" || f.name == "z") {
        StoreValue(q, f.datatype, cloud.points[i][f.name[0] - 'x'], false, 0);
      } else if (f.name == "intensity" && cloud.intensity.size() == n) {
        StoreValue(q, f.datatype, cloud.intensity[i], false, 0);
      } else if ((f.name == "ring" || f.name == "line") && cloud.ring.size() == n) {
        StoreValue(q, f.datatype, cloud.ring[i], false, 0);
      } else if (f.name == "range") {
        StoreValue(q, f.datatype, cloud.points[i].norm() * 1000.0, false, 0);  // mm (Ouster)
      } else if (f.name == convention.field && cloud.has_times()) {
        const int64_t dt = cloud.times_ns[i] -
                           (convention.reference == TimeReference::kAbsolute ? 0 : cloud.stamp_ns);
        const bool integer_ns =
            IsIntegerType(f.datatype) && convention.unit == TimeUnit::kNanoseconds;
        if (IsIntegerType(f.datatype)) {
          const double max = std::ldexp(
              1.0, 8 * int(FieldDatatypeSize(f.datatype)) - (f.datatype % 2 == 1 ? 1 : 0));
          const double v = double(dt) / UnitToNs(convention.unit);
          if ((f.datatype % 2 == 0 && v < 0) || std::abs(v) >= max) {
            throw std::runtime_error("EncodePoints: point " + std::to_string(i) + " time " +
                                     std::to_string(v) + " does not fit field '" + f.name + "' (" +
                                     FieldDatatypeName(f.datatype) + ")");
          }
        }
        StoreValue(q, f.datatype, double(dt) / UnitToNs(convention.unit), integer_ns, dt);
      }
    }
  }
  return data;
}

std::vector<PointField> OusterFields(uint32_t* point_step) {
  *point_step = 29;
  return {
      {"x", kFloat32, 0, 1},          {"y", kFloat32, 4, 1},     {"z", kFloat32, 8, 1},
      {"intensity", kFloat32, 12, 1}, {"t", kUInt32, 16, 1},     {"reflectivity", kUInt16, 20, 1},
      {"ring", kUInt8, 22, 1},        {"noise", kUInt16, 23, 1}, {"range", kUInt32, 25, 1}};
}

int64_t AzimuthOffsetNs(const Vec3& p, double start_azimuth, int64_t period_ns) {
  double d = start_azimuth - std::atan2(p.y(), p.x());  // clockwise spin
  d -= 2.0 * M_PI * std::floor(d / (2.0 * M_PI));
  return std::min<int64_t>(std::llround(d / (2.0 * M_PI) * double(period_ns)), period_ns - 1);
}

void FillTimesFromAzimuth(PointCloud* cloud, StampAt stamp_at, int64_t period_ns) {
  cloud->times_ns.resize(cloud->size());
  if (cloud->points.empty()) return;
  const Vec3& first = cloud->points.front();
  const double a0 = std::atan2(first.y(), first.x());
  const int64_t base =
      stamp_at == StampAt::kScanStart ? cloud->stamp_ns : cloud->stamp_ns - period_ns;
  for (size_t i = 0; i < cloud->size(); ++i) {
    cloud->times_ns[i] = base + AzimuthOffsetNs(cloud->points[i], a0, period_ns);
  }
}

}  // namespace ctlio::io
