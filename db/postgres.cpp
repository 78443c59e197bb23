#include "db/postgres.h"

#include <fmt/format.h>
#include <libpq-fe.h>

#include <cctype>
#include <cstdlib>
#include <optional>
#include <vector>

namespace gravsweep::db {

namespace {

// Type OIDs of the server's built-in types (src/include/catalog/pg_type.dat).
constexpr Oid kBoolOid = 16, kByteaOid = 17, kInt8Oid = 20, kInt2Oid = 21, kInt4Oid = 23, kOidOid = 26;
constexpr Oid kFloat4Oid = 700, kFloat8Oid = 701, kNumericOid = 1700;

struct ResultDeleter {
  void operator()(PGresult* r) const { PQclear(r); }
};
using Result = std::unique_ptr<PGresult, ResultDeleter>;
struct ConnDeleter {
  void operator()(PGconn* c) const { PQfinish(c); }
};

/// Serialisation failures, deadlocks and lock timeouts: the transaction can be retried.
bool retryable(const char* sqlstate) {
  if (!sqlstate) return false;
  const std::string s(sqlstate);
  return s == "40001" || s == "40P01" || s == "55P03";
}

/// The connection is gone (class 08: connection exception; 57P01-57P03: the server shuts down,
/// crashed or is starting): a new connection may succeed once the server is back.
bool connection_gone(const char* sqlstate) {
  if (!sqlstate) return false;
  const std::string s(sqlstate);
  return s.rfind("08", 0) == 0 || s == "57P01" || s == "57P02" || s == "57P03";
}

void no_notices(void*, const char*) {}

class PgConnection;

class PgCursor final : public detail::Cursor {
 public:
  PgCursor(PgConnection& conn, std::string_view sql);

  void bind_int(int idx, std::int64_t v) override { set(idx, std::to_string(v), kInt8Oid); }
  void bind_double(int idx, double v) override { set(idx, fmt::format("{}", v), kFloat8Oid); }
  void bind_text(int idx, std::string_view v) override { set(idx, std::string(v), 0); }
  void bind_null(int idx) override {
    slot(idx);
    values_[static_cast<std::size_t>(idx - 1)].reset();
    types_[static_cast<std::size_t>(idx - 1)] = 0;
  }
  [[nodiscard]] int index_of(const char* name) const override {
    const auto it = names_.find(name);
    if (it == names_.end()) throw DbError(fmt::format("no SQL parameter '{}' in: {}", name, sql_.substr(0, 200)));
    return it->second;
  }
  bool step() override;
  void reset() override {
    result_.reset();
    row_ = -1;
    for (auto& v : values_) v.reset();
    for (auto& t : types_) t = 0;
  }
  [[nodiscard]] int columns() const override { return result_ ? PQnfields(result_.get()) : 0; }
  [[nodiscard]] std::string column_name(int i) const override { return PQfname(result_.get(), i); }
  [[nodiscard]] ColumnType column_type(int i) const override {
    if (PQgetisnull(result_.get(), row_, i)) return ColumnType::null;
    switch (PQftype(result_.get(), i)) {
      case kBoolOid:
      case kInt8Oid:
      case kInt2Oid:
      case kInt4Oid:
      case kOidOid:
        return ColumnType::integer;
      case kFloat4Oid:
      case kFloat8Oid:
      case kNumericOid:
        return ColumnType::real;
      case kByteaOid:
        return ColumnType::blob;
      default:
        return ColumnType::text;
    }
  }
  [[nodiscard]] std::int64_t get_int(int i) const override {
    const char* v = value(i);
    if (!v) return 0;
    if (v[0] == 't' && v[1] == 0) return 1;
    if (v[0] == 'f' && v[1] == 0) return 0;
    for (const char* p = v; *p; ++p)
      if (*p == '.' || *p == 'e' || *p == 'E') return static_cast<std::int64_t>(std::strtod(v, nullptr));
    return std::strtoll(v, nullptr, 10);
  }
  [[nodiscard]] double get_double(int i) const override {
    const char* v = value(i);
    if (!v) return 0;
    if (v[0] == 't' && v[1] == 0) return 1;
    if (v[0] == 'f' && v[1] == 0) return 0;
    return std::strtod(v, nullptr);
  }
  [[nodiscard]] std::string get_text(int i) const override {
    const char* v = value(i);
    return v ? std::string(v, static_cast<std::size_t>(PQgetlength(result_.get(), row_, i))) : std::string();
  }

 private:
  PgConnection& conn_;
  std::string sql_, translated_;
  std::map<std::string, int> names_;
  std::vector<std::optional<std::string>> values_;
  std::vector<Oid> types_;
  Result result_;
  int row_ = -1;

  void slot(int idx) {
    if (idx < 1 || idx > static_cast<int>(values_.size()))
      throw DbError(
          fmt::format("SQL parameter {} out of range 1..{} in: {}", idx, values_.size(), sql_.substr(0, 200)));
  }
  void set(int idx, std::string v, Oid type) {
    slot(idx);
    values_[static_cast<std::size_t>(idx - 1)] = std::move(v);
    types_[static_cast<std::size_t>(idx - 1)] = type;
  }
  [[nodiscard]] const char* value(int i) const {
    if (!result_ || row_ < 0 || PQgetisnull(result_.get(), row_, i)) return nullptr;
    return PQgetvalue(result_.get(), row_, i);
  }
};

class PgConnection final : public detail::Connection {
 public:
  PgConnection(const std::string& url, int lock_timeout_ms, bool read_only) : url_(url) {
    conn_.reset(PQconnectdb(url.c_str()));
    if (!conn_ || PQstatus(conn_.get()) != CONNECTION_OK)
      throw DbError(fmt::format("cannot connect to PostgreSQL at '{}': {}", url,
                                conn_ ? trimmed(PQerrorMessage(conn_.get())) : std::string("out of memory")),
                    DbError::Kind::connection_lost);
    PQsetNoticeProcessor(conn_.get(), no_notices, nullptr);
    exec(fmt::format("SET lock_timeout = {}; SET client_min_messages = warning{}", lock_timeout_ms,
                     read_only ? "; SET default_transaction_read_only = on" : ""));
  }

  [[nodiscard]] Backend backend() const override { return Backend::postgres; }
  void exec(std::string_view sql) override {
    const std::string s(sql);
    Result r(PQexec(conn_.get(), s.c_str()));
    check(r.get(), s);
  }
  std::unique_ptr<detail::Cursor> prepare(std::string_view sql) override {
    return std::make_unique<PgCursor>(*this, sql);
  }
  [[nodiscard]] int changes() const override { return changes_; }
  void begin(TxMode mode) override {
    exec(mode == TxMode::deferred ? "BEGIN ISOLATION LEVEL REPEATABLE READ" : "BEGIN");
  }
  void rollback() noexcept override {
    PGresult* r = PQexec(conn_.get(), "ROLLBACK");
    PQclear(r);
  }

  /// Runs one statement with its parameters; throws DbError naming the server's message.
  Result run(const std::string& sql, const std::string& translated,
             const std::vector<std::optional<std::string>>& values, const std::vector<Oid>& types) {
    std::vector<const char*> ptrs(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) ptrs[i] = values[i] ? values[i]->c_str() : nullptr;
    Result r(PQexecParams(conn_.get(), translated.c_str(), static_cast<int>(values.size()), types.data(), ptrs.data(),
                          nullptr, nullptr, 0));
    check(r.get(), sql);
    const std::string status = PQcmdStatus(r.get());
    if (status.rfind("INSERT", 0) == 0 || status.rfind("UPDATE", 0) == 0 || status.rfind("DELETE", 0) == 0)
      changes_ = std::atoi(PQcmdTuples(r.get()));
    return r;
  }

 private:
  std::unique_ptr<PGconn, ConnDeleter> conn_;
  std::string url_;
  int changes_ = 0;

  static std::string trimmed(const char* m) {
    std::string s = m ? m : "";
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
    return s;
  }
  void check(PGresult* r, const std::string& sql) const {
    const ExecStatusType st = r ? PQresultStatus(r) : PGRES_FATAL_ERROR;
    if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK || st == PGRES_EMPTY_QUERY) return;
    const char* state = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : nullptr;
    const std::string msg = trimmed(r ? PQresultErrorMessage(r) : PQerrorMessage(conn_.get()));
    const bool gone = PQstatus(conn_.get()) == CONNECTION_BAD || connection_gone(state);
    throw DbError(
        fmt::format("database '{}': {} [SQLSTATE {}] (in: {})", url_, msg, state ? state : "none", sql.substr(0, 200)),
        gone               ? DbError::Kind::connection_lost
        : retryable(state) ? DbError::Kind::busy
                           : DbError::Kind::other);
  }
};

PgCursor::PgCursor(PgConnection& conn, std::string_view sql) : conn_(conn), sql_(sql) {
  int count = 0;
  translated_ = translate_parameters(sql_, names_, count);
  values_.resize(static_cast<std::size_t>(count));
  types_.assign(static_cast<std::size_t>(count), 0);
}

bool PgCursor::step() {
  if (!result_) {  // the first step runs the statement (again after the last row, like SQLite)
    result_ = conn_.run(sql_, translated_, values_, types_);
    row_ = -1;
  }
  if (row_ + 1 < PQntuples(result_.get())) {
    ++row_;
    return true;
  }
  result_.reset();
  row_ = -1;
  return false;
}

}  // namespace

std::string translate_parameters(std::string_view sql, std::map<std::string, int>& names, int& count) {
  std::string out;
  out.reserve(sql.size() + 16);
  count = 0;
  const auto is_ident = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (std::size_t i = 0; i < sql.size(); ++i) {
    const char c = sql[i];
    if (c == '\'' || c == '"') {  // a literal or a quoted identifier, copied whole ('' and "" escape)
      const std::size_t end = sql.find(c, i + 1);
      const std::size_t stop = end == std::string_view::npos ? sql.size() : end + 1;
      out.append(sql.substr(i, stop - i));
      i = stop - 1;
    } else if (c == '-' && i + 1 < sql.size() && sql[i + 1] == '-') {  // a comment to the end of the line
      const std::size_t end = sql.find('\n', i);
      const std::size_t stop = end == std::string_view::npos ? sql.size() : end;
      out.append(sql.substr(i, stop - i));
      i = stop - 1;
    } else if (c == '?') {
      std::size_t j = i + 1;
      while (j < sql.size() && std::isdigit(static_cast<unsigned char>(sql[j]))) ++j;
      const int n = j > i + 1 ? std::atoi(std::string(sql.substr(i + 1, j - i - 1)).c_str()) : count + 1;
      count = std::max(count, n);
      out += fmt::format("${}", n);
      i = j - 1;
    } else if (c == ':' && i + 1 < sql.size() && sql[i + 1] == ':') {  // a cast
      out += "::";
      ++i;
    } else if (c == ':' && i + 1 < sql.size() &&
               (std::isalpha(static_cast<unsigned char>(sql[i + 1])) || sql[i + 1] == '_') &&
               (i == 0 || !is_ident(sql[i - 1]))) {
      std::size_t j = i + 1;
      while (j < sql.size() && is_ident(sql[j])) ++j;
      const std::string name(sql.substr(i, j - i));
      auto [it, added] = names.emplace(name, count + 1);
      if (added) ++count;
      out += fmt::format("${}", it->second);
      i = j - 1;
    } else {
      out += c;
    }
  }
  return out;
}

std::unique_ptr<detail::Connection> open_postgres(const std::string& url, int lock_timeout_ms, bool read_only) {
  return std::make_unique<PgConnection>(url, lock_timeout_ms, read_only);
}

}  // namespace gravsweep::db
