// The CSV writer and reader every CSV of cairn goes through (RFC 4180):
// fields that hold a separator, a quote or a line break are quoted and read
// back exactly; others are written as they are; malformed text is refused
// with its line.
#include "cairn/error.hpp"
#include "validation/csv.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>

namespace cairn::validation {
namespace {

TEST(Csv, PlainFieldsAreWrittenAsTheyAre) {
  CsvRecord r;
  r.integer(3).number(0.1).text("box").text("");
  EXPECT_EQ(r.line(), "3,0.1,box,\n");
  r.clear();
  r.text("next");
  EXPECT_EQ(r.line(), "next\n");
}

// RFC 4180 section 2, rules 6 and 7: enclose in double quotes, double the
// quotes inside.
TEST(Csv, FieldsWithCommasQuotesOrLineBreaksAreQuoted) {
  EXPECT_EQ(csvRecord({"a,b", "say \"hi\"", "two\nlines", "cr\r", "plain"}),
            "\"a,b\",\"say \"\"hi\"\"\",\"two\nlines\",\"cr\r\",plain\n");
}

TEST(Csv, EveryFieldReadsBackExactly) {
  const std::vector<std::vector<std::string>> rows = {
      {"step", "body", "x"},
      {"0", "a, \"b\"", "1"},
      {"1", "line\nbreak", ""},
      {"", "\r\n", "\"\""},
      {",", " spaced ", "end"},
  };
  std::string text;
  for (const auto& r : rows) text += csvRecord(r);
  EXPECT_EQ(parseCsv(text, "t.csv"), rows);
  // CRLF line ends read the same, and a last record without a line break.
  std::string crlf = "a,b\r\nc,\"d\r\ne\"\r\nf,g";
  EXPECT_EQ(parseCsv(crlf, "t.csv"), (std::vector<std::vector<std::string>>{{"a", "b"}, {"c", "d\r\ne"}, {"f", "g"}}));
}

TEST(Csv, NumbersAreTheShortestTextThatReadsBackTheSameDouble) {
  for (const double v : {0.1, 1.0 / 3, 1e-300, -2.5e20, 4.9e-324, std::numeric_limits<double>::max()}) {
    CsvRecord r;
    r.number(v);
    const std::string line = r.line();
    EXPECT_EQ(std::strtod(line.c_str(), nullptr), v) << line;
    EXPECT_LE(line.size(), 25u) << line;  // 17 digits, sign, point, exponent, line break
  }
}

TEST(Csv, MalformedTextIsRefusedWithItsLine) {
  const auto refused = [](const std::string& text, const std::string& what) {
    try {
      parseCsv(text, "t.csv");
      ADD_FAILURE() << "accepted " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused("a,b\nc,\"open\nd,e\n", "t.csv:2: a quoted field is not closed");
  refused("a,b\n\"x\"y,z\n", "t.csv:2: text after a closing quote");
  refused("a,b\nc,d\"e\n", "t.csv:2: a quote inside an unquoted field");
}

}  // namespace
}  // namespace cairn::validation
