#include "scheduler/queue/table.h"

#include <algorithm>
#include <cstdlib>

namespace gravsweep::queue {

namespace {
bool numeric(const std::string& s) {
  if (s.empty()) return true;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return end && *end == '\0';
}
}  // namespace

std::string render_table(const TextTable& t, const std::string& indent) {
  const std::size_t n = t.header.size();
  std::vector<std::size_t> w(n, 0);
  std::vector<bool> right(n, true);
  for (std::size_t c = 0; c < n; ++c) {
    w[c] = t.header[c].size();
    for (const auto& r : t.rows) {
      if (c < r.size()) {
        w[c] = std::max(w[c], r[c].size());
        if (!numeric(r[c])) right[c] = false;
      }
    }
    if (c < t.right.size()) right[c] = t.right[c];
  }
  std::string out;
  auto line = [&](const std::vector<std::string>& cells) {
    out += indent;
    for (std::size_t c = 0; c < n; ++c) {
      const std::string& s = c < cells.size() ? cells[c] : std::string();
      const std::string pad(w[c] - std::min(w[c], s.size()), ' ');
      if (c) out += "  ";
      out += right[c] ? pad + s : (c + 1 == n ? s : s + pad);
    }
    out += '\n';
  };
  line(t.header);
  std::vector<std::string> rule(n);
  for (std::size_t c = 0; c < n; ++c) rule[c] = std::string(w[c], '-');
  line(rule);
  for (const auto& r : t.rows) line(r);
  return out;
}

std::string csv_escape(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += "\"\"";
    else out.push_back(c);
  }
  return out + "\"";
}

std::string render_csv(const TextTable& t) {
  std::string out;
  auto line = [&](const std::vector<std::string>& cells) {
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (c) out += ',';
      out += csv_escape(cells[c]);
    }
    out += "\r\n";
  };
  line(t.header);
  for (const auto& r : t.rows) line(r);
  return out;
}

}  // namespace gravsweep::queue
