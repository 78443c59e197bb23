// `gravsweep serve` means the same on both backends: run once on an SQLite file and once on the
// throwaway PostgreSQL server (tests/common/postgres_server.h). Pages of results (offset, limit,
// either order), the count of what a filter selects, `~` and the CSV download, the failed jobs,
// and a refused write.
#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>

#include "campaign_store.h"
#include "serve_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;

namespace {

struct ServeBackends : StoreTest {
  CmdResult cli(std::vector<std::string> args) {
    for (const auto& a : store.args()) args.push_back(a);
    return run_cli(args, dir.path);
  }
};

json get(httplib::Client& c, const std::string& path) {
  const auto r = c.Get(path.c_str());
  if (!r) {
    ADD_FAILURE() << path << ": no answer";
    return json();
  }
  EXPECT_EQ(r->status, 200) << path << ": " << r->body;
  return json::parse(r->body, nullptr, false);
}

}  // namespace

TEST_P(ServeBackends, PagesFiltersAndFailedJobsAreTheSameOnBothBackends) {
  const json ok = {{"sweep", "p"},
                   {"job", "noop"},
                   {"base", {{"g", 1.0}}},
                   {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {0.5, 1.0, 1.5, 2.0, 2.5}}}}}};
  const json dies = {{"sweep", "d"},
                     {"job", "noop"},
                     {"max_attempts", 1},
                     {"base", {{"g", 7.0}, {"fail_attempts", 9}}},
                     {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {7.0}}}}}};
  write_text(dir.path / "ok.json", ok.dump());
  write_text(dir.path / "dies.json", dies.dump());
  ASSERT_EQ(cli({"submit", "ok.json", "dies.json"}).code, 0);
  ASSERT_EQ(cli({"work", "--quiet", "--poll", "0.02"}).code, 4);  // the dead job
  ServeProcess serve(dir.path, store.args());
  ASSERT_GT(serve.port, 0);
  httplib::Client c("127.0.0.1", serve.port);
  c.set_read_timeout(30);
  json r = get(c, "/api/results?sort=-gravity_m_s2&offset=1&limit=2&columns=gravity_m_s2");
  EXPECT_EQ(r.at("rows"), json::parse("[[2.0],[1.5]]")) << r.dump();
  EXPECT_EQ(r.at("total"), 5);
  r = get(c, "/api/results?sort=gravity_m_s2&offset=3&columns=gravity_m_s2");
  EXPECT_EQ(r.at("rows"), json::parse("[[2.0],[2.5]]")) << r.dump();
  r = get(c, "/api/results?where=gravity_m_s2~1.5&columns=gravity_m_s2");
  EXPECT_EQ(r.at("rows"), json::parse("[[1.5]]")) << r.dump();
  EXPECT_EQ(r.at("total"), 1);
  const auto csv = c.Get("/api/results?format=csv&columns=gravity_m_s2&sort=gravity_m_s2&offset=4");
  ASSERT_TRUE(csv);
  EXPECT_EQ(csv->body, "gravity_m_s2\r\n2.5\r\n");
  const json f = get(c, "/api/failed");
  ASSERT_EQ(f.at("total"), 1) << f.dump();
  EXPECT_NE(f.at("jobs")[0].at("error").get<std::string>().find("asked to fail"), std::string::npos);
  const json s = get(c, "/api/status");
  ASSERT_EQ(s.at("sweeps").size(), 2u) << s.dump();
  const auto post = c.Post("/api/results", "", "text/plain");
  ASSERT_TRUE(post);
  EXPECT_EQ(post->status, 405);
  EXPECT_EQ(serve.stop(), 0) << read_file(serve.log);
}

GRAVSWEEP_INSTANTIATE_ON_THE_QUEUE_BACKEND(ServeBackends);
