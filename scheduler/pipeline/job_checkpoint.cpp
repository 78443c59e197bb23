#include "scheduler/pipeline/job_checkpoint.h"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <cstdio>
#include <ctime>

#include "scheduler/pipeline/build_version.h"
#include "scheduler/pipeline/impact_job.h"
#include "scheduler/queue/canonical.h"

namespace gravsweep::pipeline {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// The identity without the thread count: a drop continued on other threads is the same drop
/// (not bit-identical to an uninterrupted run, but as valid).
json without_threads(json identity) {
  if (identity.is_object()) identity.erase("threads");
  return identity;
}

std::string utc_time_of_day() { return fmt::format("{:%H:%M:%S}Z", fmt::gmtime(std::time(nullptr))); }

}  // namespace

json drop_identity(const json& validated_scenario, const fs::path& bed, int threads) {
  return json{{"scenario", validated_scenario}, {"bed_sha256", queue::sha256_file(bed)}, {"threads", threads}};
}

json bed_identity(const json& bed_key, int threads) { return json{{"bed_key", bed_key}, {"threads", threads}}; }

JobCheckpointer::JobCheckpointer(Checkpointing cfg, std::string kind, json identity, const std::atomic<bool>* stop)
    : cfg_(std::move(cfg)), kind_(std::move(kind)), identity_(std::move(identity)), stop_(stop) {
  started_ = last_write_ = std::chrono::steady_clock::now();
  if (cfg_.path.empty()) return;
  remove_stale_temporaries();
  load();
}

void JobCheckpointer::remove_stale_temporaries() const {
  // The job's lease is held by this attempt alone: a temporary of its checkpoint is a write that
  // an earlier, killed worker never finished (h5::write_atomically names it <file>.tmp<pid>).
  std::error_code ec;
  const std::string prefix = cfg_.path.filename().string() + ".tmp";
  for (fs::directory_iterator it(cfg_.path.parent_path(), ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::error_code rm;
    if (name.rfind(prefix, 0) == 0 && fs::remove(it->path(), rm))
      warn(fmt::format("removed {}: a checkpoint write an earlier worker never finished", it->path().string()));
  }
}

double JobCheckpointer::resumed_t_s() const { return resume_ ? resume_->position_s : -1.0; }

void JobCheckpointer::warn(const std::string& message) const {
  if (cfg_.warn)
    cfg_.warn(message);
  else
    std::fprintf(stderr, "warning: %s\n", message.c_str());
}

void JobCheckpointer::load() {
  std::error_code ec;
  if (!fs::exists(cfg_.path, ec)) {
    if (cfg_.attempt > 1)
      warn(
          fmt::format("no checkpoint {} of an earlier attempt (none was due before it ended, or it was removed): "
                      "the {} starts from {}",
                      cfg_.path.string(), kind_, start()));
    return;
  }
  std::string why;
  try {
    auto c = std::make_unique<results::CheckpointData>(results::read_checkpoint(cfg_.path));
    json have;
    try {
      have = json::parse(c->identity_json);
    } catch (const json::exception&) {
      have = json();
    }
    if (c->kind() != kind_)
      why = fmt::format("a {} checkpoint, this job is a {}", c->kind(), kind_);
    else if (c->code_version != build_version())
      why = fmt::format("written by gravsweep {}, this is {}", c->code_version, build_version());
    else if (without_threads(have) != without_threads(identity_))
      why = fmt::format("written for another {} (its identity differs at {})", kind_,
                        json::diff(without_threads(have), without_threads(identity_)).at(0).value("path", "/"));
    else
      resume_ = std::move(c);
    if (resume_ && have.value("threads", 0) != identity_.value("threads", 0))
      warn(
          fmt::format("checkpoint {} was written on {} threads, the {} continues on {}: the rest of it is not "
                      "bit-identical to an uninterrupted run",
                      cfg_.path.string(), have.value("threads", 0), kind_, identity_.value("threads", 0)));
  } catch (const results::CheckpointError& e) {
    why = e.what();
  }
  if (!why.empty()) discard(why);
}

void JobCheckpointer::discard(const std::string& why) {
  warn(fmt::format("checkpoint {} discarded: {}; the {} starts over from {}", cfg_.path.string(), why, kind_, start()));
  resume_.reset();
  std::error_code ec;
  fs::remove(cfg_.path, ec);
}

bool JobCheckpointer::due() const {
  const std::atomic<bool>* save_on = cfg_.save_on_stop != nullptr ? cfg_.save_on_stop : stop_;
  if (save_on != nullptr && save_on->load(std::memory_order_relaxed)) return true;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - last_write_).count() >= cfg_.interval_s;
}

template <class Hooks, class State, class PositionOf>
Hooks JobCheckpointer::hooks(const State* resume, PositionOf position_s) {
  Hooks h;
  h.resume = resume;
  if (cfg_.path.empty() || !(cfg_.interval_s > 0)) return h;
  h.due = [this] { return due(); };
  h.save = [this, position_s](const System& sys, const decltype(State::loop)& loop) {
    results::CheckpointData c;
    c.state = State{sys.save_state(), loop};
    c.position_s = position_s(sys, loop);
    save(std::move(c));
  };
  return h;
}

DropCheckpoints JobCheckpointer::drop_hooks() {
  // A drop's checkpoint is at its last sample (0 before the first).
  return hooks<DropCheckpoints>(resume_drop(), [](const System&, const DropLoopState& loop) {
    return loop.result.samples.empty() ? 0.0 : loop.result.samples.t_s.back();
  });
}

BedCheckpoints JobCheckpointer::bed_hooks() {
  return hooks<BedCheckpoints>(resume_bed(), [](const System& sys, const BedLoopState&) { return sys.time_s(); });
}

void JobCheckpointer::save(results::CheckpointData c) {
  c.identity_json = identity_.dump();
  c.code_version = build_version();
  c.wall_time_s =
      prior_wall_time_s() + std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  c.resumes = resume_ ? resume_->resumes + 1 : 0;
  const double t_s = c.position_s;
  try {
    fs::create_directories(cfg_.path.parent_path());
    results::write_checkpoint(cfg_.path, c);
    ++written_;
    last_t_s_ = t_s;
    if (cfg_.progress_saved != nullptr && t_s > resumed_t_s()) cfg_.progress_saved->store(true);
    last_clock_ = utc_time_of_day();
  } catch (const std::exception& e) {  // a full disk ends no run: the next checkpoint may succeed
    warn(fmt::format("checkpoint {} not written (the {} goes on): {}", cfg_.path.string(), kind_, e.what()));
  }
  last_write_ = std::chrono::steady_clock::now();
  if ((stop_ != nullptr && stop_->load()) || (cfg_.save_on_stop != nullptr && cfg_.save_on_stop->load()))
    throw Interrupted(fmt::format("{} interrupted at t = {:.4f} s; {}", kind_, t_s,
                                  last_t_s_ == t_s ? "checkpoint " + cfg_.path.string() : "no checkpoint written"));
}

void JobCheckpointer::finished() {
  if (cfg_.path.empty()) return;
  std::error_code ec;
  fs::remove(cfg_.path, ec);
  remove_stale_temporaries();
}

std::string JobCheckpointer::detail(const std::string& run_detail) const {
  if (last_t_s_ >= 0) return fmt::format("{} ckpt t={:.4f}s at {}", run_detail, last_t_s_, last_clock_);
  if (resume_ && resume_->position_s > 0)
    return fmt::format("{} resumed from t={:.4f}s", run_detail, resume_->position_s);
  return run_detail;
}

double JobCheckpointer::prior_wall_time_s() const { return resume_ ? resume_->wall_time_s : 0.0; }

results::CheckpointCounts JobCheckpointer::counts() const {
  results::CheckpointCounts c;
  c.resumes = resume_ ? resume_->resumes + 1 : 0;
  if (resume_ && resume_->position_s > 0) c.resumed_at_s = resume_->position_s;
  c.written = written_;
  return c;
}

}  // namespace gravsweep::pipeline
