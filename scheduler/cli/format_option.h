// --format, the same in every verb: one of the formats of the table writer (results/io/table.h),
// an unknown value refused while parsing (exit code 2) with the same message in every verb, e.g.
// "--format: xml not in {table,csv,json}".
#pragma once
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "results/io/table.h"

namespace gravsweep::cli {

/// Adds --format to `sub` (default: what `format` holds). `formats` narrows the choice for a verb
/// whose output is not one table (status: table or json).
inline CLI::Option* add_format_option(CLI::App* sub, std::string& format,
                                      const std::vector<std::string>& formats = results::table_formats()) {
  std::string help;
  for (std::size_t i = 0; i < formats.size(); ++i)
    help += (i == 0 ? "" : i + 1 == formats.size() ? " or " : ", ") + formats[i];
  return sub->add_option("--format", format, help)->check(CLI::IsMember(formats))->capture_default_str();
}

}  // namespace gravsweep::cli
