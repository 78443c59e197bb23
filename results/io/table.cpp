#include "results/io/table.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "results/io/csv.h"

namespace gravsweep::results {

namespace {

/// The whole cell reads as a number (strtod: also nan and inf).
bool reads_as_number(const std::string& s) {
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return !s.empty() && end && *end == '\0';
}

/// A cell that stands for a missing value: it leaves the column's alignment to the others.
bool placeholder(const std::string& s) { return s.empty() || s == "-"; }

std::string cell_text(const nlohmann::json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) return fmt::format("{}", v.get<double>());
  return v.dump();
}

nlohmann::json cell_json(const std::string& s) {
  if (reads_as_number(s)) {
    const double d = std::strtod(s.c_str(), nullptr);
    if (std::isfinite(d)) return d;
  }
  return s;
}

}  // namespace

Table::Table(std::vector<std::string> columns, TextStyle style) : cols_(std::move(columns)), style_(style) {}

void Table::add(std::vector<std::string> row) {
  row.resize(cols_.size());
  rows_.push_back({std::move(row), {}});
}

void Table::add_values(std::vector<nlohmann::json> row) {
  row.resize(cols_.size());
  Row r;
  for (const auto& v : row) r.text.push_back(cell_text(v));
  r.value = std::move(row);
  rows_.push_back(std::move(r));
}

std::string Table::render(const std::string& format) const {
  if (format == "table") return text();
  if (format == "csv") return csv();
  if (format == "json") return json();
  throw std::invalid_argument(fmt::format("--format '{}': expected table, csv or json", format));
}

std::string Table::text() const {
  const std::size_t n = cols_.size();
  std::vector<std::size_t> w(n);
  std::vector<bool> number(n, false), text(n, false);  // the column holds a number, a text
  for (std::size_t j = 0; j < n; ++j) w[j] = cols_[j].size();
  for (const auto& r : rows_)
    for (std::size_t j = 0; j < n; ++j) {
      w[j] = std::max(w[j], r.text[j].size());
      if (placeholder(r.text[j])) continue;
      (reads_as_number(r.text[j]) ? number : text)[j] = true;
    }
  std::vector<bool> right(n);
  for (std::size_t j = 0; j < n; ++j) right[j] = number[j] && !text[j] && !(j == 0 && style_.label_column);
  std::string out;
  const auto line = [&](const std::vector<std::string>& cells) {
    std::string l;
    for (std::size_t j = 0; j < n; ++j) {
      if (j) l += "  ";
      l += right[j] ? fmt::format("{:>{}}", cells[j], w[j]) : fmt::format("{:<{}}", cells[j], w[j]);
    }
    while (!l.empty() && l.back() == ' ') l.pop_back();
    out += l;
    out += '\n';
  };
  line(cols_);
  if (style_.rule) {
    std::vector<std::string> rule(n);
    for (std::size_t j = 0; j < n; ++j) rule[j] = std::string(w[j], '-');
    line(rule);
  }
  for (const auto& r : rows_) line(r.text);
  return out;
}

std::string Table::csv() const {
  std::string out;
  const auto record = [&](const std::vector<std::string>& cells) {
    for (std::size_t j = 0; j < cells.size(); ++j) {
      if (j) out += ',';
      out += csv_field(cells[j]);
    }
    out += "\r\n";
  };
  record(cols_);
  for (const auto& r : rows_) record(r.text);
  return out;
}

nlohmann::json Table::json_value() const {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& r : rows_) {
    nlohmann::json o = nlohmann::json::object();
    for (std::size_t j = 0; j < cols_.size(); ++j) o[cols_[j]] = r.value.empty() ? cell_json(r.text[j]) : r.value[j];
    a.push_back(std::move(o));
  }
  return a;
}

std::string Table::json() const { return json_value().dump(2) + "\n"; }

std::string Table::render_html() const {
  std::string out = "<table>\n<tr>";
  for (const auto& c : cols_) out += "<th>" + html_escape(c) + "</th>";
  out += "</tr>\n";
  for (const auto& r : rows_) {
    out += "<tr>";
    for (const auto& c : r.text) out += (reads_as_number(c) ? "<td class=\"n\">" : "<td>") + html_escape(c) + "</td>";
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

void Table::print(const std::string& format) const { std::fputs(render(format).c_str(), stdout); }

}  // namespace gravsweep::results
