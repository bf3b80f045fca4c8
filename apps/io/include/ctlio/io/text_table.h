// Line-oriented numeric tables (CSV or whitespace separated) with errors naming file and line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ctlio/manifolds/types.h"

namespace ctlio::io {

struct TableRow {
  int line = 0;                     // 1-based line number in the file
  std::vector<std::string> fields;  // split on ',' and/or whitespace
};

// Reads every non-empty line that does not start with '#'. CRLF line ends, trailing blanks and
// one trailing comma are tolerated, and so is a UTF-8 byte-order mark; an empty field inside a line
// is reported by ExpectFields. If `skip_header` is true and no field of the first such line is a
// number, it is a header and skipped. Throws "<path>: file not found".
std::vector<TableRow> ReadTable(const std::string& path, bool skip_header);

// Strict conversions: the whole field must parse; otherwise "<path>:<line>: field k ('...') is not
// a number". ToInt64 accepts only integers.
double ToDouble(const std::string& path, const TableRow& row, size_t k);
int64_t ToInt64(const std::string& path, const TableRow& row, size_t k);
// Fields k, k+1, k+2 as a vector (x, y, z), with ToDouble's checks.
Vec3 ToVec3(const std::string& path, const TableRow& row, size_t k);
// Throws "<path>:<line>: expected N fields, found M" unless the row has exactly (or, with
// `at_least`, at least) n fields.
void ExpectFields(const std::string& path, const TableRow& row, size_t n, bool at_least = false);
[[noreturn]] void FailAt(const std::string& path, int line, const std::string& what);

}  // namespace ctlio::io
