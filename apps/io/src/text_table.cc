#include "ctlio/io/text_table.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace ctlio::io {
namespace {

bool IsNumber(const std::string& s) {
  if (s.empty()) return false;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

}  // namespace

void FailAt(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

std::vector<TableRow> ReadTable(const std::string& path, bool skip_header) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw std::runtime_error(path + ": file not found");
  }
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<TableRow> rows;
  std::string line;
  bool first = true;
  for (int n = 1; std::getline(in, line); ++n) {
    // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first field.
    if (n == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    // Tolerated: CRLF line ends, trailing blanks and one trailing comma (common in exports).
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) {
      line.pop_back();
    }
    if (!line.empty() && line.back() == ',') line.pop_back();
    TableRow row;
    row.line = n;
    std::string cur;
    bool in_field = false;
    for (char c : line) {
      if (c == ',' || c == ' ' || c == '\t' || c == ';') {
        if (in_field || c == ',') row.fields.push_back(cur);
        cur.clear();
        in_field = false;
      } else {
        cur += c;
        in_field = true;
      }
    }
    if (in_field) row.fields.push_back(cur);
    // "a, b" gives an empty field before the space: drop empties created by ", ".
    std::vector<std::string> kept;
    for (auto& f : row.fields) {
      if (!f.empty()) kept.push_back(f);
    }
    // A trailing or doubled comma leaves an empty field: report it as malformed later.
    const size_t commas = std::count(line.begin(), line.end(), ',');
    if (commas > 0 && kept.size() != commas + 1) kept.push_back("");
    row.fields = std::move(kept);
    if (row.fields.empty() || row.fields[0].rfind("#", 0) == 0) continue;
    if (first && skip_header) {
      // A header names columns: no field of it is a number. A data row always has one (a row of
      // scans.csv ends in a file name, so "any field not a number" would drop it).
      first = false;
      bool any_number = false;
      for (const auto& f : row.fields) any_number = any_number || IsNumber(f);
      if (!any_number) continue;
    }
    first = false;
    rows.push_back(std::move(row));
  }
  return rows;
}

void ExpectFields(const std::string& path, const TableRow& row, size_t n, bool at_least) {
  const size_t m = row.fields.size();
  if (m == n || (at_least && m > n)) {
    bool ok = true;
    for (const auto& f : row.fields) ok = ok && !f.empty();
    if (ok) return;
    FailAt(path, row.line, "empty field (doubled or trailing separator)");
  }
  FailAt(path, row.line,
         "expected " + std::string(at_least ? "at least " : "") + std::to_string(n) +
             " fields, found " + std::to_string(m));
}

double ToDouble(const std::string& path, const TableRow& row, size_t k) {
  if (k >= row.fields.size()) FailAt(path, row.line, "missing field " + std::to_string(k + 1));
  const std::string& s = row.fields[k];
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) {
    FailAt(path, row.line, "field " + std::to_string(k + 1) + " ('" + s + "') is not a number");
  }
  return v;
}

Vec3 ToVec3(const std::string& path, const TableRow& row, size_t k) {
  return Vec3(ToDouble(path, row, k), ToDouble(path, row, k + 1), ToDouble(path, row, k + 2));
}

int64_t ToInt64(const std::string& path, const TableRow& row, size_t k) {
  if (k >= row.fields.size()) FailAt(path, row.line, "missing field " + std::to_string(k + 1));
  const std::string& s = row.fields[k];
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE) {
    FailAt(path, row.line, "field " + std::to_string(k + 1) + " ('" + s + "') is not an integer");
  }
  return int64_t(v);
}

}  // namespace ctlio::io
