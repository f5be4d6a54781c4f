#include "validation/csv.hpp"

#include "cairn/error.hpp"

#include <charconv>

namespace cairn::validation {

void appendExactNumber(std::string& out, double v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

void CsvRecord::separate() {
  if (!open_) clear();
  if (!first_) line_ += ',';
  first_ = false;
}

CsvRecord& CsvRecord::text(std::string_view field) {
  separate();
  if (field.find_first_of(",\"\r\n") == std::string_view::npos) {
    line_ += field;
    return *this;
  }
  line_ += '"';
  for (char c : field) {
    if (c == '"') line_ += '"';
    line_ += c;
  }
  line_ += '"';
  return *this;
}

CsvRecord& CsvRecord::number(double v) {
  separate();
  appendExactNumber(line_, v);
  return *this;
}

CsvRecord& CsvRecord::integer(long long v) {
  separate();
  line_ += std::to_string(v);
  return *this;
}

const std::string& CsvRecord::line() {
  if (open_) line_ += '\n';
  open_ = false;
  return line_;
}

void CsvRecord::clear() {
  line_.clear();
  open_ = true;
  first_ = true;
}

std::string csvRecord(const std::vector<std::string>& fields) {
  CsvRecord r;
  for (const std::string& f : fields) r.text(f);
  return r.line();
}

std::vector<CsvRow> parseCsvRows(std::string_view text, const std::string& source) {
  std::vector<CsvRow> records;
  CsvRow record;
  std::string field;
  size_t line = 1;
  record.line = 1;
  const auto fail = [&](const std::string& why) { throw InputError(source + ":" + std::to_string(line), "", why); };
  size_t i = 0;
  const size_t n = text.size();
  while (i < n) {
    // One field: quoted or bare.
    field.clear();
    if (text[i] == '"') {
      const size_t opened = line;
      ++i;
      while (true) {
        if (i >= n) {
          line = opened;
          fail("a quoted field is not closed");
        }
        if (text[i] == '"') {
          if (i + 1 < n && text[i + 1] == '"') {
            field += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        if (text[i] == '\n') ++line;
        field += text[i++];
      }
      if (i < n && text[i] != ',' && text[i] != '\n' && text[i] != '\r') fail("text after a closing quote");
    } else {
      while (i < n && text[i] != ',' && text[i] != '\n' && text[i] != '\r') {
        if (text[i] == '"') fail("a quote inside an unquoted field (RFC 4180: quote the whole field)");
        field += text[i++];
      }
    }
    record.fields.push_back(field);
    // The field ends the record, or another follows.
    if (i < n && text[i] == ',') {
      ++i;
      if (i == n) record.fields.emplace_back();
      continue;
    }
    if (i < n && text[i] == '\r') ++i;
    if (i < n && text[i] == '\n') ++i;
    ++line;
    if (!(record.fields.size() == 1 && record.fields[0].empty())) records.push_back(std::move(record));
    record = CsvRow{static_cast<int>(line), {}};
  }
  if (!record.fields.empty()) records.push_back(std::move(record));  // the last record had no line break
  return records;
}

std::vector<std::vector<std::string>> parseCsv(std::string_view text, const std::string& source) {
  std::vector<std::vector<std::string>> out;
  for (CsvRow& r : parseCsvRows(text, source)) out.push_back(std::move(r.fields));
  return out;
}

}  // namespace cairn::validation
