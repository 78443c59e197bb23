// `gravsweep serve` as users run it: the real binary on a free port over a campaign that a real
// worker runs meanwhile. The API follows the worker (counts, results, failed jobs, a drop's
// trace), answers in pages, refuses bad filters with the grammar's message, and nothing it
// serves changes the campaign (any method but GET is 405, any other path 404).
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <nlohmann/json.hpp>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "serve_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;

namespace {

json get_json(httplib::Client& c, const std::string& path, int expect = 200) {
  const auto r = c.Get(path.c_str());
  if (!r) {
    ADD_FAILURE() << "GET " << path << ": no answer";
    return json();
  }
  EXPECT_EQ(r->status, expect) << path << ": " << r->body;
  return json::parse(r->body, nullptr, false);
}

std::int64_t done_of(const json& status) {
  std::int64_t done = 0;
  for (const auto& s : status.at("sweeps")) done += s.at("done").get<std::int64_t>();
  return done;
}

/// Every job's state and attempts and the results rows: what a write would change.
std::string campaign_state(const std::filesystem::path& db_path) {
  db::Database db(db_path.string());
  std::string out;
  db::Statement st(db, "SELECT job_id, state, attempts, coalesce(finished_at, 0) FROM jobs ORDER BY seq");
  while (st.step()) out += st.get_text(0) + st.get_text(1) + st.get_text(2) + st.get_text(3) + ";";
  return out + std::to_string(sql_int(db, "SELECT count(*) FROM results")) +
         std::to_string(sql_int(db, "SELECT count(*) FROM attempts"));
}

/// After the worker of TheApiFollowsAWorkerAsItFinishesJobs: the views beyond the counts and rows.
void check_levels_collapse_and_rank(httplib::Client& c) {
  // The drops in Froude scaling: gravity and diameter from each drop's scenario.
  const json col = get_json(c, "/api/collapse");
  ASSERT_EQ(col.at("total"), 2) << col.dump();
  const auto at = [&col](const char* name) {
    const auto& cs = col.at("columns");
    return static_cast<std::size_t>(std::find(cs.begin(), cs.end(), name) - cs.begin());
  };
  for (const auto& row : col.at("rows")) {
    EXPECT_EQ(row[at("gravity_m_s2")], 9.81) << col.dump();
    EXPECT_EQ(row[at("projectile_diameter_m")], 0.03) << col.dump();  // tiny_base's projectile
    const double vc = row[at("vc_m_s")].get<double>();
    EXPECT_NEAR(row[at("froude")].get<double>(), vc / std::sqrt(9.81 * 0.03), 1e-9);
    EXPECT_GT(row[at("zstop_over_d")].get<double>(), 0);
    EXPECT_GT(row[at("tstop_sqrt_g_over_d")].get<double>(), 0);
    EXPECT_GT(row[at("apeak_over_g")].get<double>(), 0);
  }
  EXPECT_EQ(get_json(c, "/api/collapse?where=gravity_m_s2%3C1").at("total"), 0);
  get_json(c, "/api/collapse?where=nope%3C1", 400);

  // Per sweep, kind and gravity level: the four waits at g = 1..4, the dead one at 7, the drops.
  const json lv = get_json(c, "/api/levels");
  ASSERT_EQ(lv.at("levels").size(), 7u) << lv.dump();
  std::map<std::string, json> by;
  for (const auto& l : lv.at("levels"))
    by[l.at("sweep").get<std::string>() + "/" + l.at("kind").get<std::string>() + "/" + l.at("gravity_m_s2").dump()] =
        l;
  EXPECT_EQ(by["wait/noop/4.0"].at("done"), 1) << lv.dump();
  EXPECT_EQ(by["dies/noop/7.0"].at("dead"), 1) << lv.dump();
  EXPECT_EQ(by["drops/drop/9.81"].at("done"), 2) << lv.dump();
  EXPECT_EQ(by["drops/bed/9.81"].at("done"), 1) << lv.dump();
  EXPECT_EQ(by["drops/drop/9.81"].at("eta_s"), 0) << lv.dump();
  EXPECT_GT(by["drops/drop/9.81"].at("jobs_per_min").get<double>(), 0) << lv.dump();

  // Two drops are too few for the model's verdict, and it says so.
  json rank;
  for (int i = 0; i < 100; ++i) {
    rank = get_json(c, "/api/rank");
    if (rank.at("state") != "computing" && rank.at("for").is_object() && rank.at("for").at("drops") == 2) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(rank.at("state"), "not enough drops") << rank.dump();
  EXPECT_NE(rank.value("message", "").find("at least 6"), std::string::npos) << rank.dump();
}

}  // namespace

TEST(Serve, TheApiFollowsAWorkerAsItFinishesJobs) {
  TempDir d;
  ASSERT_TRUE(make_serve_campaign(d.path, 4, 0.4, {0.4, 0.6}));  // 4 + 1 no-op jobs, 1 bed, 2 drops
  ServeProcess serve(d.path);
  ASSERT_GT(serve.port, 0);
  const std::string said = read_file(serve.log);
  EXPECT_NE(said.find("loopback only"), std::string::npos) << said;
  EXPECT_NE(said.find("read-only"), std::string::npos) << said;
  httplib::Client c("127.0.0.1", serve.port);
  c.set_read_timeout(30);
  json s = get_json(c, "/api/status");
  ASSERT_EQ(s.at("sweeps").size(), 4u) << s.dump();  // wait/noop, dies/noop, drops/bed, drops/drop
  EXPECT_EQ(done_of(s), 0);
  EXPECT_EQ(s.at("campaign"), (d.path / "c.db").string());
  // A worker runs the campaign; the counts the API reports climb while it does.
  const pid_t w =
      start_cli({"work", "--db", (d.path / "c.db").string(), "--threads", "1", "--poll", "0.05"}, d.path / "w.log");
  std::set<std::int64_t> seen;
  bool saw_running = false;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(600);
  while (std::chrono::steady_clock::now() < end) {
    s = get_json(c, "/api/status");
    seen.insert(done_of(s));
    saw_running = saw_running || !s.at("running").empty();
    if (done_of(s) == 7) break;  // 4 waits, the bed, 2 drops (the fifth no-op job dies)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(wait_child(w, 120), 4) << "a dead job: work exits 4\n" << read_file(d.path / "w.log");
  EXPECT_EQ(done_of(s), 7) << s.dump(1);
  EXPECT_GE(seen.size(), 3u) << "the done count seen climbing through intermediate values";
  EXPECT_TRUE(saw_running) << "a running job seen with its progress";
  EXPECT_EQ(s.at("running").size(), 0u);

  // Results: rows in pages, with a total; the --where grammar; sorting either way; CSV.
  json r = get_json(c, "/api/results?columns=all");
  EXPECT_EQ(r.at("total"), 6) << r.dump();  // 4 waits, 2 drops (a bed is no results row)
  EXPECT_EQ(r.at("rows").size(), 6u);
  r = get_json(c, "/api/results?limit=2&offset=1&sort=-gravity_m_s2&columns=gravity_m_s2,job_id");
  ASSERT_EQ(r.at("rows").size(), 2u) << r.dump();
  EXPECT_EQ(r.at("total"), 6);
  EXPECT_EQ(r.at("rows")[0][0], 9.81);  // 9.81 (drop), 9.81 (drop), 4, 3, ...: the second and third
  EXPECT_EQ(r.at("rows")[1][0], 4.0);
  r = get_json(c, "/api/results?where=" + httplib::detail::encode_query_param("gravity_m_s2<2.5 and kind=noop") +
                      "&columns=gravity_m_s2&sort=gravity_m_s2");
  EXPECT_EQ(r.at("rows"), json::parse("[[1.0],[2.0]]")) << r.dump();
  const auto csv = c.Get("/api/results?format=csv&columns=gravity_m_s2,kind&where=kind%3Dnoop&sort=gravity_m_s2");
  ASSERT_TRUE(csv);
  EXPECT_EQ(csv->status, 200);
  EXPECT_EQ(csv->body, "gravity_m_s2,kind\r\n1,noop\r\n2,noop\r\n3,noop\r\n4,noop\r\n");
  EXPECT_NE(csv->get_header_value("Content-Disposition").find("results.csv"), std::string::npos);
  // Without columns, a CSV download is what `results --format csv` writes: every column, every row.
  const auto full = c.Get("/api/results?format=csv");
  ASSERT_TRUE(full);
  EXPECT_EQ(full->body, run_cli({"results", "--db", "c.db", "--format", "csv"}, d.path).out);
  json bad =
      get_json(c, "/api/results?where=" + httplib::detail::encode_query_param("gravity_m_s2<1; DELETE FROM jobs"), 400);
  EXPECT_NE(bad.value("error", "").find("expected 'and'"), std::string::npos) << bad.dump();
  bad = get_json(c, "/api/results?sort=nope", 400);
  EXPECT_NE(bad.value("error", "").find("found column 'nope'"), std::string::npos) << bad.dump();
  get_json(c, "/api/results?limit=100000", 400);  // a JSON page is bounded

  check_levels_collapse_and_rank(c);

  // Failed and dead jobs, with the reason.
  const json f = get_json(c, "/api/failed");
  ASSERT_EQ(f.at("total"), 1) << f.dump();
  EXPECT_EQ(f.at("jobs")[0].at("state"), "dead");
  EXPECT_NE(f.at("jobs")[0].at("error").get<std::string>().find("asked to fail"), std::string::npos) << f.dump();

  // A drop: its row and its trace, thinned to the points asked for; a no-op job has no trace.
  db::Database db((d.path / "c.db").string());
  const std::string drop = sql_text(db, "SELECT job_id FROM results WHERE kind='drop' LIMIT 1");
  json t = get_json(c, "/api/drop/" + drop + "?points=100");
  ASSERT_TRUE(t.at("trace").is_object()) << t.dump();
  EXPECT_EQ(t.at("row").at("job_id"), drop);
  const json& tr = t.at("trace");
  EXPECT_GT(tr.at("samples").get<int>(), 100);
  EXPECT_LE(tr.at("t_s").size(), 101u);
  EXPECT_GT(tr.at("t_s").size(), 40u);
  EXPECT_EQ(tr.at("accel_up_m_s2").size(), tr.at("t_s").size());
  EXPECT_EQ(tr.at("depth_m").size(), tr.at("t_s").size());
  EXPECT_LT(tr.at("t_s")[0].get<double>(), tr.at("t_s")[1].get<double>());
  const std::string noop = sql_text(db, "SELECT job_id FROM results WHERE kind='noop' LIMIT 1");
  t = get_json(c, "/api/drop/" + noop);
  EXPECT_TRUE(t.at("trace").is_null());
  EXPECT_NE(t.value("trace_error", "").find("no trace"), std::string::npos) << t.dump();
  get_json(c, "/api/drop/0123456789abcdef", 404);
  get_json(c, "/api/drop/not-a-job", 404);

  // The drop's Fig. 2 and Fig. 1 as PNG images, drawn once: with the trace moved away they are
  // still served, as drawn. A no-op job has none, and a figure of another name is no page.
  std::map<std::string, std::string> drawn;
  const auto png_of = [&c](const std::string& path) {
    const auto png = c.Get(path.c_str());
    EXPECT_TRUE(png) << path;
    if (!png) return std::string();
    EXPECT_EQ(png->status, 200) << path << ": " << png->body;
    EXPECT_EQ(png->get_header_value("Content-Type"), "image/png") << path;
    return png->body;
  };
  for (const char* fig : {"fig2", "fig1"}) {
    const std::string path = "/api/drop/" + drop + "/" + fig + ".png";
    drawn[path] = png_of(path);
    ASSERT_GT(drawn[path].size(), 10000u) << path;
    EXPECT_EQ(drawn[path].substr(1, 3), "PNG") << path;
  }
  const std::filesystem::path trace =
      d.path / "c.files" / sql_text(db, "SELECT trace_path FROM results WHERE job_id='" + drop + "'");
  ASSERT_TRUE(std::filesystem::exists(trace)) << trace;
  std::filesystem::rename(trace, trace.string() + ".away");
  for (const auto& [path, bytes] : drawn) EXPECT_EQ(png_of(path), bytes) << path << ": drawn again";
  std::filesystem::rename(trace.string() + ".away", trace);
  EXPECT_NE(get_json(c, "/api/drop/" + noop + "/fig2.png", 404).value("error", "").find("not a drop"),
            std::string::npos);
  get_json(c, "/api/drop/" + drop + "/fig3.png", 404);

  // A job's attempts are its log: the dead job's attempts, the last first, with worker, host and error.
  const std::string dead = f.at("jobs")[0].at("job_id");
  const json a = get_json(c, "/api/attempts/" + dead);
  ASSERT_EQ(a.at("attempts").size(), f.at("jobs")[0].at("attempts").get<std::size_t>()) << a.dump();
  EXPECT_EQ(a.at("attempts")[0].at("outcome"), "dead") << a.dump();
  EXPECT_FALSE(a.at("attempts")[0].at("worker").get<std::string>().empty());
  EXPECT_FALSE(a.at("attempts")[0].at("host").get<std::string>().empty());
  EXPECT_NE(a.at("attempts")[0].at("error").get<std::string>().find("asked to fail"), std::string::npos) << a.dump();
  EXPECT_EQ(get_json(c, "/api/attempts/" + drop).at("attempts")[0].at("outcome"), "done");
  get_json(c, "/api/attempts/0123456789abcdef", 404);
  get_json(c, "/api/attempts/not-a-job", 404);

  // Nothing served writes: other methods are refused, unknown paths are 404, the campaign unchanged.
  const std::string before = campaign_state(d.path / "c.db");
  for (const char* path : {"/api/status", "/api/results", "/", "/api/drop/"}) {
    const std::string p = std::string(path) + (std::string(path) == "/api/drop/" ? drop : "");
    auto post = c.Post(p.c_str(), "{}", "application/json");
    ASSERT_TRUE(post);
    EXPECT_EQ(post->status, 405) << p;
    EXPECT_EQ(post->get_header_value("Allow"), "GET, HEAD");
    auto del = c.Delete(p.c_str());
    ASSERT_TRUE(del);
    EXPECT_EQ(del->status, 405) << p;
    auto put = c.Put(p.c_str(), "x", "text/plain");
    ASSERT_TRUE(put);
    EXPECT_EQ(put->status, 405) << p;
  }
  // A page elsewhere whose host name points at 127.0.0.1 (DNS rebinding) is refused.
  const auto rebound = c.Get("/api/status", httplib::Headers{{"Host", "campaign.evil.example:80"}});
  ASSERT_TRUE(rebound);
  EXPECT_EQ(rebound->status, 403);
  const auto local = c.Get("/api/status", httplib::Headers{{"Host", "localhost:" + std::to_string(serve.port)}});
  ASSERT_TRUE(local);
  EXPECT_EQ(local->status, 200);
  get_json(c, "/api/nothing", 404);
  get_json(c, "/api/status/../../c.db", 404);
  EXPECT_EQ(campaign_state(d.path / "c.db"), before);

  // The page itself: one self-contained document, nothing fetched from elsewhere.
  const auto page = c.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<canvas id=\"trace-canvas\""), std::string::npos);
  EXPECT_EQ(page->body.find("src=\"http"), std::string::npos);
  EXPECT_EQ(page->body.find("href=\"http"), std::string::npos);
  EXPECT_EQ(serve.stop(), 0) << read_file(serve.log);
}

// The verdict of `model rank` follows the finished drops: computed in the background for the
// campaign's state, never while a request waits, and the same as the verb's.
TEST(Serve, TheModelVerdictIsComputedAgainWhenDropsFinish) {
  TempDir d;
  ASSERT_TRUE(make_serve_campaign(d.path, 1, 0, {0.4, 0.5, 0.6}, {9.81, 3.71}));  // 6 drops at two levels
  ServeProcess serve(d.path);
  ASSERT_GT(serve.port, 0);
  httplib::Client c("127.0.0.1", serve.port);
  c.set_read_timeout(30);
  json r = get_json(c, "/api/rank");
  EXPECT_TRUE(r.at("state") == "computing" || r.at("state") == "not enough drops") << r.dump();
  EXPECT_EQ(r.at("min_drops"), 6);
  const pid_t w =
      start_cli({"work", "--db", (d.path / "c.db").string(), "--threads", "1", "--poll", "0.05"}, d.path / "w.log");
  EXPECT_EQ(wait_child(w, 600), 4) << "a dead job: work exits 4\n" << read_file(d.path / "w.log");
  double slowest = 0;
  std::set<std::string> states;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(300);
  while (std::chrono::steady_clock::now() < end) {
    const auto t0 = std::chrono::steady_clock::now();
    r = get_json(c, "/api/rank");
    slowest = std::max(slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    states.insert(r.at("state").get<std::string>());
    if (r.at("state") != "computing" && r.at("for").is_object() && r.at("for").at("drops") == 6) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(r.at("state"), "ready") << r.dump(1);
  EXPECT_LT(slowest, 1.0) << "a request never waits for the computation";
  EXPECT_EQ(r.at("trials"), 6) << r.dump();
  EXPECT_GT(r.at("computed_at").get<double>(), 0);
  ASSERT_EQ(r.at("ranking").at("columns")[2], "term");
  EXPECT_FALSE(r.at("ranking").at("rows").empty()) << r.dump();
  // The verb on the same campaign says the same.
  const auto verb = run_cli({"model", "rank", "c.db"}, d.path);
  ASSERT_EQ(verb.code, 0) << verb.err;
  EXPECT_NE(verb.out.find("Verdict: " + r.at("verdict").get<std::string>()), std::string::npos) << verb.out << "\n"
                                                                                                << r.dump();
  // Nothing changed since: the same answer, not computed again.
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  EXPECT_EQ(get_json(c, "/api/rank").at("computed_at"), r.at("computed_at"));
  EXPECT_EQ(serve.stop(), 0) << read_file(serve.log);
}

TEST(Serve, ABadDatabaseOrABusyPortIsRefusedNamingIt) {
  TempDir d;
  auto r = run_cli({"serve", "--db", "missing.db", "--port", "0"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing.db"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.path / "missing.db")) << "serve must not create a database";
  ASSERT_TRUE(make_serve_campaign(d.path, 1, 0, {0.5}));
  // A port some other program listens on.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(::listen(fd, 1), 0);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  const std::string port = std::to_string(ntohs(a.sin_port));
  r = run_cli({"serve", "--db", "c.db", "--port", port}, d.path);
  ::close(fd);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("127.0.0.1:" + port), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--port 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("another program listens on it"), std::string::npos) << r.err;
  // An address that is not this machine's (TEST-NET-1, RFC 5737).
  r = run_cli({"serve", "--db", "c.db", "--port", "0", "--bind", "192.0.2.1"}, d.path);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("192.0.2.1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is --bind an address of this machine"), std::string::npos) << r.err;
  r = run_cli({"serve", "--db", "c.db", "--port", "70000"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
}

TEST(Serve, HelpTeachesWithExamples) {
  TempDir d;
  const auto r = run_cli({"serve", "--help"}, d.path);
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("read-only"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Examples:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("gravsweep serve --db campaign.db"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/api/status"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/api/rank"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Froude"), std::string::npos) << r.out;
}
