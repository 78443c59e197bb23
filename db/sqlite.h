// The SQLite backend of db/database.h (RAII over sqlite3 and sqlite3_stmt).
#pragma once
#include <memory>
#include <string>

#include "db/database.h"

namespace gravsweep::db {

/// Opens (creating if needed) the file; WAL, synchronous=NORMAL, foreign keys, busy timeout.
std::unique_ptr<detail::Connection> open_sqlite(const std::string& path, int busy_timeout_ms, bool read_only);

}  // namespace gravsweep::db
