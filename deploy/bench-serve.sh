#!/usr/bin/env bash
# The load time of the `gravsweep serve` page on a large campaign (docs/serve.md, "Load time"):
# N no-op jobs (default 100,000: 5 gravity levels x N/5 speeds) submitted by `gravsweep submit`,
# a few hundred run by a real worker, then most of the rest marked done by SQL in the form the
# worker gave the real ones (results rows, attempts), a share failed and dead, the rest queued, so
# that the campaign takes seconds to make instead of minutes of workers. Then `serve` on it, the
# API timed with curl and the page loaded in headless chromium (tests/scheduler/serve_page_check.js).
#   deploy/bench-serve.sh [N] [DIR]     (DIR kept; default a temporary folder)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
gs="${GRAVSWEEP_BUILD_DIR:-$root/build}/scheduler/gravsweep"
n="${1:-100000}"
dir="${2:-$(mktemp -d)}"
mkdir -p "$dir"
cd "$dir"
rm -rf big.db big.db-wal big.db-shm big.files
per=$((n / 5))
cat > big.json <<SPEC
{"sweep": "big", "job": "noop", "max_attempts": 2, "base": {"g": 1.0, "v": 0.0},
 "axes": [{"name": "gravity_m_s2", "pointer": "/g", "values": [9.81, 3.71, 1.62, 0.5, 0.1]},
          {"name": "impact_speed_m_s", "pointer": "/v", "range": {"start": 0.1, "stop": 5.0, "num": $per}}]}
SPEC
"$gs" submit big.json --db big.db >/dev/null
timeout 20 "$gs" work --db big.db --workers 1 --poll 0.01 --quiet >/dev/null 2>&1 || true
/usr/bin/python3 - big.db <<'PY'
import sqlite3, sys, time
db = sqlite3.connect(sys.argv[1])
now = time.time()
cols = [r[1] for r in db.execute("PRAGMA table_info(results)")]
real = db.execute("SELECT count(*) FROM results").fetchone()[0]
total = db.execute("SELECT count(*) FROM jobs").fetchone()[0]
done_to = int(total * 0.9)
with db:
    db.execute("CREATE TEMP TABLE pick AS SELECT job_id, params_json FROM jobs WHERE state='queued' ORDER BY seq LIMIT ?",
               (done_to - real,))
    db.execute("UPDATE jobs SET state='done', attempts=1, finished_at=?, started_at=?-0.01, "
               "output_path='noop/'||job_id||'.a1.json' WHERE job_id IN (SELECT job_id FROM pick)", (now, now))
    db.execute("INSERT INTO attempts(job_id, attempt, lease_token, kind, worker, host, pid, threads, code_version, "
               "started_at, ended_at, runtime_s, outcome, output_path) SELECT job_id, 1, 1, 'noop', 'bench', 'bench', 0, 1, "
               "'bench', ?-0.01, ?, 0.01, 'done', 'noop/'||job_id||'.a1.json' FROM pick", (now, now))
    values = {"job_id": "job_id", "sweep": "'big'", "kind": "'noop'", "bed_job_id": "NULL", "attempt": "1",
              "trace_path": "'noop/'||job_id||'.a1.json'", "trace_sha256": "printf('%064d', 0)",
              "trace_bytes": "64", "runtime_s": "0.01", "finished_at": str(now), "code_version": "'bench'",
              "gravity_m_s2": "json_extract(params_json, '$.gravity_m_s2')",
              "impact_speed_m_s": "json_extract(params_json, '$.impact_speed_m_s')"}
    select = ", ".join(values.get(c, "0") for c in cols)
    db.execute(f"INSERT INTO results({', '.join(chr(34) + c + chr(34) for c in cols)}) SELECT {select} FROM pick")
    # 1 % dead, 1 % failed (waiting for a retry), with their reasons; the rest stays queued.
    db.execute("UPDATE jobs SET state='dead', attempts=2, finished_at=?, last_error='noop job asked to fail on "
               "attempt 2 (bench)' WHERE job_id IN (SELECT job_id FROM jobs WHERE state='queued' ORDER BY seq LIMIT ?)",
               (now, total // 100))
    db.execute("UPDATE jobs SET state='failed', attempts=1, finished_at=?, not_before=?+1e9, last_error='noop job "
               "asked to fail on attempt 1 (bench)' WHERE job_id IN (SELECT job_id FROM jobs WHERE state='queued' "
               "ORDER BY seq LIMIT ?)", (now, now, total // 100))
print(dict(db.execute("SELECT state, count(*) FROM jobs GROUP BY state").fetchall()),
      db.execute("SELECT count(*) FROM results").fetchone()[0], "results rows")
PY
"$gs" serve --db big.db --port 0 > serve.log 2>&1 &
serve=$!
trap 'kill $serve 2>/dev/null || true' EXIT
for _ in $(seq 600); do grep -q http serve.log && break; sleep 0.1; done
url="$(grep -o 'http://[0-9.:]*/' serve.log | head -1)"
[ -n "$url" ] || { echo "bench-serve: serve printed no URL within 60 s:" >&2; cat serve.log >&2; exit 1; }
for path in "api/status" "api/status" "api/status" "api/results?limit=50" "api/results?limit=50&sort=-impact_speed_m_s" \
            "api/results?limit=50&offset=80000&where=gravity_m_s2%3C1" "api/failed?limit=20" \
            "api/results?columns=impact_speed_m_s,noop_value,gravity_m_s2&limit=5000" "api/results?format=csv" \
            "api/levels" "api/levels" "api/collapse"; do
  curl -s -o /dev/null -w "GET /$path: %{http_code}, %{size_download} bytes, %{time_total} s\n" "$url$path"
done
for run in 1 2 3; do
  NODE_PATH="$root/deploy/node/node_modules" node "$root/tests/scheduler/serve_page_check.js" "$url" "$dir/big.png" --load
done
