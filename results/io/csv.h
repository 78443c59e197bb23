// RFC 4180 CSV records (measurement campaigns, docs/formats/measurements.md section 4): an optional
// UTF-8 byte-order mark, comma separators, fields in double quotes may hold commas, line breaks and
// doubled quotes (""), CRLF or LF line ends. Unquoted fields are trimmed of spaces and tabs.
#pragma once
#include <istream>
#include <string>
#include <vector>

namespace gravsweep::results {

class CsvReader {
 public:
  explicit CsvReader(std::istream& in) : in_(in) {}
  /// Reads the next record; false at the end of the input. `line` is the 1-based line the record
  /// starts on. Blank lines are skipped. Throws CsvSyntaxError on an unterminated quote or text
  /// after a closing quote.
  bool next(std::vector<std::string>& fields, int& line);

 private:
  std::istream& in_;
  int line_ = 0;
  bool first_ = true;
};

/// A field as RFC 4180 writes it (quoted when it holds a comma, a quote or a line break).
std::string csv_field(const std::string& s);

struct CsvSyntaxError {
  int line = 0, column = 0;
  std::string message;
};

}  // namespace gravsweep::results
