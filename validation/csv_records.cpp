#include "validation/csv_records.hpp"

#include "cairn/error.hpp"

namespace cairn::validation {

std::vector<CsvRecord> parseCsv(const std::string& text, const std::string& path) {
  std::vector<CsvRecord> records;
  CsvRecord rec;
  std::string field;
  int line = 1;
  bool quoted = false;       // inside a quoted field
  bool was_quoted = false;   // the current field was quoted (only a separator may follow)
  bool any = false;          // the current record has content
  rec.line = 1;
  const auto bad = [&](const std::string& why) { return InputError(path, "", "line " + std::to_string(line) + ": " + why); };
  const auto endField = [&] {
    rec.fields.push_back(std::move(field));
    field.clear();
    was_quoted = false;
  };
  const auto endRecord = [&] {
    if (any) {
      endField();
      records.push_back(std::move(rec));
    }
    rec = CsvRecord{};
    field.clear();
    was_quoted = false;
    any = false;
  };
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          field += '"';
          ++i;
        } else {
          quoted = false;
          was_quoted = true;
        }
      } else {
        if (c == '\n') ++line;
        field += c;
      }
      continue;
    }
    if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') continue;
    if (c == '\n' || c == '\r') {
      endRecord();
      ++line;
      rec.line = line;
      continue;
    }
    any = true;
    if (c == ',') {
      endField();
    } else if (c == '"') {
      if (!field.empty() || was_quoted) throw bad("a quote inside an unquoted field (RFC 4180: quote the whole field)");
      quoted = true;
    } else {
      if (was_quoted) throw bad("text after a closing quote");
      field += c;
    }
  }
  if (quoted) throw bad("a quoted field is not closed");
  endRecord();
  return records;
}

}  // namespace cairn::validation
