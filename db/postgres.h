// The PostgreSQL backend of db/database.h: RAII over libpq's PGconn and PGresult. Statements are
// written in SQLite's parameter syntax (`?N`, `?`, `:name`) and translated to `$N` once, outside
// string literals, quoted identifiers and comments (`::` casts are left alone). Values are sent as
// text with their type (int8, float8; text and NULL untyped, so the server infers them from the
// column), rows come back as text and are parsed on access.
#pragma once
#include <map>
#include <memory>
#include <string>

#include "db/database.h"

namespace gravsweep::db {

/// Connects to `url` (a libpq connection URI). `lock_timeout_ms` bounds every wait for a lock
/// (SQLite's busy timeout); read_only makes every transaction read-only.
std::unique_ptr<detail::Connection> open_postgres(const std::string& url, int lock_timeout_ms, bool read_only);

/// `sql` with SQLite-style parameters rewritten to `$N`; `names` receives ":name" -> N and
/// `count` the highest parameter number.
std::string translate_parameters(std::string_view sql, std::map<std::string, int>& names, int& count);

}  // namespace gravsweep::db
