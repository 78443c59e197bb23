// `gravsweep campaign copy SRC DST`: a campaign moved between backends (SQLite <-> PostgreSQL).
#include <fmt/format.h>

#include <memory>
#include <string>

#include "scheduler/cli/verbs.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/copy.h"

namespace gravsweep::cli {

namespace {

struct CopyOptions {
  std::string src, dst, src_files, dst_files;
};

void run_copy(const CopyOptions& o) {
  // The source is migrated like by any writing verb (a version-1 campaign gets relative paths).
  db::Database src = queue::open_campaign(o.src, queue::OpenMode::write, o.src_files);
  const queue::CampaignPaths src_paths(o.src, o.src_files);
  db::Database dst = queue::open_campaign(o.dst, queue::OpenMode::create, o.dst_files);
  const queue::CampaignPaths dst_paths(o.dst, o.dst_files);
  const auto rep = queue::copy_campaign(src, src_paths, dst, dst_paths);
  // The copy is the same campaign: its identity, and its files root's marker.
  queue::set_campaign_id(dst, queue::campaign_id(src));
  queue::bind_files_root(dst, dst_paths);
  fmt::print(
      "copied {} -> {}: {} jobs, {} attempts, {} results rows ({} parameter and metric columns); {} files "
      "copied to {}\n",
      o.src, o.dst, rep.jobs, rep.attempts, rep.results, rep.result_columns, rep.files, dst_paths.root.string());
}

}  // namespace

void setup_campaign(CLI::App& app) {
  auto* campaign = app.add_subcommand("campaign", "Whole-campaign operations (copy between backends)");
  campaign->require_subcommand(1);
  auto o = std::make_shared<CopyOptions>();
  auto* copy = campaign->add_subcommand(
      "copy",
      "Copy a campaign to a new database, of either backend: every job with its state, attempts,\n"
      "dependencies, sweeps and results (with their columns), in one transaction on the\n"
      "destination; the files (beds/, traces/, noop/) are copied too when the two files roots\n"
      "differ. Stop the source's workers first (a running job is refused). A campaign started on a\n"
      "laptop continues on a cluster, and back.\n\n"
      "Examples:\n"
      "  gravsweep campaign copy campaign.db postgresql://me@dbhost:5432/sweep --files /shared/sweep\n"
      "  gravsweep campaign copy postgresql://me@dbhost:5432/sweep back.db --from-files /shared/sweep");
  copy->add_option("SRC", o->src, "source campaign: an SQLite file or postgresql://user@host:port/dbname")->required();
  copy->add_option("DST", o->dst, "destination (new): an SQLite file or postgresql://user@host:port/dbname")
      ->required();
  copy->add_option("--from-files", o->src_files, "the source's files root (required for a PostgreSQL source)");
  copy->add_option("--files", o->dst_files, "the destination's files root (required for a PostgreSQL destination)");
  copy->callback([o]() { run_copy(*o); });
}

}  // namespace gravsweep::cli
