#include "scheduler/queue/copy.h"

#include <fmt/format.h>

#include <vector>

#include "engine/core/error.h"
#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

namespace {

/// Copies every row of `table` (all columns, by name) from src to dst; returns the row count.
std::int64_t copy_rows(Database& src, Database& dst, const std::string& table, const std::string& order_by) {
  Statement read(src, fmt::format("SELECT * FROM {} ORDER BY {}", table, order_by));
  std::unique_ptr<Statement> write;
  std::int64_t n = 0;
  while (read.step()) {
    if (!write) {
      std::string names, marks;
      for (int i = 0; i < read.columns(); ++i) {
        names += (i ? ", \"" : "\"") + read.column_name(i) + "\"";
        marks += i ? ", ?" : "?";
      }
      write = std::make_unique<Statement>(dst, fmt::format("INSERT INTO {}({}) VALUES({})", table, names, marks));
    }
    write->reset();
    for (int i = 0; i < read.columns(); ++i) {
      switch (read.column_type(i)) {
        case db::ColumnType::null:
          write->bind_null(i + 1);
          break;
        case db::ColumnType::integer:
          write->bind(i + 1, read.get_int(i));
          break;
        case db::ColumnType::real:
          write->bind(i + 1, read.get_double(i));
          break;
        default:
          write->bind(i + 1, read.get_text(i));
      }
    }
    write->run();
    ++n;
  }
  return n;
}

std::size_t copy_files(const CampaignPaths& from, const CampaignPaths& to) {
  std::error_code ec;
  if (fs::equivalent(from.root, to.root, ec)) return 0;
  std::size_t n = 0;
  for (const std::string& dir : kind_folders()) {
    const fs::path src = from.root / dir;
    if (!fs::is_directory(src, ec)) continue;
    fs::create_directories(to.root / dir);
    for (const auto& e : fs::directory_iterator(src)) {
      const fs::path target = to.root / dir / e.path().filename();
      if (!e.is_regular_file() || fs::exists(target)) continue;
      fs::copy_file(e.path(), target);
      ++n;
    }
  }
  return n;
}

}  // namespace

CopyReport copy_campaign(Database& src, const CampaignPaths& src_paths, Database& dst, const CampaignPaths& dst_paths) {
  CopyReport rep;
  {
    Statement st(src, "SELECT count(*) FROM jobs WHERE state='running'");
    st.step();
    if (st.get_int(0) > 0)
      throw ConfigError(
          fmt::format("'{}': {} job(s) are running; stop the workers (or let them finish) before copying "
                      "the campaign: a copied lease would run the job twice",
                      src.path(), st.get_int(0)));
  }
  ensure_schema(dst);
  Transaction tx(dst);
  {
    Statement st(dst, "SELECT count(*) FROM jobs");
    st.step();
    if (st.get_int(0) > 0)
      throw ConfigError(fmt::format("'{}' already holds a campaign ({} jobs); the destination must be new", dst.path(),
                                    st.get_int(0)));
  }
  Transaction snapshot(src, Transaction::Mode::deferred);  // one consistent read of the source
  copy_rows(src, dst, "sweeps", "sweep_id");
  rep.jobs = copy_rows(src, dst, "jobs", "seq");
  copy_rows(src, dst, "job_deps", "job_id, dep_id");
  copy_rows(src, dst, "sweep_jobs", "sweep_id, job_id");
  rep.attempts = copy_rows(src, dst, "attempts", "attempt_id");
  {  // the dynamic results columns, in their order, with the destination's types
    Statement st(src, "SELECT name, role, sql_type FROM results_columns ORDER BY position");
    while (st.step()) {
      detail::add_result_column(dst, st.get_text(0), st.get_text(1), st.get_text(2));
      ++rep.result_columns;
    }
  }
  rep.results = copy_rows(src, dst, "results", dialect_of(src).insertion_order());
  dialect_of(dst).after_copy(dst);
  snapshot.commit();
  tx.commit();
  rep.files = copy_files(src_paths, dst_paths);
  return rep;
}

}  // namespace gravsweep::queue
