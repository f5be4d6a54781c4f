// Reading CSV text as RFC 4180 defines it: fields separated by commas,
// records by CRLF or LF; a field in double quotes may hold commas, line
// breaks and doubled quotes ("" for "). Blank lines are skipped.
#pragma once

#include <string>
#include <vector>

namespace cairn::validation {

struct CsvRecord {
  int line = 0;  // 1-based line where the record starts
  std::vector<std::string> fields;
};

// Throws InputError naming `path` and the line on an unterminated quoted
// field or a quote inside an unquoted one.
std::vector<CsvRecord> parseCsv(const std::string& text, const std::string& path);

}  // namespace cairn::validation
