// The bad-input corpus of sweep specs: each case is refused by `gravsweep submit`
// with exit code 2, a message naming the file and the JSON pointer (or line) of the problem, and
// nothing written (no database, no files folder). Plus the cases that must be accepted.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "db/database.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

json noop_doc() {
  return {{"sweep", "bad"},
          {"job", "noop"},
          {"base", {{"g", 1.0}, {"sleep_s", 0.0}}},
          {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {1.0, 2.0}}}}}};
}

json impact_doc() {
  return {{"sweep", "bad"},
          {"base", json::parse(tiny_base())},
          {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/gravity_m_s2"}, {"values", {9.81, 3.71}}}}}};
}

struct Case {
  std::string name;
  std::string text;     ///< the spec file's content
  std::string where;    ///< the pointer or line the message must name
  std::string also;     ///< another piece the message must hold ("" = none)
  bool impact = false;  ///< needs the impact pipeline
};

std::string with(json doc, const std::string& pointer, const json& value) {
  doc[json::json_pointer(pointer)] = value;
  return doc.dump(1);
}

std::string without(json doc, const std::string& pointer) {
  const json::json_pointer jp(pointer);
  doc[jp.parent_pointer()].erase(jp.back());
  return doc.dump(1);
}

std::vector<Case> corpus() {
  std::vector<Case> c;
  const json n = noop_doc(), im = impact_doc();
  c.push_back({"syntax error", "{\n  \"sweep\": \"x\",\n  \"base\": {\n}", "bad_spec.json:4:", "JSON"});
  c.push_back({"number out of range", "{\"sweep\": \"x\", \"job\": \"noop\",\n \"base\": {\"g\": 1e999}}",
               "bad_spec.json:2:", "1e999"});
  c.push_back({"nested 100000 deep",
               "{\"sweep\": \"x\", \"base\": " + std::string(100000, '[') + std::string(100000, ']') + "}",
               "bad_spec.json:1:", "deeper than 64"});
  c.push_back({"not an object", "[1, 2]", "(array)", "an object"});
  c.push_back({"base is a folder", with(n, "/base", "/tmp"), "/base", "a folder"});
  c.push_back({"base file missing", with(n, "/base", "no_such_scenario.json"), "/base", "no readable file"});
  c.push_back({"sweep missing", without(n, "/sweep"), "/sweep", "missing"});
  c.push_back({"sweep name with a space", with(n, "/sweep", "a b"), "/sweep", "[A-Za-z0-9_.-]+"});
  c.push_back({"unknown key", with(n, "/axis", json::array()), "/axis", "unknown key"});
  c.push_back({"unknown job kind", with(n, "/job", "gpu"), "/job", "noop"});
  c.push_back({"max_attempts 0", with(n, "/max_attempts", 0), "/max_attempts", "between 1 and 100"});
  c.push_back({"priority a string", with(n, "/priority", "high"), "/priority", "an integer"});
  c.push_back({"axes not an array", with(n, "/axes", json::object()), "/axes", "an array"});
  c.push_back({"axis without pointer", without(n, "/axes/0/pointer"), "/axes/0/pointer", "missing"});
  c.push_back({"pointer not in base", with(n, "/axes/0/pointer", "/h"), "/axes/0/pointer", "present in the base"});
  c.push_back({"empty values", with(n, "/axes/0/values", json::array()), "/axes/0/values", "non-empty"});
  c.push_back({"string among numbers", with(n, "/axes/0/values/1", "fast"), "/axes/0/values/1", "a number"});
  c.push_back({"duplicate values", with(n, "/axes/0/values/1", 1.0), "/axes/0/values/1", "differ"});
  c.push_back({"invalid column name", with(n, "/axes/0/name", "Gravity"), "/axes/0/name", "column name"});
  json r = n;
  r["axes"][0].erase("values");
  c.push_back({"range negative step", with(r, "/axes/0/range", {{"start", 1}, {"stop", 2}, {"step", -1}}),
               "/axes/0/range/step", "a positive number"});
  c.push_back({"range step and num", with(r, "/axes/0/range", {{"start", 1}, {"stop", 2}, {"step", 1}, {"num", 2}}),
               "/axes/0/range", "exactly one of"});
  c.push_back({"range stop below start", with(r, "/axes/0/range", {{"start", 2}, {"stop", 1}, {"step", 0.5}}),
               "/axes/0/range/stop", ">= start"});
  c.push_back({"too many points", with(r, "/axes/0/range", {{"start", 0}, {"stop", 1}, {"num", 1000001}}),
               "/axes/0/range/num", "1000000"});
  json z = n;
  z["base"]["h"] = 1.0;
  z["axes"] = {{{"zip", {{{"pointer", "/g"}, {"values", {1.0, 2.0}}}, {{"pointer", "/h"}, {"values", {1.0}}}}}}};
  c.push_back({"zip of unequal lengths", z.dump(), "/axes/0/zip/1", "as many as"});
  json twice = n;
  twice["axes"].push_back({{"name", "g2"}, {"pointer", "/g"}, {"values", {3.0}}});
  c.push_back({"one field swept twice", twice.dump(), "/axes/1", "swept twice"});
  c.push_back({"repeats count 0", with(n, "/repeats", {{"pointer", "/g"}, {"count", 0}}), "/repeats/count",
               "between 1 and 1000000"});
  c.push_back({"noop sleep_s a string", with(n, "/base/sleep_s", "long"), "/base/sleep_s", "a number of seconds"});
  c.push_back({"noop sleep_s negative", with(n, "/base/sleep_s", -1), "/base/sleep_s", "between 0 and 86400"});
  c.push_back({"noop fail_attempts 1.5", with(n, "/base/fail_attempts", 1.5), "/base/fail_attempts", "an integer"});
  json sleeps = n;
  sleeps["axes"][0] = {{"name", "sleep_s"}, {"pointer", "/sleep_s"}, {"values", {0.1, -2.0}}};
  c.push_back({"noop axis value out of range", sleeps.dump(), "/base/sleep_s", "-2"});
  // Impact scenarios: reported at the base's own pointer.
  c.push_back({"repeats step 0.5 on an integer seed",
               with(im, "/repeats", {{"pointer", "/projectile/seed"}, {"count", 3}, {"step", 0.5}}), "/repeats/step",
               "an integer", true});
  c.push_back({"mass a string", with(im, "/base/projectile/mass_kg", "heavy"), "/base/projectile/mass_kg", "", true});
  // 2^64 is shown as the number it is (never wrapped to -9223372036854775808), with the bound in full.
  c.push_back({"seed 2^64", with(im, "/base/bed/seed", json::parse("18446744073709551616")), "/base/bed/seed",
               "found 1.8446744073709552e+19 (number), expected an integer between 0 and 9007199254740991", true});
  c.push_back({"dt_s 5e-324", with(im, "/base/dt_s", 5e-324), "/base/dt_s", "at least 1e-09", true});
  json wide = im;
  wide["base"]["container"]["diameter_m"] = 20;
  c.push_back({"a 20 m x 20 m fill", with(wide, "/base/container/fill_height_m", 20), "/base/container/fill_height_m",
               "this machine's memory", true});
  c.push_back({"unknown scenario field", with(im, "/base/projectile/speed", 1.0), "/base/projectile/speed", "", true});
  return c;
}

}  // namespace

TEST(BadSpecs, EveryCaseExitsTwoNamingFileAndFieldAndWritesNothing) {
  int checked = 0;
  for (const auto& c : corpus()) {
    SCOPED_TRACE(c.name);
    TempDir d;
    write_text(d.path / "bad_spec.json", c.text);
    const auto r = run_cli({"submit", "bad_spec.json", "--db", "c.db"}, d.path);
    EXPECT_EQ(r.code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find("bad_spec.json"), std::string::npos) << r.err.substr(0, 600);
    EXPECT_NE(r.err.find(c.where), std::string::npos) << "expected " << c.where << " in: " << r.err.substr(0, 600);
    if (!c.also.empty()) {
      EXPECT_NE(r.err.find(c.also), std::string::npos) << "expected " << c.also << " in: " << r.err.substr(0, 600);
    }
    EXPECT_FALSE(fs::exists(d.path / "c.db")) << "a refused spec must not create the database";
    EXPECT_FALSE(fs::exists(d.path / "c.files"));
    ++checked;
  }
  std::printf("bad-spec corpus: %d cases refused with exit 2, file and pointer/line\n", checked);
  EXPECT_GE(checked, 25);
}

TEST(BadSpecs, AnIntegerBaseValueTakesFloatAxisValues) {
  TempDir d;
  json doc = impact_doc();
  doc["base"]["gravity_m_s2"] = 10;
  write_text(d.path / "spec.json", doc.dump());
  const auto r = run_cli({"submit", "spec.json", "--dry-run"}, d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("2 points"), std::string::npos) << r.out;
}

TEST(BadSpecs, AScenarioFileOfRunIsCheckedTheSameWay) {
  TempDir d;
  write_text(d.path / "deep.json", std::string(5000, '[') + std::string(5000, ']'));
  auto r = run_cli({"run", "deep.json", "--out", "o"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("deep.json:1:"), std::string::npos) << r.err;
  r = run_cli({"run", ".", "--out", "o"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(fs::exists(d.path / "o"));
}

TEST(BadSpecs, EveryProblemOfAScenarioIsListedInOneMessage) {
  // Three independent problems (a wrong type, an unknown field, a fill below two grains): all three
  // are reported at once, by `run` at the scenario's pointers and by `submit` at the base's.
  TempDir d;
  json scenario = json::parse(tiny_base());
  scenario["projectile"]["mass_kg"] = "heavy";
  scenario["projectile"]["colour"] = "red";
  scenario["container"]["fill_height_m"] = 0.001;
  write_text(d.path / "three.json", scenario.dump(1));
  auto r = run_cli({"run", "three.json", "--out", "o"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("three.json: 3 problems"), std::string::npos) << r.err;
  for (const char* p : {"/projectile/mass_kg", "/projectile/colour", "/container/fill_height_m"})
    EXPECT_NE(r.err.find(std::string(p) + " = "), std::string::npos) << p << " missing in: " << r.err;
  EXPECT_FALSE(fs::exists(d.path / "o"));

  json doc = impact_doc();
  doc["base"] = scenario;
  write_text(d.path / "sweep.json", doc.dump(1));
  r = run_cli({"submit", "sweep.json", "--db", "c.db"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("sweep.json: invalid sweep spec (3 problems)"), std::string::npos) << r.err;
  for (const char* p : {"/base/projectile/mass_kg:", "/base/projectile/colour:", "/base/container/fill_height_m:"})
    EXPECT_NE(r.err.find(p), std::string::npos) << p << " missing in: " << r.err;
  EXPECT_FALSE(fs::exists(d.path / "c.db"));
}

TEST(BadSpecs, AnUnreadableBaseIsOneProblemNotAlsoEveryAxisPointer) {
  TempDir d;
  write_text(d.path / "spec.json", with(noop_doc(), "/base", "/tmp"));
  const auto r = run_cli({"submit", "spec.json", "--db", "c.db"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("(1 problem)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'/tmp' is a folder, not a file"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("/axes/0/pointer"), std::string::npos) << r.err;
}

// The database is a trust boundary: a bed job whose stored scenario was edited after submit (a
// 1000 m container, with this build's validation mark kept) is refused at once, naming the field,
// before anything is allocated: one attempt, dead, not three attempts of several GB each.
TEST(BadSpecs, ATamperedStoredScenarioIsRefusedAtOnceNamingItsField) {
  TempDir d;
  json doc = {{"sweep", "tamper"}, {"base", json::parse(tiny_base())}};
  write_text(d.path / "spec.json", doc.dump());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  {
    db::Database db((d.path / "c.db").string());
    db::Statement q(db, "SELECT job_id, scenario_json FROM jobs WHERE kind = 'bed'");
    ASSERT_TRUE(q.step());
    const std::string job = q.get_text(0);
    json s = json::parse(q.get_text(1));
    s["container"]["diameter_m"] = 1000.0;                    // the validated scenario, and the point as written (a
    if (s.contains(pipeline::StoredScenario::kAsWrittenKey))  // build with uncommitted changes trusts no mark)
      s[pipeline::StoredScenario::kAsWrittenKey]["container"]["diameter_m"] = 1000.0;
    db::Statement u(db, "UPDATE jobs SET scenario_json = ? WHERE job_id = ?");
    u.bind(1, s.dump());
    u.bind(2, job);
    u.step();
  }
  const auto r = run_cli({"work", "--db", "c.db", "--workers", "1", "--quiet"}, d.path);
  db::Database db((d.path / "c.db").string());
  db::Statement q(db, "SELECT state, attempts, last_error FROM jobs WHERE kind = 'bed'");
  ASSERT_TRUE(q.step());
  EXPECT_EQ(q.get_text(0), "dead") << r.err;
  EXPECT_EQ(q.get_int(1), 1) << "refused at its first attempt, not retried";
  EXPECT_NE(q.get_text(2).find("/container/diameter_m"), std::string::npos) << q.get_text(2);
}

// `work --max-memory`: a job whose bed needs more than the limit (its estimate from the scenario:
// the tiny bed's up to ~490 grains at 2 kB, 0.96 MB, against 0.5 MB) is refused before it allocates,
// permanently, naming the fields and the limit; `submit --dry-run` prints the same estimate.
TEST(BadSpecs, AJobAboveTheMemoryLimitIsRefusedBeforeItAllocates) {
  TempDir d;
  json doc = {{"sweep", "memory"}, {"base", json::parse(tiny_base())}};
  write_text(d.path / "spec.json", doc.dump());
  auto r = run_cli({"submit", "spec.json", "--db", "c.db", "--dry-run"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("memory per bed or drop job: up to 0.96 MB"), std::string::npos) << r.out;
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  r = run_cli({"work", "--db", "c.db", "--workers", "1", "--quiet", "--max-memory", "0.5"}, d.path);
  EXPECT_EQ(r.code, 4) << r.err;  // some job is dead
  db::Database db((d.path / "c.db").string());
  db::Statement q(db, "SELECT state, attempts, last_error FROM jobs WHERE kind = 'bed'");
  ASSERT_TRUE(q.step());
  EXPECT_EQ(q.get_text(0), "dead") << r.err;
  EXPECT_EQ(q.get_int(1), 1) << "refused at its first attempt, not retried";
  EXPECT_NE(q.get_text(2).find("/container/fill_height_m"), std::string::npos) << q.get_text(2);
  EXPECT_NE(q.get_text(2).find("above work --max-memory 0.5 MB"), std::string::npos) << q.get_text(2);
}
