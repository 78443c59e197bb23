#include "scheduler/pipeline/drop_checkpoint.h"

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

DropCheckpointer::DropCheckpointer(DropCheckpointing cfg, json identity, const std::atomic<bool>* stop)
    : cfg_(std::move(cfg)), identity_(std::move(identity)), stop_(stop) {
  started_ = last_write_ = std::chrono::steady_clock::now();
  if (cfg_.path.empty()) return;
  remove_stale_temporaries();
  load();
}

void DropCheckpointer::remove_stale_temporaries() const {
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

double DropCheckpointer::resumed_t_s() const {
  if (!resume_) return -1.0;
  return resume_->drop.loop.result.samples.empty() ? 0.0 : resume_->drop.loop.result.samples.back().t_s;
}

void DropCheckpointer::warn(const std::string& message) const {
  if (cfg_.warn)
    cfg_.warn(message);
  else
    std::fprintf(stderr, "warning: %s\n", message.c_str());
}

void DropCheckpointer::load() {
  std::error_code ec;
  if (!fs::exists(cfg_.path, ec)) {
    if (cfg_.attempt > 1)
      warn(
          fmt::format("no checkpoint {} of an earlier attempt (none was due before it ended, or it was removed): "
                      "the drop starts from its release",
                      cfg_.path.string()));
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
    if (c->code_version != build_version())
      why = fmt::format("written by gravsweep {}, this is {}", c->code_version, build_version());
    else if (without_threads(have) != without_threads(identity_))
      why = fmt::format("written for another drop (its identity differs at {})",
                        json::diff(without_threads(have), without_threads(identity_)).at(0).value("path", "/"));
    else
      resume_ = std::move(c);
    if (resume_ && have.value("threads", 0) != identity_.value("threads", 0))
      warn(
          fmt::format("checkpoint {} was written on {} threads, the drop continues on {}: the rest of it is not "
                      "bit-identical to an uninterrupted run",
                      cfg_.path.string(), have.value("threads", 0), identity_.value("threads", 0)));
  } catch (const results::CheckpointError& e) {
    why = e.what();
  }
  if (!why.empty()) discard(why);
}

void DropCheckpointer::discard(const std::string& why) {
  warn(fmt::format("checkpoint {} discarded: {}; the drop starts over from its release", cfg_.path.string(), why));
  resume_.reset();
  std::error_code ec;
  fs::remove(cfg_.path, ec);
}

DropCheckpoints DropCheckpointer::hooks() {
  DropCheckpoints h;
  h.resume = resume();
  if (cfg_.path.empty() || !(cfg_.interval_s > 0)) return h;
  h.due = [this] {
    const std::atomic<bool>* save_on = cfg_.save_on_stop != nullptr ? cfg_.save_on_stop : stop_;
    if (save_on != nullptr && save_on->load(std::memory_order_relaxed)) return true;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - last_write_).count() >= cfg_.interval_s;
  };
  h.save = [this](const System& sys, const DropLoopState& loop) { save(sys, loop); };
  return h;
}

void DropCheckpointer::save(const System& sys, const DropLoopState& loop) {
  results::CheckpointData c;
  c.drop.system = sys.save_state();
  c.drop.loop = loop;
  c.identity_json = identity_.dump();
  c.code_version = build_version();
  c.wall_time_s =
      prior_wall_time_s() + std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  c.resumes = resume_ ? resume_->resumes + 1 : 0;
  const double t_s = loop.result.samples.empty() ? 0.0 : loop.result.samples.back().t_s;
  try {
    fs::create_directories(cfg_.path.parent_path());
    results::write_checkpoint(cfg_.path, c);
    ++written_;
    last_t_s_ = t_s;
    if (cfg_.progress_saved != nullptr && t_s > resumed_t_s()) cfg_.progress_saved->store(true);
    last_clock_ = utc_time_of_day();
  } catch (const std::exception& e) {  // a full disk ends no drop: the next checkpoint may succeed
    warn(fmt::format("checkpoint {} not written (the drop goes on): {}", cfg_.path.string(), e.what()));
  }
  last_write_ = std::chrono::steady_clock::now();
  if ((stop_ != nullptr && stop_->load()) || (cfg_.save_on_stop != nullptr && cfg_.save_on_stop->load()))
    throw Interrupted(fmt::format("drop interrupted at t = {:.4f} s; {}", t_s,
                                  last_t_s_ == t_s ? "checkpoint " + cfg_.path.string() : "no checkpoint written"));
}

void DropCheckpointer::finished() {
  if (cfg_.path.empty()) return;
  std::error_code ec;
  fs::remove(cfg_.path, ec);
  remove_stale_temporaries();
}

std::string DropCheckpointer::detail(const std::string& drop_detail) const {
  if (last_t_s_ >= 0) return fmt::format("{} ckpt t={:.4f}s at {}", drop_detail, last_t_s_, last_clock_);
  if (resume_ && !resume_->drop.loop.result.samples.empty())
    return fmt::format("{} resumed from t={:.4f}s", drop_detail, resume_->drop.loop.result.samples.back().t_s);
  return drop_detail;
}

double DropCheckpointer::prior_wall_time_s() const { return resume_ ? resume_->wall_time_s : 0.0; }

void DropCheckpointer::add_metrics(json& m) const {
  m["checkpoint_resumes"] = resume_ ? resume_->resumes + 1 : 0;
  m["resumed_at_s"] = resume_ && !resume_->drop.loop.result.samples.empty()
                          ? json(resume_->drop.loop.result.samples.back().t_s)
                          : json(nullptr);
  m["checkpoints_written"] = written_;
}

}  // namespace gravsweep::pipeline
