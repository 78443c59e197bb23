// `gravsweep slurm submit|cancel`: pilot workers as a Slurm job array on a PostgreSQL campaign.
// Each array task runs `gravsweep work` until no job is left; a task killed at its time limit
// loses nothing (its lease expires and another worker takes the job over), and `scancel`'s
// SIGTERM makes a worker give its lease back.
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <set>
#include <string>

#include "scheduler/cli/campaign_options.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/pipeline/job_checkpoint.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/spawn.h"

namespace gravsweep::cli {

namespace {

namespace fs = std::filesystem;

struct SlurmOptions {
  std::string db, files, partition, time_limit, account;
  int workers = 1, threads = 1;
  double lease_s = 60;
  double checkpoint_interval_s = pipeline::kDefaultCheckpointInterval_s;
  bool dry_run = false;
};

/// Single-quoted for sh.
std::string sh_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// Double-quoted for an `#SBATCH` line (sbatch reads `"` as grouping and `\` as escape there); a
/// line break cannot be written in one, so it is refused.
std::string sbatch_quote(const std::string& what, const std::string& s) {
  if (s.find_first_of("\n\r") != std::string::npos)
    throw UsageError(fmt::format("{} '{}': holds a line break, which an #SBATCH line cannot carry", what, s));
  std::string out = "\"";
  for (char c : s) out += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

/// Refuses --time, --partition and --account that are not in Slurm's syntax (sbatch(1)): each is
/// written into an `#SBATCH` line, where a line break or a space would inject or cut an option.
void check_slurm_syntax(const SlurmOptions& o) {
  static const std::regex time_re(
      R"(^(\d+|\d+:\d+|\d+:\d+:\d+|\d+-\d+|\d+-\d+:\d+|\d+-\d+:\d+:\d+|UNLIMITED|INFINITE)$)", std::regex::icase);
  static const std::regex name_re(R"(^[A-Za-z0-9_.-]+$)");
  static const std::regex names_re(R"(^[A-Za-z0-9_.-]+(,[A-Za-z0-9_.-]+)*$)");
  if (!o.time_limit.empty() && !std::regex_match(o.time_limit, time_re))
    throw UsageError(fmt::format(
        "--time '{}': expected a Slurm time limit: minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS or UNLIMITED",
        o.time_limit));
  if (!o.partition.empty() && !std::regex_match(o.partition, names_re))
    throw UsageError(fmt::format(
        "--partition '{}': expected a Slurm partition name or a comma-separated list of them (letters, digits, "
        "'_', '-', '.')",
        o.partition));
  if (!o.account.empty() && !std::regex_match(o.account, name_re))
    throw UsageError(
        fmt::format("--account '{}': expected a Slurm account name (letters, digits, '_', '-', '.')", o.account));
}

std::string sbatch_script(const SlurmOptions& o, const std::string& exe, const fs::path& logs) {
  std::string s = "#!/bin/sh\n";
  s += "#SBATCH --job-name=gravsweep-work\n";
  s += fmt::format("#SBATCH --array=1-{}\n", o.workers);
  s += fmt::format("#SBATCH --cpus-per-task={}\n", o.threads);
  s += "#SBATCH --ntasks=1\n";
  s += fmt::format("#SBATCH --output={}\n", sbatch_quote("--files", (logs / "%A_%a.log").string()));
  if (!o.partition.empty()) s += fmt::format("#SBATCH --partition={}\n", o.partition);
  if (!o.time_limit.empty()) s += fmt::format("#SBATCH --time={}\n", o.time_limit);
  if (!o.account.empty()) s += fmt::format("#SBATCH --account={}\n", o.account);
  s += "# One pilot worker per array task: it claims jobs until none is left. SIGTERM (scancel, or the\n"
       "# time limit) makes it give its lease back; SIGKILL loses only the current attempt.\n";
  s += fmt::format("exec {} work --db {} --files {} --threads {} --lease {} --checkpoint-interval {}\n", sh_quote(exe),
                   sh_quote(o.db), sh_quote(fs::absolute(o.files).string()), o.threads, o.lease_s,
                   o.checkpoint_interval_s);
  return s;
}

/// Runs `cmd` and returns its stdout (throws with its exit status on failure).
std::string run_capture(const std::string& cmd) {
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("cannot run: " + cmd);
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int rc = ::pclose(p);
  if (rc != 0) throw std::runtime_error(fmt::format("'{}' failed (status {}): {}", cmd, rc, out));
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

void run_submit(const SlurmOptions& o) {
  check_slurm_syntax(o);
  if (!db::is_postgres_url(o.db))
    throw UsageError(
        fmt::format("--db '{}': Slurm workers on a cluster need a PostgreSQL campaign "
                    "(postgresql://user@host:port/dbname); an SQLite file must not be shared between "
                    "nodes (WAL needs one host). Copy it: gravsweep campaign copy {} postgresql://...",
                    o.db, o.db));
  { db::Database db = queue::open_campaign(o.db, queue::OpenMode::write, o.files); }  // refuses a non-campaign
  const queue::CampaignPaths paths(o.db, o.files);
  const fs::path logs = paths.root / "slurm";
  const std::string script = sbatch_script(o, queue::self_exe(), logs);
  if (o.dry_run) {
    fmt::print("{}", script);
    return;
  }
  fs::create_directories(logs);
  const auto stamp =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count();
  const fs::path file = logs / fmt::format("submit-{}.sh", stamp);
  std::ofstream(file) << script;
  const std::string id = run_capture("sbatch --parsable " + sh_quote(file.string()));
  std::ofstream(logs / "jobs.txt", std::ios::app) << id.substr(0, id.find(';')) << "\n";
  fmt::print("submitted Slurm job array {} ({} workers x {} threads); logs in {}/\n", id, o.workers, o.threads,
             logs.string());
}

void run_cancel(const SlurmOptions& o) {
  const queue::CampaignPaths paths(o.db, o.files);
  std::set<std::string> ids;
  std::ifstream in(paths.root / "slurm" / "jobs.txt");
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) ids.insert(line);
  {  // and every Slurm job holding a lease now (a worker records SLURM_JOB_ID in its name)
    db::Database db = queue::open_campaign(o.db, queue::OpenMode::read, o.files);
    for (const auto& r : queue::status(db, 1u << 20).running) {
      const auto at = r.owner.find(":slurm=");
      if (at != std::string::npos) ids.insert(r.owner.substr(at + 7));
    }
  }
  if (ids.empty()) {
    fmt::print("no Slurm job of this campaign to cancel\n");
    return;
  }
  std::string cmd = "scancel";
  for (const auto& id : ids) cmd += " " + sh_quote(id);
  fmt::print("{}\n", cmd);
  if (!o.dry_run) run_capture(cmd);
}

}  // namespace

void setup_slurm(CLI::App& app) {
  auto* slurm = app.add_subcommand("slurm", "Pilot workers on a Slurm cluster (a PostgreSQL campaign)");
  slurm->require_subcommand(1);
  auto o = std::make_shared<SlurmOptions>();
  auto* sub = slurm->add_subcommand(
      "submit",
      "Submit --workers pilot workers as one sbatch job array: each task runs `gravsweep work` with\n"
      "--threads engine threads (cpus-per-task) until no job is left; logs in <files>/slurm/. Needs a\n"
      "PostgreSQL campaign and a files root every node mounts at the same path. --dry-run prints the\n"
      "script. Workers stopped by the time limit or scancel lose nothing: a running drop is\n"
      "checkpointed at the SIGTERM and the next task continues it. --time, --partition and\n"
      "--account are checked against Slurm's syntax (exit 2 otherwise); every path is quoted.\n\n"
      "Example:\n"
      "  gravsweep slurm submit --db postgresql://me@dbhost:5432/sweep --files /shared/sweep \\\n"
      "      --workers 16 --threads 4 --partition small --time 04:00:00");
  add_campaign_options(sub, o->db, &o->files);
  sub->add_option("--workers", o->workers, "array tasks (pilot workers)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub->add_option("--threads", o->threads, "engine threads per worker (= cpus-per-task)")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  sub->add_option("--partition", o->partition, "Slurm partition (or a comma-separated list)");
  sub->add_option("--time", o->time_limit, "time limit per task: minutes, HH:MM:SS or D-HH:MM:SS (Slurm's syntax)");
  sub->add_option("--account", o->account, "Slurm account");
  sub->add_option("--lease", o->lease_s, "lease length, s, passed to the workers")
      ->check(CLI::Range(0.5, 86400.0))
      ->capture_default_str();
  sub->add_option("--checkpoint-interval", o->checkpoint_interval_s,
                  "wall seconds between two checkpoints of a running drop, passed to the workers (0: none)")
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
  sub->add_flag("--dry-run", o->dry_run, "print the sbatch script, submit nothing");
  sub->callback([o]() { run_submit(*o); });
  auto* cancel = slurm->add_subcommand(
      "cancel",
      "scancel the job arrays `slurm submit` started for this campaign and every Slurm job holding a\n"
      "lease; the workers give their leases back on the SIGTERM.\n\n"
      "Example:\n"
      "  gravsweep slurm cancel --db postgresql://me@dbhost:5432/sweep --files /shared/sweep");
  add_campaign_options(cancel, o->db, &o->files);
  cancel->add_flag("--dry-run", o->dry_run, "print the scancel command only");
  cancel->callback([o]() { run_cancel(*o); });
}

}  // namespace gravsweep::cli
