#include "results/io/csv.h"

namespace gravsweep::results {

namespace {
std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  const auto e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}
}  // namespace

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

bool CsvReader::next(std::vector<std::string>& fields, int& line) {
  std::string text;
  for (;;) {
    if (!std::getline(in_, text)) return false;
    ++line_;
    if (first_) {
      first_ = false;
      if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
    }
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (!text.empty()) break;
  }
  line = line_;
  fields.clear();
  std::string cur;
  bool quoted = false;  // the current field was quoted
  std::size_t i = 0;
  int column = 1;
  for (;;) {
    if (i >= text.size()) {
      fields.push_back(quoted ? cur : trim(cur));
      return true;
    }
    const char c = text[i];
    if (c == ',') {
      fields.push_back(quoted ? cur : trim(cur));
      cur.clear();
      quoted = false;
      ++column;
      ++i;
      continue;
    }
    if (c == '"' && trim(cur).empty() && !quoted) {
      // A quoted field: up to the closing quote, across line breaks.
      cur.clear();
      quoted = true;
      ++i;
      for (;;) {
        if (i >= text.size()) {
          std::string more;
          if (!std::getline(in_, more))
            throw CsvSyntaxError{line, column, "unterminated quoted field (a closing \" expected)"};
          ++line_;
          if (!more.empty() && more.back() == '\r') more.pop_back();
          cur.push_back('\n');
          text = more;
          i = 0;
          continue;
        }
        if (text[i] == '"') {
          if (i + 1 < text.size() && text[i + 1] == '"') {
            cur.push_back('"');
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        cur.push_back(text[i++]);
      }
      while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
      if (i < text.size() && text[i] != ',')
        throw CsvSyntaxError{line_, column, "text after a closing quote (a ',' or the end of the line expected)"};
      continue;
    }
    cur.push_back(c);
    ++i;
  }
}

}  // namespace gravsweep::results
