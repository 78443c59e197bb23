// The files root's marker: which campaign a files root belongs to (written at submit, checked by
// every verb that moves or deletes files in it).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>

#include "engine/core/error.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

namespace {

/// Folders gravsweep makes in a files root: the output folders (job_types.h), quarantine/ and
/// snapshots/; anything else at its top is foreign content.
/// quarantine/ and snapshots/: folders no job refers to (any file in them is foreign content).
bool unreferenced_folder(const std::string& name) { return name == "quarantine" || name == "snapshots"; }

bool root_folder(const std::string& name) {
  const auto& out = output_folders();
  return std::find(out.begin(), out.end(), name) != out.end() || unreferenced_folder(name);
}

/// `postgresql://user:secret@host/db` without its password (the marker and messages name it).
std::string without_password(const std::string& location) {
  const auto scheme = location.find("://");
  const auto at = location.find('@');
  if (scheme == std::string::npos || at == std::string::npos || at < scheme) return location;
  const auto colon = location.find(':', scheme + 3);
  if (colon == std::string::npos || colon > at) return location;
  return location.substr(0, colon) + location.substr(at);
}

std::string random_id() {
  std::random_device rd;
  std::string id;
  for (int i = 0; i < 4; ++i) id += fmt::format("{:08x}", rd());
  return id;
}

struct Marker {
  std::string campaign_id, database;
};

/// The marker of `root`, or nullopt when there is none; ConfigError when it is unreadable.
std::optional<Marker> read_marker(const fs::path& root) {
  const fs::path p = root / kFilesMarker;
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(p, ec))) return std::nullopt;
  std::ifstream in(p);
  std::stringstream text;
  text << in.rdbuf();
  try {
    const json doc = json::parse(text.str());
    return Marker{doc.at("campaign_id").get<std::string>(), doc.value("database", std::string("?"))};
  } catch (const json::exception& e) {
    throw ConfigError(
        fmt::format("'{}': not a gravsweep files-root marker ({}); expected a JSON object with "
                    "\"campaign_id\"; nothing was moved or removed",
                    p.string(), e.what()));
  }
}

void write_marker(const fs::path& root, const Marker& m) {
  fs::create_directories(root);
  const fs::path tmp = root / fmt::format(".{}.{}", kFilesMarker, ::getpid());
  {
    std::ofstream out(tmp);
    out << json{{"campaign_id", m.campaign_id}, {"database", m.database}}.dump(2) << "\n";
    if (!out.flush()) throw ConfigError(fmt::format("'{}': cannot write the files-root marker", tmp.string()));
  }
  fs::rename(tmp, root / kFilesMarker);  // atomic: concurrent workers write the same content
}

/// The first foreign thing in `root` (empty when none): a top-level entry gravsweep does not make,
/// an entry of an output folder that no done job or running attempt refers to, or any file in
/// `quarantine/` or `snapshots/` (no job refers to those).
std::string first_foreign(Database& db, const fs::path& root) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return {};
  const Referenced ref = referenced_files(db);
  for (const auto& e : fs::directory_iterator(root, ec)) {
    const std::string name = e.path().filename().string();
    if (name == kFilesMarker) continue;
    const bool ours = root_folder(name);
    if (!ours || fs::symlink_status(e.path(), ec).type() != fs::file_type::directory) return e.path().string();
    if (unreferenced_folder(name)) {
      if (count_files(e.path()) > 0) return e.path().string();
      continue;
    }
    for (const auto& f : fs::directory_iterator(e.path(), ec))
      if (!ref.refers_to((fs::path(name) / f.path().filename()).string())) return f.path().string();
  }
  return {};
}

/// True when `paths` is the default root beside an SQLite database: `<stem>.files/` of `db`.
bool default_root(Database& db, const CampaignPaths& paths) {
  if (db::is_postgres_url(db.path())) return false;
  std::error_code ec;
  const CampaignPaths beside(db.path());
  return beside.root == paths.root || fs::equivalent(beside.root, paths.root, ec);
}

/// The campaign's identity as stored ("" when it has none yet: a campaign of an earlier gravsweep).
std::string stored_campaign_id(Database& db) {
  Statement get(db, "SELECT value FROM queue_meta WHERE key='campaign_id'");
  return get.step() ? get.get_text(0) : std::string();
}

}  // namespace

std::string campaign_id(Database& db) {
  if (std::string id = stored_campaign_id(db); !id.empty()) return id;
  Transaction tx(db);
  Statement put(db, "INSERT INTO queue_meta(key, value) VALUES('campaign_id', ?) ON CONFLICT(key) DO NOTHING");
  put.bind(1, random_id());
  put.run();
  Statement get(db, "SELECT value FROM queue_meta WHERE key='campaign_id'");
  get.step();
  std::string id = get.get_text(0);
  tx.commit();
  return id;
}

void set_campaign_id(Database& db, const std::string& id) {
  Statement put(db,
                "INSERT INTO queue_meta(key, value) VALUES('campaign_id', ?) "
                "ON CONFLICT(key) DO UPDATE SET value=excluded.value");
  put.bind(1, id);
  put.run();
}

void bind_files_root(Database& db, const CampaignPaths& paths, bool write) {
  const std::string id = write ? campaign_id(db) : stored_campaign_id(db);  // a dry run writes nothing
  const std::string me =
      db::is_postgres_url(db.path()) ? without_password(db.path()) : fs::absolute(db.path()).string();
  if (const auto m = read_marker(paths.root)) {
    if (m->campaign_id == id) return;
    throw ConfigError(fmt::format(
        "files root '{}' belongs to another campaign: its marker {} names campaign {} (database '{}'), not '{}' "
        "(campaign {}); refusing to move or delete anything in it. Pass this campaign's own --files",
        paths.root.string(), kFilesMarker, m->campaign_id, m->database, me, id));
  }
  // No marker: a campaign of an earlier gravsweep, or a folder that is not a campaign's at all.
  if (!default_root(db, paths)) {
    const std::string foreign = first_foreign(db, paths.root);
    if (!foreign.empty())
      throw ConfigError(fmt::format(
          "files root '{}' has no campaign marker ({}) and holds what campaign '{}' (campaign {}) did not write "
          "(first: {}); refusing to move or delete anything in it. Pass this campaign's own --files; if this "
          "folder is its own, mark it: echo '{{\"campaign_id\": \"{}\"}}' > '{}'",
          paths.root.string(), kFilesMarker, me, id, foreign, id, (paths.root / kFilesMarker).string()));
  }
  if (write) write_marker(paths.root, Marker{id, me});
}

}  // namespace gravsweep::queue
