// A drop's Fig. 1 and Fig. 2 as PNG replies (see figures.h).
#include "scheduler/serve/figures.h"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "results/report/figures.h"
#include "results/report/report.h"
#include "scheduler/queue/filter.h"

namespace gravsweep::serve {

namespace fs = std::filesystem;

namespace {

/// The drop's trace and bed files (absolute), or the reason there are none.
struct DropFiles {
  fs::path trace, bed;
  std::string why_not;
};

DropFiles drop_files(db::Database& db, const queue::CampaignPaths& paths, const std::string& job_id) {
  queue::ResultsQuery q;
  q.where = {"job_id='" + job_id + "'"};  // quoted: an id of digits alone is still text
  q.columns = {"kind", "trace_path", "bed_job_id"};
  q.limit = 1;
  const queue::ResultsTable t = queue::query_results(db, q);
  if (t.rows.empty()) return {{}, {}, fmt::format("job {} has no results row (unknown, or not finished)", job_id)};
  const auto& row = t.rows[0];
  if (row[0] != "drop" || !row[1].is_string()) return {{}, {}, fmt::format("job {} is not a drop: no figure", job_id)};
  DropFiles f{paths.abs(row[1].get<std::string>()), {}, ""};
  if (row[2].is_string())
    if (const std::string bed = queue::done_output_path(db, row[2].get<std::string>()); !bed.empty())
      f.bed = paths.abs(bed);
  return f;
}

Reply png_reply(const fs::path& png) {
  std::ifstream in(png, std::ios::binary);
  Reply r;
  r.content_type = "image/png";
  r.body.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) return error_reply(500, fmt::format("cannot read the drawn figure {}", png.string()));
  return r;
}

}  // namespace

DropFigures::DropFigures() : cache_(std::make_unique<results::ScratchDir>("serve-figures")) {}
DropFigures::~DropFigures() = default;

Reply DropFigures::reply(db::Database& db, const queue::CampaignPaths* paths, const std::string& job_id,
                         const std::string& which) {
  if (!is_job_id(job_id)) return error_reply(404, fmt::format("'{}' is not a job id (hexadecimal digits)", job_id));
  if (which != "fig1" && which != "fig2")
    return error_reply(404, fmt::format("{}.png: the figures of a drop are fig1.png and fig2.png", which));
  if (!paths) return error_reply(404, "the campaign's files root is unknown: serve it with --files");
  DropFiles files;
  try {
    files = drop_files(db, *paths, job_id);
  } catch (const std::invalid_argument& e) {  // the where grammar refused the id: no such job
    return error_reply(404, fmt::format("job {}: {}", job_id, e.what()));
  }
  if (!files.why_not.empty()) return error_reply(404, files.why_not);
  const fs::path png = cache_->path / fmt::format("{}_{}.png", job_id, which);
  std::error_code ec;
  if (fs::exists(png, ec)) return png_reply(png);  // drawn before: no lock needed to read it
  if (which == "fig1" && files.bed.empty())
    return error_reply(404, fmt::format("the bed of drop {} is not in the campaign", job_id));
  const std::lock_guard<std::mutex> one_at_a_time(drawing_);
  if (fs::exists(png, ec)) return png_reply(png);  // drawn while this request waited
  // Drawn under another name and renamed: a request never reads half a PNG.
  const fs::path tmp = cache_->path / fmt::format("{}_{}.tmp.png", job_id, which);
  try {
    // results/report reads the trace and the bed with HDF5 (not thread-safe in Debian's build), then
    // runs plots.py: the lock is held for both, a drop's figure at a time.
    const std::lock_guard<std::mutex> hdf5(hdf5_mutex());
    if (which == "fig2")
      results::draw_fig2({files.trace.string(), "", tmp.string()});
    else
      results::draw_fig1({files.bed.string(), files.trace.string(), "", "", tmp.string()});
    fs::rename(tmp, png);
  } catch (const std::exception& e) {  // a trace moved or unreadable, plots.py failing: the page says why
    fs::remove(tmp, ec);
    return error_reply(500, fmt::format("drop {}: {} could not be drawn: {}", job_id, which, e.what()));
  }
  return png_reply(png);
}

}  // namespace gravsweep::serve
