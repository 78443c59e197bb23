// A small table for CLI output: aligned text, CSV or JSON (`--format table|csv|json`).
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "results/measurements/csv.h"

namespace gravsweep::results {

/// &, <, >, " escaped for HTML text and attributes.
inline std::string html_escape(const std::string& x) {
  std::string o;
  for (char c : x) o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : c == '"' ? "&quot;" : std::string(1, c);
  return o;
}

class Table {
 public:
  explicit Table(std::vector<std::string> columns) : cols_(std::move(columns)) {}
  void add(std::vector<std::string> row) {
    row.resize(cols_.size());
    rows_.push_back(std::move(row));
  }
  [[nodiscard]] std::string render(const std::string& format) const {
    std::string out;
    if (format == "csv") {  // RFC 4180: a field with a comma, a quote or a line break is quoted
      for (std::size_t j = 0; j < cols_.size(); ++j) out += (j ? "," : "") + csv_field(cols_[j]);
      out += "\n";
      for (const auto& r : rows_) {
        for (std::size_t j = 0; j < r.size(); ++j) out += (j ? "," : "") + csv_field(r[j]);
        out += "\n";
      }
    } else if (format == "json") {
      nlohmann::json a = nlohmann::json::array();
      for (const auto& r : rows_) {
        nlohmann::json o;
        for (std::size_t j = 0; j < r.size(); ++j) {
          double d;
          char* end = nullptr;
          d = std::strtod(r[j].c_str(), &end);
          if (!r[j].empty() && end && *end == '\0' && std::isfinite(d)) o[cols_[j]] = d;
          else o[cols_[j]] = r[j];
        }
        a.push_back(o);
      }
      out = a.dump(2) + "\n";
    } else if (format == "table") {
      std::vector<std::size_t> w(cols_.size());
      for (std::size_t j = 0; j < cols_.size(); ++j) w[j] = cols_[j].size();
      for (const auto& r : rows_)
        for (std::size_t j = 0; j < r.size(); ++j) w[j] = std::max(w[j], r[j].size());
      // Numbers right-aligned, text left-aligned (a column is numeric when all its cells are).
      std::vector<bool> numeric(cols_.size(), true);
      for (const auto& r : rows_)
        for (std::size_t j = 0; j < r.size(); ++j) {
          char* end = nullptr;
          std::strtod(r[j].c_str(), &end);
          if (!(r[j].empty() || r[j] == "nan" || r[j] == "-" || (end && *end == '\0'))) numeric[j] = false;
        }
      numeric[0] = false;
      auto line = [&](const std::vector<std::string>& r) {
        std::string l;
        for (std::size_t j = 0; j < r.size(); ++j)
          l += (j ? "  " : "") + (numeric[j] ? fmt::format("{:>{}}", r[j], w[j]) : fmt::format("{:<{}}", r[j], w[j]));
        while (!l.empty() && l.back() == ' ') l.pop_back();
        out += l + "\n";
      };
      line(cols_);
      for (const auto& r : rows_) line(r);
    } else {
      throw std::invalid_argument(fmt::format("--format '{}': expected table, csv or json", format));
    }
    return out;
  }
  /// An HTML <table> (cells escaped; numeric cells right-aligned by the page's style).
  [[nodiscard]] std::string render_html() const {
    const auto& esc = html_escape;
    std::string out = "<table>\n<tr>";
    for (const auto& c : cols_) out += "<th>" + esc(c) + "</th>";
    out += "</tr>\n";
    for (const auto& r : rows_) {
      out += "<tr>";
      for (const auto& c : r) {
        char* end = nullptr;
        std::strtod(c.c_str(), &end);
        const bool number = !c.empty() && end && *end == '\0';
        out += (number ? "<td class=\"n\">" : "<td>") + esc(c) + "</td>";
      }
      out += "</tr>\n";
    }
    return out + "</table>\n";
  }
  void print(const std::string& format) const { std::fputs(render(format).c_str(), stdout); }

 private:
  std::vector<std::string> cols_;
  std::vector<std::vector<std::string>> rows_;
};

inline std::string num(double x, int prec = 4) {
  if (!std::isfinite(x)) return "nan";
  return fmt::format("{:.{}g}", x, prec);
}

}  // namespace gravsweep::results
