// CSV as RFC 4180 specifies it, written and read by every CSV cairn makes
// (`cairn run --out`, the validation report, `cairn sweep`):
//   - fields are separated by commas, one record per line;
//   - a field that holds a comma, a double quote, a CR or an LF is enclosed
//     in double quotes, and a double quote inside it is doubled ("a ""b""");
//     other fields are written as they are;
//   - records end with LF, not the CRLF the RFC names: every CSV reader
//     (Python's csv, pandas, R, spreadsheets) accepts LF, Unix tools expect
//     it, and the reader below accepts both.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace cairn::validation {

// Builds one record field by field; line() is the record with its line
// break, ready to write. clear() starts the next one and keeps the buffer,
// so a writer of many rows allocates once.
class CsvRecord {
 public:
  CsvRecord& text(std::string_view field);
  CsvRecord& number(double v);  // shortest text that reads back to the same double
  CsvRecord& integer(long long v);
  const std::string& line();
  void clear();

 private:
  void separate();
  std::string line_;
  bool open_ = true;  // no line break written yet
  bool first_ = true;
};

// A whole record from its fields (all written with text()).
std::string csvRecord(const std::vector<std::string>& fields);

// Appends the shortest text that reads back to the same double (C++17
// to_chars): 0.1 as "0.1", 1/3 as "0.3333333333333333".
void appendExactNumber(std::string& out, double v);

// Splits CSV text into records of fields, undoing the quoting. Blank lines
// are skipped. Throws InputError(source + ":LINE", "", why) on a quote that
// is not closed, stray text after a closing quote, or a quote inside an
// unquoted field.
std::vector<std::vector<std::string>> parseCsv(std::string_view text, const std::string& source);

// The same, each record with the line it starts on (1-based), for messages
// that name the line of a bad value.
struct CsvRow {
  int line = 0;
  std::vector<std::string> fields;
};
std::vector<CsvRow> parseCsvRows(std::string_view text, const std::string& source);

}  // namespace cairn::validation
