// The report you can send: one self-contained HTML page, REPORT/index.html, with the
// verdict, the tables and every figure (PNG, base64-embedded) with a one-line caption. Nothing is
// linked: the file opens in any browser, mailed or copied alone.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "results/io/table.h"

namespace gravsweep::results {

struct HtmlSection {
  std::string heading;
  std::string text;                                   ///< a paragraph before the tables (plain text, escaped)
  std::vector<std::pair<std::string, Table>> tables;  ///< (label, table); the label may be empty
};

struct HtmlFigure {
  std::string file;     ///< PNG inside the report folder
  std::string caption;  ///< one line
};

struct HtmlReport {
  std::string title;
  std::string summary;              ///< what was read (plain text)
  std::vector<std::string> issues;  ///< trials that could not be used, one line each
  std::string verdict;
  std::vector<HtmlSection> sections;
  std::vector<HtmlFigure> figures;  ///< those missing from the folder are left out
};

/// RFC 4648 base64 of `bytes`.
std::string base64(const std::string& bytes);

/// Writes <dir>/index.html (temporary name, then renamed); returns its path.
std::filesystem::path write_html_report(const std::string& dir, const HtmlReport& report);

}  // namespace gravsweep::results
