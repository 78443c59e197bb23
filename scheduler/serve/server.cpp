#include "scheduler/serve/server.h"

#include <fmt/format.h>
#include <httplib.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "engine/core/error.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/stop.h"
#include "scheduler/serve/api.h"
#include "scheduler/serve/figures.h"
#include "scheduler/serve/levels.h"
#include "scheduler/serve/page_html.h"
#include "scheduler/serve/rank.h"

namespace gravsweep::serve {

namespace {

/// Open campaign connections to lend to the request threads: one a thread at a time, opened on
/// first need and kept for the next request.
class Connections {
 public:
  explicit Connections(const ServeOptions& o) : db_(o.db), files_(o.files) {}

  class Lease {
   public:
    Lease(Connections& pool, std::unique_ptr<db::Database> db) : pool_(pool), db_(std::move(db)) {}
    ~Lease() {
      if (db_) pool_.give_back(std::move(db_));
    }
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    db::Database& operator*() { return *db_; }
    /// The connection failed (a server restart): do not lend it again.
    void discard() { db_.reset(); }

   private:
    Connections& pool_;
    std::unique_ptr<db::Database> db_;
  };

  Lease take() {
    {
      const std::lock_guard<std::mutex> lock(m_);
      if (!idle_.empty()) {
        auto db = std::move(idle_.back());
        idle_.pop_back();
        return Lease(*this, std::move(db));
      }
    }
    return Lease(*this, std::make_unique<db::Database>(queue::open_campaign(db_, queue::OpenMode::read, files_)));
  }

 private:
  void give_back(std::unique_ptr<db::Database> db) {
    const std::lock_guard<std::mutex> lock(m_);
    idle_.push_back(std::move(db));
  }

  std::string db_, files_;
  std::mutex m_;
  std::vector<std::unique_ptr<db::Database>> idle_;
};

/// The status is the dearest query a page polls (0.2 s on 100,000 jobs and their attempts, most
/// of it the runtimes behind the ETA): computed at most once a second, whatever the number of
/// pages open. A caller that finds it being computed waits for that answer instead of asking again.
class StatusCache {
 public:
  Reply get(db::Database& db, const std::string& campaign) {
    const std::lock_guard<std::mutex> lock(m_);
    const auto now = std::chrono::steady_clock::now();
    if (!fresh_ || now - at_ > std::chrono::seconds(1)) {
      reply_ = status_reply(db, campaign);
      at_ = now;
      fresh_ = reply_.status == 200;
    }
    return reply_;
  }

 private:
  std::mutex m_;
  Reply reply_;
  std::chrono::steady_clock::time_point at_;
  bool fresh_ = false;
};

void send(httplib::Response& res, const Reply& r) {
  res.status = r.status;
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Content-Type-Options", "nosniff");
  if (!r.download_name.empty())
    res.set_header("Content-Disposition", fmt::format("attachment; filename=\"{}\"", r.download_name));
  res.set_content(r.body, r.content_type.c_str());
}

Params params_of(const httplib::Request& req) { return Params(req.params.begin(), req.params.end()); }

/// A handler that answers `api(db, request)` with a connection of the pool.
httplib::Server::Handler with_db(Connections& pool, std::function<Reply(db::Database&, const httplib::Request&)> api) {
  return [&pool, api = std::move(api)](const httplib::Request& req, httplib::Response& res) {
    auto db = pool.take();
    try {
      send(res, api(*db, req));
    } catch (const db::DbError& e) {
      db.discard();
      send(res, error_reply(503, fmt::format("the campaign database did not answer: {}", e.what())));
    }
  };
}

/// The host of a Host header ("127.0.0.1:8080" -> 127.0.0.1, "[::1]:8080" -> ::1).
std::string host_of(const std::string& header) {
  if (!header.empty() && header[0] == '[') return header.substr(1, header.find(']') - 1);
  return header.substr(0, header.find(':'));
}

void add_routes(httplib::Server& svr, Connections& pool, StatusCache& status, LevelCounts& levels, DropFigures& figures,
                const ServeOptions& o, const std::optional<queue::CampaignPaths>& paths,
                const std::optional<RankWatch>& rank) {
  svr.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(page_html(), "text/html; charset=utf-8");
  });
  svr.Get("/api/status", with_db(pool, [&status, name = o.db](db::Database& db, const httplib::Request&) {
            return status.get(db, name);
          }));
  svr.Get("/api/levels",
          with_db(pool, [&levels](db::Database& db, const httplib::Request&) { return levels.reply(db); }));
  svr.Get("/api/results", with_db(pool, [](db::Database& db, const httplib::Request& req) {
            return results_reply(db, params_of(req));
          }));
  svr.Get("/api/failed", with_db(pool, [](db::Database& db, const httplib::Request& req) {
            return failed_reply(db, params_of(req));
          }));
  svr.Get("/api/collapse", with_db(pool, [](db::Database& db, const httplib::Request& req) {
            return collapse_reply(db, params_of(req));
          }));
  svr.Get(R"(/api/drop/([^/]+))", with_db(pool, [&paths](db::Database& db, const httplib::Request& req) {
            return drop_reply(db, paths ? &*paths : nullptr, req.matches[1].str(), params_of(req));
          }));
  svr.Get(R"(/api/drop/([^/]+)/([^/]+)\.png)",
          with_db(pool, [&paths, &figures](db::Database& db, const httplib::Request& req) {
            return figures.reply(db, paths ? &*paths : nullptr, req.matches[1].str(), req.matches[2].str());
          }));
  svr.Get(R"(/api/attempts/([^/]+))", with_db(pool, [](db::Database& db, const httplib::Request& req) {
            return attempts_reply(db, req.matches[1].str());
          }));
  // The verdict is computed by its own thread (rank.h): a request only copies the latest answer.
  svr.Get("/api/rank", [&rank](const httplib::Request&, httplib::Response& res) {
    send(res, rank ? rank->reply() : error_reply(503, "the model verdict is not watched yet"));
  });
  // Read-only: every other method is refused, whatever the path, before any body is read. Served
  // on loopback, a request must also name a loopback host: a web page elsewhere that points one of
  // its own host names at 127.0.0.1 (DNS rebinding) gets nothing.
  svr.set_pre_routing_handler([loopback = is_loopback(o.bind)](const httplib::Request& req, httplib::Response& res) {
    if (req.method != "GET" && req.method != "HEAD") {
      send(res, error_reply(405, fmt::format("{} {}: gravsweep serve is read-only (GET only)", req.method, req.path)));
      res.set_header("Allow", "GET, HEAD");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (loopback && !is_loopback(host_of(req.get_header_value("Host")))) {
      send(res, error_reply(403, "served on loopback: ask for it as 127.0.0.1 or localhost"));
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  svr.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    send(res, error_reply(res.status, res.status == 404
                                          ? fmt::format("{}: no such page (see docs/serve.md for the API)", req.path)
                                          : fmt::format("{} {}: refused ({})", req.method, req.path, res.status)));
  });
  svr.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "unknown error";
    try {
      std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    send(res, error_reply(500, fmt::format("{}: {}", req.path, what)));
  });
}

std::string url_of(const std::string& host, int port) {
  const bool v6 = host.find(':') != std::string::npos;
  return fmt::format("http://{}{}{}:{}/", v6 ? "[" : "", host, v6 ? "]" : "", port);
}

}  // namespace

void serve(const ServeOptions& o, const std::function<void(const std::string& url)>& listening) {
  Connections pool(o);
  { auto first = pool.take(); }  // not a campaign, unreadable: refused now, naming the file
  // A server campaign read without its files root still shows everything but the traces.
  std::optional<queue::CampaignPaths> paths;
  if (!db::is_postgres_url(o.db) || !o.files.empty()) paths.emplace(o.db, o.files);
  httplib::Server svr;
  const int threads = std::max(2, o.threads);
  svr.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
  // A browser keeps connections open; a short keep-alive frees their threads for others.
  svr.set_keep_alive_timeout(2);
  StatusCache status;
  LevelCounts levels;
  DropFigures figures;
  std::optional<RankWatch> rank;  // started once the port is bound
  add_routes(svr, pool, status, levels, figures, o, paths, rank);
  errno = 0;
  int port = o.port;
  if (o.port == 0) {
    port = svr.bind_to_any_port(o.bind);
  } else if (!svr.bind_to_port(o.bind, o.port)) {
    port = -1;
  }
  if (port <= 0) {
    const int err = errno;
    const std::string hint = err == EADDRINUSE ? "another program listens on it: choose another --port, or --port 0 "
                                                 "for any free port"
                                               : "is --bind an address of this machine (127.0.0.1, 0.0.0.0, one of "
                                                 "its interfaces)?";
    throw ConfigError(fmt::format("cannot listen on {}:{}: {}; {}", o.bind, o.port,
                                  err ? std::strerror(err) : "the address cannot be resolved or bound", hint));
  }
  rank.emplace(o.db, o.files, paths);
  queue::install_stop_signals();
  std::thread watcher([&svr] {
    while (!queue::stop_requested().load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    svr.stop();
  });
  try {
    listening(url_of(o.bind, port));
    svr.listen_after_bind();
  } catch (...) {
    queue::stop_requested().store(true);
    watcher.join();
    throw;
  }
  queue::stop_requested().store(true);  // the server ended of its own: let the watcher go
  watcher.join();
}

bool is_loopback(const std::string& host) { return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0; }

const char* page_html() { return kPageHtml; }

}  // namespace gravsweep::serve
