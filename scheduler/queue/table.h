// Output of the scheduler's verbs: aligned tables (numbers right-aligned), CSV (RFC 4180 quoting).
#pragma once
#include <string>
#include <vector>

namespace gravsweep::queue {

struct TextTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<bool> right;  ///< per column; empty = guess (right when every cell looks numeric)
};

std::string render_table(const TextTable& t, const std::string& indent = "");
std::string render_csv(const TextTable& t);
std::string csv_escape(const std::string& s);

}  // namespace gravsweep::queue
