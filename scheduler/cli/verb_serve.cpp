// `gravsweep serve`: a read-only web page of a live campaign and its JSON API (scheduler/serve/).
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <string>

#include "scheduler/cli/campaign_options.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/serve/server.h"

namespace gravsweep::cli {

namespace {

void run_serve(const serve::ServeOptions& o) {
  if (o.port < 0 || o.port > 65535) throw UsageError(fmt::format("--port {}: expected 0 to 65535", o.port));
  serve::serve(o, [&o](const std::string& url) {
    fmt::print("serving campaign {} at {}\n", o.db, url);
    if (serve::is_loopback(o.bind))
      fmt::print("loopback only: reachable from this machine alone (--bind 0.0.0.0 to serve others)\n");
    else
      fmt::print("bound to {}: reachable from other machines; the page and API are read-only, without login\n", o.bind);
    fmt::print("read-only: nothing here changes the campaign; Ctrl-C stops\n");
    std::fflush(stdout);
  });
  fmt::print("stopped\n");
}

}  // namespace

void setup_serve(CLI::App& app) {
  auto opt = std::make_shared<serve::ServeOptions>();
  opt->db = "campaign.db";
  auto* sub = app.add_subcommand(
      "serve",
      "Serve a read-only web page of a campaign while it runs: job counts per sweep and state with\n"
      "the ETA, and per sweep and gravity level with the throughput and an ETA at that rate;\n"
      "workers and their heartbeats, running jobs with their progress, failed and dead jobs with the\n"
      "reason, the results table (the --where grammar of `results`, sorting, pages, a CSV download),\n"
      "a figure of a metric against impact speed per gravity level, the Froude collapse (zstop/D,\n"
      "tstop sqrt(g/D), apeak/g against Fr = vc/sqrt(g D), one colour per level), a drop's trace\n"
      "(acceleration and depth against time) on a click, and the verdict of `model rank` on the\n"
      "finished drops, computed again in the background when drops finish (at least 6 are needed).\n"
      "The page polls the JSON API under /api/ (docs/serve.md): /api/status, /api/levels,\n"
      "/api/results, /api/collapse, /api/failed, /api/drop/ID, /api/rank. Nothing served\n"
      "changes the campaign (GET only; any other method is refused with 405). It binds to the\n"
      "loopback address unless --bind says otherwise, and says so. Stop it with Ctrl-C.\n\n"
      "Examples:\n"
      "  gravsweep serve --db campaign.db                     # http://127.0.0.1:8080/\n"
      "  gravsweep serve --db campaign.db --port 0            # any free port, printed\n"
      "  gravsweep serve --db postgresql://me@db:5432/c --files /shared/c.files\n"
      "  ssh -L 8080:127.0.0.1:8080 cluster                   # watch a remote campaign from here");
  add_campaign_options(sub, opt->db, &opt->files);
  sub->add_option("--port", opt->port, "TCP port (0: any free port, printed)")->capture_default_str();
  sub->add_option("--bind", opt->bind, "address to listen on (0.0.0.0: every interface)")->capture_default_str();
  sub->add_option("--threads", opt->threads, "requests served at once")->capture_default_str();
  sub->callback([opt]() { run_serve(*opt); });
}

}  // namespace gravsweep::cli
