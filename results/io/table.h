// The one table writer of every verb and of the report: aligned text, CSV (RFC 4180) and JSON
// (`--format table|csv|json`), plus the HTML <table> of the report page. It lives in results/ so
// that results/ (the report) and scheduler/ (every CLI verb) can both use it.
#pragma once
#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace gravsweep::results {

/// &, <, >, " escaped for HTML text and attributes.
inline std::string html_escape(const std::string& x) {
  std::string o;
  for (char c : x)
    o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : c == '"' ? "&quot;" : std::string(1, c);
  return o;
}

/// The formats a table is written in, as `--format` takes them (scheduler/cli/format_option.h).
inline const std::vector<std::string>& table_formats() {
  static const std::vector<std::string> formats{"table", "csv", "json"};
  return formats;
}

/// The look of the aligned text. A column of numbers (`nan` included) is right-aligned, any other
/// left-aligned; empty and `-` cells stand for missing values and leave the choice to the others
/// (a column of them alone is left-aligned). Trailing spaces are trimmed.
struct TextStyle {
  bool rule = false;         ///< a line of dashes under the header
  bool label_column = true;  ///< the first column (a row label) left-aligned whatever it holds
};
/// The look of the queue verbs (status, results, pile): a rule under the header, every column
/// aligned by what it holds. The default TextStyle is the look of the model verbs and the report.
inline constexpr TextStyle kRuledText{true, false};

class Table {
 public:
  explicit Table(std::vector<std::string> columns, TextStyle style = {});

  /// A row of text cells (missing ones empty). JSON writes a cell that reads as a finite number
  /// as a number, any other as a string.
  void add(std::vector<std::string> row);
  /// A row of typed values (null, numbers, strings, objects). JSON writes them as they are; text
  /// and CSV write null as an empty cell, a number in its shortest exact form, a string as it is.
  void add_values(std::vector<nlohmann::json> row);

  [[nodiscard]] std::size_t size() const { return rows_.size(); }
  [[nodiscard]] const std::vector<std::string>& columns() const { return cols_; }

  /// `table`, `csv` or `json`; throws std::invalid_argument on anything else (the verbs refuse an
  /// unknown --format while parsing, with exit code 2).
  [[nodiscard]] std::string render(const std::string& format) const;
  [[nodiscard]] std::string text() const;
  /// RFC 4180: CRLF after every record (the header first), a field with a comma, a double quote
  /// or a line break in double quotes with its quotes doubled.
  [[nodiscard]] std::string csv() const;
  /// An array with one object per row, keyed by column.
  [[nodiscard]] std::string json() const;
  /// The same array as a value, for a verb that prints several tables as one JSON document.
  [[nodiscard]] nlohmann::json json_value() const;
  /// An HTML <table> (cells escaped; numeric cells right-aligned by the page's style).
  [[nodiscard]] std::string render_html() const;
  void print(const std::string& format) const;

 private:
  struct Row {
    std::vector<std::string> text;      ///< what text, CSV and HTML write
    std::vector<nlohmann::json> value;  ///< empty for a row of text cells
  };
  std::vector<std::string> cols_;
  TextStyle style_;
  std::vector<Row> rows_;
};

/// A number for a table cell: `prec` significant digits, `nan` when not finite.
inline std::string num(double x, int prec = 4) {
  if (!std::isfinite(x)) return "nan";
  return fmt::format("{:.{}g}", x, prec);
}

}  // namespace gravsweep::results
