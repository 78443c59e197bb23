// A campaign's files root: `resume` and `work` touch nothing outside the campaign.
// - `resume` removes only what it quarantined itself (its `<ms>-<pid>/` batches), never through a
//   symbolic link: a `quarantine` that is a link is refused, a user's file under it stays;
// - a files root proves it belongs to the campaign by its marker (written at submit): a wrong
//   `--files` is refused (exit 2, naming both) before anything in it is moved or deleted.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

/// A no-op sweep of `n` jobs (gravity 0.01, 0.02, ...), named `name`.
std::string noop_sweep(int n, const std::string& name = "files") {
  json doc = {{"sweep", name},
              {"job", "noop"},
              {"base", {{"g", 1.0}, {"sleep_s", 0.0}}},
              {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", json::array()}}}}};
  for (int i = 1; i <= n; ++i) doc["axes"][0]["values"].push_back(i * 0.01);
  return doc.dump();
}

/// A finished no-op campaign of `n` jobs in dir/<stem>.db.
void finished_campaign(const fs::path& dir, int n, const std::string& stem = "c") {
  write_text(dir / (stem + ".json"), noop_sweep(n, stem));
  auto r = run_cli({"submit", stem + ".json", "--db", stem + ".db"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli({"work", "--db", stem + ".db", "--quiet"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
}

/// A user's folder holding `keep.txt` and `sub/deep.txt`.
void user_folder(const fs::path& dir) {
  fs::create_directories(dir / "sub");
  write_text(dir / "keep.txt", "a");
  write_text(dir / "sub" / "deep.txt", "b");
}

std::size_t count_regular(const fs::path& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) ++n;
  return n;
}

void expect_user_folder(const fs::path& dir) {
  EXPECT_TRUE(fs::exists(dir / "keep.txt")) << dir;
  EXPECT_TRUE(fs::exists(dir / "sub" / "deep.txt")) << dir;
}

}  // namespace

TEST(FilesRoot, ResumeRefusesAQuarantineThatIsASymlinkAndLeavesItsTargetAlone) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 2));
  user_folder(d.path / "victim");
  fs::create_directory_symlink(d.path / "victim", d.path / "c.files" / "quarantine");
  const auto r = run_cli({"resume", "--db", "c.db"}, d.path);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("symbolic link"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("quarantine"), std::string::npos) << r.err;
  expect_user_folder(d.path / "victim");
}

TEST(FilesRoot, ResumeRemovesOnlyItsOwnQuarantineBatchesNeverThroughALink) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 2));
  const fs::path q = d.path / "c.files" / "quarantine";
  // gravsweep's own batch of an earlier resume: removed.
  const fs::path own = q / "1700000000000-4242" / "noop" / "deadbeef.a1.json";
  fs::create_directories(own.parent_path());
  write_text(own, "orphan");
  // A user's file and folder under quarantine/, and a folder shaped like a batch but not named like one.
  write_text(q / "notes.txt", "mine");
  user_folder(q / "mine" / "traces");
  // A batch that is a link to a user's folder, and a link inside a real batch: links go, targets stay.
  user_folder(d.path / "victim2" / "traces");
  fs::create_directory_symlink(d.path / "victim2", q / "1700000000001-4243");
  user_folder(d.path / "victim3");
  fs::create_directory_symlink(d.path / "victim3", q / "1700000000000-4242" / "traces");
  const auto r = run_cli({"resume", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("quarantined files removed: 1"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(own));
  EXPECT_TRUE(fs::exists(q / "notes.txt"));
  expect_user_folder(q / "mine" / "traces");
  expect_user_folder(d.path / "victim2" / "traces");
  expect_user_folder(d.path / "victim3");
}

namespace {

/// Sets every file under `dir` a minute back: older than resume's 5 s margin for orphans.
void age_files(const fs::path& dir) {
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) fs::last_write_time(e.path(), fs::file_time_type::clock::now() - std::chrono::minutes(1));
}

std::string marker_id(const fs::path& root) {
  std::ifstream in(root / "gravsweep-campaign.json");
  return json::parse(in).at("campaign_id").get<std::string>();
}

}  // namespace

TEST(FilesRoot, SubmitWritesTheMarkerNamingTheCampaign) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 2));
  db::Database db((d.path / "c.db").string());
  const std::string id = sql_text(db, "SELECT value FROM queue_meta WHERE key='campaign_id'");
  EXPECT_EQ(id.size(), 32u);
  EXPECT_EQ(marker_id(d.path / "c.files"), id);
}

// A database reached through a symbolic link keeps its own files root: resume through the link
// made a <link>.files/ holding a marker with the real campaign's id, which a later work would
// have taken as the campaign's own.
TEST(FilesRoot, AVerbGivenASymlinkToTheDatabaseUsesTheDatabasesOwnFolder) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 2));
  std::filesystem::create_symlink("c.db", d.path / "link.db");
  const auto r = run_cli({"resume", "--db", "link.db"}, d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.path / "link.files")) << "a second files root was made for the link";
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(marker_id(d.path / "c.files"), sql_text(db, "SELECT value FROM queue_meta WHERE key='campaign_id'"));
}

TEST(FilesRoot, AnotherCampaignsFolderIsRefusedBeforeAnythingMoves) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 3, "other"));
  age_files(d.path / "other.files");
  const std::size_t before = count_regular(d.path / "other.files");
  // A fresh campaign (no done jobs: the "most outputs missing" check cannot tell) given the wrong folder.
  write_text(d.path / "c.json", noop_sweep(2, "c"));
  ASSERT_EQ(run_cli({"submit", "c.json", "--db", "c.db"}, d.path).code, 0);
  for (const std::vector<std::string>& verb : {std::vector<std::string>{"resume"},
                                               {"resume", "--dry-run"},
                                               {"resume", "--keep-orphans"},
                                               {"work", "--quiet"}}) {
    std::vector<std::string> args = verb;
    args.insert(args.end(), {"--db", "c.db", "--files", (d.path / "other.files").string()});
    const auto r = run_cli(args, d.path);
    EXPECT_EQ(r.code, 2) << verb[0] << ": " << r.out << r.err;
    EXPECT_NE(r.err.find("other.files"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("other.db"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("c.db"), std::string::npos) << r.err;
  }
  EXPECT_EQ(count_regular(d.path / "other.files"), before);
  EXPECT_FALSE(fs::exists(d.path / "other.files" / "quarantine"));
}

TEST(FilesRoot, AnUnmarkedFolderWithForeignFilesIsRefusedAndKept) {
  TempDir d;
  write_text(d.path / "c.json", noop_sweep(2, "c"));
  ASSERT_EQ(run_cli({"submit", "c.json", "--db", "c.db"}, d.path).code, 0);
  // A user's folder that happens to hold tmp/ and beds/ (e.g. --files $HOME).
  const fs::path fake = d.path / "fakeroot";
  fs::create_directories(fake / "tmp");
  fs::create_directories(fake / "beds");
  write_text(fake / "tmp" / "draft.txt", "mine");
  write_text(fake / "beds" / "sand.h5", "mine too");
  age_files(fake);
  for (const std::string verb : {"resume", "work"}) {
    const auto r = run_cli({verb, "--db", "c.db", "--files", fake.string()}, d.path);
    EXPECT_EQ(r.code, 2) << verb << ": " << r.out << r.err;
    EXPECT_NE(r.err.find("fakeroot"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("c.db"), std::string::npos) << r.err;
  }
  EXPECT_TRUE(fs::exists(fake / "tmp" / "draft.txt"));
  EXPECT_TRUE(fs::exists(fake / "beds" / "sand.h5"));
  EXPECT_FALSE(fs::exists(fake / "gravsweep-campaign.json"));
}

TEST(FilesRoot, AnEarlierCampaignWithoutAMarkerGetsOneWhereItIsSafe) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 2));
  // As an earlier gravsweep left it: no marker, no campaign id.
  fs::remove(d.path / "c.files" / "gravsweep-campaign.json");
  {
    db::Database db((d.path / "c.db").string());
    db::Statement st(db, "DELETE FROM queue_meta WHERE key='campaign_id'");
    st.run();
  }
  auto r = run_cli({"resume", "--db", "c.db", "--dry-run"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(d.path / "c.files" / "gravsweep-campaign.json")) << "a dry run writes nothing";
  r = run_cli({"resume", "--db", "c.db"}, d.path);  // the default folder beside the database
  ASSERT_EQ(r.code, 0) << r.err;
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(marker_id(d.path / "c.files"), sql_text(db, "SELECT value FROM queue_meta WHERE key='campaign_id'"));
  // A given folder holding only what the campaign wrote is adopted too; an empty one as well.
  fs::rename(d.path / "c.files", d.path / "moved");
  fs::remove(d.path / "moved" / "gravsweep-campaign.json");
  r = run_cli({"resume", "--db", "c.db", "--files", (d.path / "moved").string()}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(d.path / "moved" / "gravsweep-campaign.json"));
  r = run_cli({"resume", "--db", "c.db", "--files", (d.path / "empty").string(), "--keep-orphans"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(d.path / "empty" / "gravsweep-campaign.json"));
}
