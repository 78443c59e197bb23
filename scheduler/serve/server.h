// The HTTP server of `gravsweep serve`: the page at /, the JSON API under /api/ (api.h), nothing
// else. Read-only by construction: GET (and HEAD) only; any other method is answered 405, any
// other path 404, and the campaign is opened for reading. Requests run on a small thread pool,
// each with its own database connection (one connection a thread: db/database.h), so a slow page
// of results never holds up the status poll; SQLite in WAL mode lets them read while workers write.
#pragma once
#include <functional>
#include <string>

namespace gravsweep::serve {

struct ServeOptions {
  std::string db;     ///< an SQLite file or a postgresql:// URL
  std::string files;  ///< the files root (default: beside an SQLite file)
  std::string bind = "127.0.0.1";
  int port = 8080;  ///< 0: any free port (the one bound is reported)
  int threads = 8;
};

/// Serves until SIGINT/SIGTERM (queue::stop_requested). `listening(url)` is called once the port
/// is bound. Throws ConfigError naming the database (not a campaign) or the address (in use,
/// cannot be bound) before serving anything.
void serve(const ServeOptions& o, const std::function<void(const std::string& url)>& listening);

/// True for a name or address of this machine's loopback interface (localhost, 127.x.y.z, ::1).
bool is_loopback(const std::string& host);

/// The page at / (page.html, compiled in).
const char* page_html();

}  // namespace gravsweep::serve
