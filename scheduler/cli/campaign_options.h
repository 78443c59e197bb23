// The options that name a campaign, the same in every verb: --db (an SQLite file, or a PostgreSQL
// server by URL) and, where the verb reads or writes the campaign's files, --files.
#pragma once
#include <CLI/CLI.hpp>

#include <string>

namespace gravsweep::cli {

/// Adds --db with `what` (e.g. "campaign database") and, when `files` is given, --files.
inline void add_campaign_options(CLI::App* sub, std::string& db, std::string* files,
                                 const std::string& what = "campaign database") {
  sub->add_option("--db", db, what + ": an SQLite file, or postgresql://user@host:port/dbname")->capture_default_str();
  if (files)
    sub->add_option("--files", *files,
                    "the campaign's files root (beds/, traces/, ...): default <db stem>.files/ beside an SQLite "
                    "file; required with PostgreSQL (a folder every worker node mounts at the same path)");
}

}  // namespace gravsweep::cli
