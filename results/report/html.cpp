// The self-contained HTML report (see html.h).
#include "results/report/html.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace gravsweep::results {

namespace {

constexpr const char* kStyle = R"(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em;
       color: #222; line-height: 1.45; }
h1 { font-size: 1.6em; border-bottom: 2px solid #345; padding-bottom: .2em; }
h2 { font-size: 1.25em; margin-top: 1.8em; color: #234; }
.verdict { background: #eef5ee; border-left: 6px solid #2a7a2a; padding: .8em 1em; font-size: 1.05em; }
.summary { color: #444; }
table { border-collapse: collapse; margin: .6em 0 1.2em; font-size: .9em; }
th, td { border: 1px solid #bbb; padding: .25em .6em; }
th { background: #e8ecf0; text-align: left; }
td.n { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
figure { margin: 1.5em 0; }
figure img { max-width: 100%; border: 1px solid #ccc; }
figcaption { font-size: .92em; color: #333; margin-top: .3em; }
.label { font-weight: bold; margin: .4em 0 0; }
)";

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace

std::string base64(const std::string& in) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(in[i]) << 16) | (static_cast<unsigned char>(in[i + 1]) << 8) |
                       static_cast<unsigned char>(in[i + 2]);
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  const std::size_t rest = in.size() - i;
  if (rest > 0) {
    unsigned v = static_cast<unsigned char>(in[i]) << 16;
    if (rest == 2) v |= static_cast<unsigned char>(in[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::filesystem::path write_html_report(const std::string& dir, const HtmlReport& r) {
  namespace fs = std::filesystem;
  std::string h = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n"
      "<style>{}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
      html_escape(r.title), kStyle, html_escape(r.title));
  h += fmt::format("<p class=\"summary\">{}</p>\n", html_escape(r.summary));
  if (!r.issues.empty()) {
    h += "<details><summary>" + fmt::format("{} trials not usable", r.issues.size()) + "</summary><ul>\n";
    for (const auto& is : r.issues) h += "<li>" + html_escape(is) + "</li>\n";
    h += "</ul></details>\n";
  }
  h += "<h2>Verdict</h2>\n<div class=\"verdict\">" + html_escape(r.verdict) + "</div>\n";
  for (const auto& s : r.sections) {
    h += "<h2>" + html_escape(s.heading) + "</h2>\n";
    if (!s.text.empty()) h += "<p>" + html_escape(s.text) + "</p>\n";
    for (const auto& [label, table] : s.tables) {
      if (!label.empty()) h += "<p class=\"label\">" + html_escape(label) + "</p>\n";
      h += table.render_html();
    }
  }
  h += "<h2>Figures</h2>\n";
  for (const auto& f : r.figures) {
    const fs::path p = fs::path(dir) / f.file;
    if (!fs::exists(p)) continue;
    h += fmt::format(
        "<figure id=\"{}\">\n<img alt=\"{}\" src=\"data:image/png;base64,{}\">\n"
        "<figcaption><b>{}</b>: {}</figcaption>\n</figure>\n",
        html_escape(f.file), html_escape(f.file), base64(read_bytes(p)), html_escape(f.file), html_escape(f.caption));
  }
  h += "</body>\n</html>\n";
  const fs::path out = fs::path(dir) / "index.html";
  const fs::path tmp = fs::path(dir) / "index.html.tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << h;
    if (!f) throw std::runtime_error(fmt::format("{}: cannot write", tmp.string()));
  }
  fs::rename(tmp, out);
  return out;
}

}  // namespace gravsweep::results
