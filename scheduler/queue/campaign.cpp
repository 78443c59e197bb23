#include "scheduler/queue/campaign.h"

#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <optional>

#include "engine/core/error.h"
#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

namespace {

constexpr const char* kQueueTables = "'queue_meta','jobs','attempts','results'";

/// Number of the queue's tables present (queue_meta, jobs, attempts, results), read without
/// writing anything to the file.
int queue_tables(const std::string& path) {
  try {
    Database probe(path, 30000, /*read_only=*/true);
    return dialect_of(probe).tables_present(probe, kQueueTables);
  } catch (const db::DbError& e) {
    if (e.not_a_database())
      throw ConfigError(fmt::format("'{}' is not a gravsweep campaign: not a SQLite database ({})", path, e.what()));
    throw;
  }
}

std::string schema_version(Database& db) {
  Statement get(db, "SELECT value FROM queue_meta WHERE key='schema_version'");
  return get.step() ? get.get_text(0) : std::string();
}

double mtime_s(const fs::path& p) {
  struct stat st {};
  if (::lstat(p.c_str(), &st) != 0) return 0;
  return static_cast<double>(st.st_mtim.tv_sec) + 1e-9 * static_cast<double>(st.st_mtim.tv_nsec);
}

/// Moves `from` to `to` (creating `to`'s folder); false when it failed (e.g. vanished meanwhile).
bool move_file(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::create_directories(to.parent_path(), ec);
  fs::rename(from, to, ec);
  return !ec;
}

/// True for the name of a batch `quarantine_orphans` makes: "<milliseconds>-<pid>".
bool is_batch_name(const std::string& name) {
  const auto dash = name.find('-');
  if (dash == std::string::npos || dash == 0 || dash + 1 == name.size()) return false;
  for (std::size_t i = 0; i < name.size(); ++i)
    if (i != dash && (name[i] < '0' || name[i] > '9')) return false;
  return true;
}

/// A real folder (not a symbolic link to one, not a file).
bool real_directory(const fs::path& p) {
  std::error_code ec;
  return fs::symlink_status(p, ec).type() == fs::file_type::directory;
}

/// Regular files under `p` (the entry itself when it is one), never through a symbolic link.
std::size_t own_files(const fs::path& p) {
  std::error_code ec;
  const auto type = fs::symlink_status(p, ec).type();
  if (type == fs::file_type::regular) return 1;
  return type == fs::file_type::directory ? count_files(p) : 0;
}

/// Removes (or, when referenced again, puts back) what earlier resumes quarantined: only the
/// entries of the output folders of gravsweep's own batches (`<ms>-<pid>/{beds,traces,noop,tmp}/`),
/// each a real folder; a symbolic link is removed as a link, never followed. Anything else a user
/// put under `quarantine/` stays, and so does a batch folder that still holds it.
void purge_quarantine(Database& db, const CampaignPaths& paths, OrphanReport& rep) {
  const fs::path qroot = paths.root / "quarantine";
  std::error_code ec;
  if (!real_directory(qroot)) return;  // check_quarantine_folder refused a link before
  const Referenced ref = referenced_files(db);
  for (const auto& batch : fs::directory_iterator(qroot, ec)) {
    if (!is_batch_name(batch.path().filename().string()) || !real_directory(batch.path())) continue;
    for (const std::string& dir : output_folders()) {
      const fs::path d = batch.path() / dir;
      if (!real_directory(d)) continue;
      for (const auto& e : fs::directory_iterator(d, ec)) {
        const std::string rel = (fs::path(dir) / e.path().filename()).string();
        const fs::path home = paths.root / rel;
        if (ref.refers_to(rel) && !fs::exists(fs::symlink_status(home, ec)) && move_file(e.path(), home)) {
          rep.restored.push_back(rel);
          continue;
        }
        rep.purged += own_files(e.path());
        fs::remove_all(e.path(), ec);  // removes a symbolic link itself, never its target
      }
      fs::remove(d, ec);  // only when empty
    }
    fs::remove(batch.path(), ec);  // only when empty: a user's file in it stays
  }
}

/// The schema of a campaign just opened: created (create), checked, and migrated (write).
void prepare_opened(Database& db, OpenMode mode) {
  if (mode == OpenMode::create) {
    ensure_schema(db);
    return;
  }
  check_campaign(db);
  if (mode == OpenMode::write) {
    migrate_paths(db);
    add_missing_columns(db);
  }
}

}  // namespace

std::size_t count_files(const fs::path& dir) {
  std::size_t n = 0;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  for (auto it = fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) ++n;
  return n;
}

std::string files_rel(const std::string& stored) {
  const fs::path p(stored);
  fs::path after;
  bool found = false;
  for (const auto& part : p) {
    const std::string s = part.string();
    if (s.size() > 6 && s.compare(s.size() - 6, 6, ".files") == 0) {
      found = true;
      after.clear();
    } else if (found) {
      after /= part;
    }
  }
  return found ? after.string() : stored;
}

void check_campaign(Database& db) {
  const std::string v = schema_version(db);
  if (v != "1" && v != std::to_string(kSchemaVersion))
    throw ConfigError(fmt::format("'{}': job queue schema version '{}' (this gravsweep knows 1 and {})", db.path(), v,
                                  kSchemaVersion));
}

void migrate_paths(Database& db) {
  Transaction tx(db);
  if (schema_version(db) != "1") return;
  struct Column {
    const char *table, *column;
  };
  for (const Column c :
       {Column{"jobs", "output_path"}, Column{"attempts", "output_path"}, Column{"results", "trace_path"}}) {
    std::vector<std::pair<std::int64_t, std::string>> rows;
    {
      Statement st(db, fmt::format("SELECT rowid, {1} FROM {0} WHERE {1} IS NOT NULL", c.table, c.column));
      while (st.step()) {
        std::string rel = files_rel(st.get_text(1));
        if (rel != st.get_text(1)) rows.emplace_back(st.get_int(0), std::move(rel));
      }
    }
    Statement up(db, fmt::format("UPDATE {} SET {}=? WHERE rowid=?", c.table, c.column));
    for (const auto& [rowid, rel] : rows) {
      up.reset();
      up.bind(1, rel).bind(2, rowid);
      up.run();
    }
  }
  Statement put(db, "UPDATE queue_meta SET value=? WHERE key='schema_version'");
  put.bind(1, std::to_string(kSchemaVersion));
  put.run();
  tx.commit();
}

Database open_campaign(const fs::path& db_path, OpenMode mode, const fs::path& files_root) {
  const std::string name = db_path.string();
  const bool server = db::is_postgres_url(name);
  // Reading a server campaign needs no files root (status, results); everything else does.
  std::optional<CampaignPaths> paths;
  if (!server || !files_root.empty() || mode != OpenMode::read) paths.emplace(db_path, files_root);
  std::error_code ec;
  if (fs::is_directory(db_path, ec))
    throw ConfigError(fmt::format("--db '{}': is a directory, expected a campaign database file", name));
  const std::size_t files = paths ? count_files(paths->root) : 0;
  const std::string beside =
      files > 0 ? fmt::format(" next to '{}' holding {} file(s)", paths->root.string(), files) : std::string();
  const std::string keep = files > 0 ? "; refusing to start a new campaign over another one's outputs (restore the "
                                       "database from a backup, or move the folder away); nothing was changed"
                                     : "";
  const auto refuse_tables = [&](int tables) {
    if ((tables == 0 && (mode != OpenMode::create || files > 0)) || (tables > 0 && tables < 4))
      throw ConfigError(
          fmt::format("'{}' is not a gravsweep campaign: {} of the job queue's 4 tables (queue_meta, "
                      "jobs, attempts, results) found{}{}",
                      name, tables, beside, keep));
  };
  if (server) {
    Database db(name, 30000, mode == OpenMode::read);
    refuse_tables(dialect_of(db).tables_present(db, kQueueTables));
    prepare_opened(db, mode);
    return db;
  }
  if (!fs::exists(db_path, ec)) {
    if (mode != OpenMode::create || files > 0)
      throw ConfigError(fmt::format("--db: no campaign database at '{}'{}{}", name, beside,
                                    files > 0 ? keep : " (run `gravsweep submit` first)"));
  } else if (fs::file_size(db_path, ec) == 0) {
    if (mode != OpenMode::create || files > 0)
      throw ConfigError(
          fmt::format("'{}' is not a gravsweep campaign: the file is empty (0 bytes){}{}", name, beside, keep));
  } else {
    refuse_tables(queue_tables(name));
  }
  Database db(name);
  prepare_opened(db, mode);
  return db;
}

bool Referenced::refers_to(const std::string& rel) const {
  if (done.count(rel) || live.count(rel)) return true;
  const std::string name = fs::path(rel).filename().string();
  for (const auto& p : live_prefixes)
    if (name.rfind(p, 0) == 0) return true;
  return false;
}

Referenced referenced_files(Database& db) {
  Referenced r;
  r.taken_at_s = now_s();
  Transaction tx(db, Transaction::Mode::deferred);  // one read snapshot for both queries
  {
    Statement st(db, "SELECT output_path FROM jobs WHERE state='done' AND output_path IS NOT NULL");
    while (st.step()) r.done.insert(files_rel(st.get_text(0)));
  }
  {
    Statement st(db, "SELECT job_id, attempt, coalesce(output_path, '') FROM attempts WHERE outcome='running'");
    while (st.step()) {
      if (!st.get_text(2).empty()) r.live.insert(files_rel(st.get_text(2)));
      r.live_prefixes.push_back(fmt::format("{}.a{}.", st.get_text(0), st.get_int(1)));
    }
  }
  tx.commit();
  return r;
}

void check_files_belong(Database& db, const CampaignPaths& paths) {
  std::size_t total = 0, missing = 0;
  std::string first;
  Statement st(db, "SELECT output_path FROM jobs WHERE state='done' AND output_path IS NOT NULL");
  std::error_code ec;
  while (st.step()) {
    ++total;
    const fs::path p = paths.abs(st.get_text(0));
    if (fs::exists(p, ec)) continue;
    if (missing++ == 0) first = p.string();
  }
  if (total > 0 && 2 * missing > total)
    throw ConfigError(fmt::format(
        "'{}' and '{}' do not belong together: {} of {} files that done jobs refer to are missing (first: {}); "
        "refusing to remove anything. Keep the campaign's folder beside its database as '<db stem>.files/' (a "
        "renamed copy needs its folder renamed too), or pass --keep-orphans",
        db.path(), paths.root.string(), missing, total, first));
}

void check_quarantine_folder(const CampaignPaths& paths) {
  const fs::path qroot = paths.root / "quarantine";
  std::error_code ec;
  const auto st = fs::symlink_status(qroot, ec);
  if (!fs::exists(st) || st.type() == fs::file_type::directory) return;
  throw ConfigError(fmt::format(
      "'{}' is {}, expected the campaign's own quarantine folder: resume moves orphans into it and deletes what "
      "it put there, and never does either through a link; nothing was moved or removed (remove the link, or "
      "pass --keep-orphans)",
      qroot.string(), st.type() == fs::file_type::symlink ? "a symbolic link" : "not a folder"));
}

OrphanReport quarantine_orphans(Database& db, const CampaignPaths& paths, bool dry_run, double min_age_s) {
  OrphanReport rep;
  check_quarantine_folder(paths);
  if (!dry_run) purge_quarantine(db, paths, rep);
  struct Candidate {
    fs::path path;
    std::string rel;
  };
  std::vector<Candidate> found;
  std::error_code ec;
  for (const std::string& dir : output_folders()) {
    const fs::path d = paths.root / dir;
    if (!fs::is_directory(d, ec)) continue;
    for (const auto& e : fs::directory_iterator(d, ec))
      found.push_back({e.path(), (fs::path(dir) / e.path().filename()).string()});
  }
  // The snapshot is taken after the listing: a file created after it began is younger than the
  // cutoff, and one a job or attempt of the snapshot refers to is kept by name.
  const Referenced ref = referenced_files(db);
  const double cutoff_s = ref.taken_at_s - min_age_s;
  const fs::path batch = paths.root / "quarantine" / fmt::format("{:.0f}-{}", now_s() * 1000, getpid());
  for (const auto& c : found) {
    if (ref.refers_to(c.rel) || mtime_s(c.path) >= cutoff_s) continue;
    if (dry_run) {
      rep.moved.push_back(c.rel);
    } else if (mtime_s(c.path) < cutoff_s && move_file(c.path, batch / c.rel)) {
      rep.moved.push_back(c.rel);
    }
  }
  if (dry_run || rep.moved.empty()) return rep;
  // Anything the database refers to by now goes back (none should: their names are never reused).
  const Referenced after = referenced_files(db);
  for (const auto& rel : rep.moved)
    if (after.refers_to(rel) && !fs::exists(paths.root / rel, ec) && move_file(batch / rel, paths.root / rel))
      rep.restored.push_back(rel);
  return rep;
}

}  // namespace gravsweep::queue
