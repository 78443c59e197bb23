#!/usr/bin/env bash
# What the whole five-level gravity sweep (GRAVITY.md, examples/gravity_sweep/) costs on this
# machine's cores, from scratch: the five beds prepared, then the 50 drops, per level. For
# BENCHMARKS.md ("Campaigns"); a figure for before/after comparisons of two builds on one host.
#
#   deploy/bench-sweep.sh estimate            the cost read from the committed records: each level's
#                                             drops (data/gravity_sweep/results.csv: runtime_s x threads)
#                                             and bed (its report in data/gravity_sweep/beds/), as
#                                             core-hours and as wall hours on CORES cores
#   deploy/bench-sweep.sh run OUT [GRAVSWEEP] the sweep from scratch into OUT/sweep.db (no bed cache:
#                                             every bed is poured, settled and ramped), then the report
#   deploy/bench-sweep.sh report OUT          per level: beds and drops (count, wall, core-hours),
#                                             the drop at Fr 1, and the campaign's wall from its first
#                                             claim to its last completion
#
# Environment: CORES (2), WORKERS (CORES), THREADS (1): the pool `run` starts (gravsweep work
# --workers W --threads T); SPECS (examples/gravity_sweep: every g*.json in it); WHERE (a `submit
# --where` filter on the axes, e.g. 'projectile_seed<2', to time part of the sweep; `run` prints
# it before the report). `run` resumes an interrupted campaign in OUT
# (the campaign's own records give the figures, so an interruption costs only the lost work; say
# so with the figure). Run it on an otherwise idle machine: the report prints the host's CPU
# model and load average. The records' runtime_s is an attempt's wall time, so two builds compare
# only on one host, interleaved or back to back.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
usage="usage: deploy/bench-sweep.sh estimate | run OUT [GRAVSWEEP] | report OUT"
py=/usr/bin/python3
cores="${CORES:-2}"
specs="${SPECS:-$root/examples/gravity_sweep}"

report() {
  local db="$1/sweep.db"
  [ -f "$db" ] || { echo "bench-sweep: no campaign at $db" >&2; exit 2; }
  echo "host: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores; load average $(cut -d' ' -f1-3 /proc/loadavg)"
  "$py" - "$db" "$cores" <<'PY'
import json, math, sqlite3, statistics, sys
db, cores = sys.argv[1], int(sys.argv[2])
con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
# Each finished job with the wall and core time of all its attempts (an attempt interrupted and
# resumed from its checkpoint counts with the one that finished it).
rows = con.execute("""
  SELECT j.sweep_id, j.kind, sum(a.runtime_s), max(a.threads), min(a.started_at), max(a.ended_at),
         group_concat(DISTINCT a.code_version), j.scenario_json, sum(a.runtime_s * a.threads)
  FROM attempts a JOIN jobs j ON j.job_id = a.job_id
  WHERE j.state = 'done' AND a.runtime_s IS NOT NULL GROUP BY j.job_id""").fetchall()
if not rows:
    sys.exit("bench-sweep: no finished attempt in " + db)
states = dict(con.execute("SELECT state, count(*) FROM jobs GROUP BY state").fetchall())
def facts(scenario):
    """gravity (m/s2) and Froude number v / sqrt(g D) of a stored scenario (its fields, with the
    validation marks beside them)."""
    s = json.loads(scenario)
    g, p = s.get("gravity_m_s2"), s.get("projectile", {})
    v, d = p.get("impact_speed_m_s"), p.get("diameter_m")
    return g, (v / math.sqrt(g * d) if v and g and d else float("nan"))
by = {}
for sweep, kind, rt, th, t0, t1, build, scen, core_s in rows:
    g, fr = facts(scen)
    e = by.setdefault((sweep, g), {"bed": [], "drop": [], "t0": t0, "t1": t1, "fr1": []})
    e[kind].append((rt, core_s))
    e["t0"], e["t1"] = min(e["t0"], t0), max(e["t1"], t1)
    if kind == "drop" and abs(fr - 1) < 0.05: e["fr1"].append(rt)
builds = sorted({b for r in rows for b in r[6].split(",")})
print(f"campaign {db}: builds {', '.join(builds)}; jobs " + ", ".join(f"{k} {v}" for k, v in sorted(states.items())))
hdr = ["sweep", "gravity_m_s2", "beds", "bed_wall_s", "drops", "drop_wall_median_s", "drop_wall_max_s",
       "drop_at_fr1_wall_s", "core_h", "span_h"]
out = []
for sweep, g in sorted(by, key=lambda k: (-k[1], k[0])):  # by level, then sweep
    e = by[(sweep, g)]
    core_s = sum(c for _, c in e["bed"] + e["drop"])
    drops = [rt for rt, _ in e["drop"]]
    out.append([sweep, "%g" % g, len(e["bed"]), "%.0f" % sum(rt for rt, _ in e["bed"]), len(drops),
                "%.0f" % statistics.median(drops) if drops else "-", "%.0f" % max(drops) if drops else "-",
                "/".join("%.0f" % x for x in e["fr1"]) or "-", "%.2f" % (core_s / 3600),
                "%.2f" % ((e["t1"] - e["t0"]) / 3600)])
w = [max(len(str(r[i])) for r in [hdr] + out) for i in range(len(hdr))]
for r in [hdr] + out:
    print("  ".join(str(c).rjust(w[i]) for i, c in enumerate(r)))
core_h = sum(r[8] for r in rows) / 3600
span = (max(r[5] for r in rows) - min(r[4] for r in rows)) / 3600
print(f"whole campaign: {core_h:.2f} core-hours; wall {span:.2f} h ({span * 3600:.0f} s) from the first claim to the last "
      f"completion ({core_h / cores:.2f} h if {cores} cores never idled)")
PY
}

case "${1:-}" in
  estimate)
    "$py" - "$root/data/gravity_sweep" "$cores" <<'PY'
import csv, json, os, statistics, sys
import h5py
data, cores = sys.argv[1], int(sys.argv[2])
levels = ["9.81", "1.62", "0.1", "0.01", "0.001"]
# The sweep's 50 drops: each level's folder and its at-rest rerun on the axis window (g<level>_axis).
folders = lambda lv: ("g" + lv, "g" + lv + "_axis")
rows = list(csv.DictReader(open(os.path.join(data, "results.csv"))))
print("the committed gravity sweep's records (data/gravity_sweep/results.csv and its beds' reports); "
      "runtime_s is each attempt's wall time on the host that ran it, beside other work: an upper bound")
hdr = ["gravity_m_s2", "drops", "drop_core_h", "bed", "bed_core_h", "level_core_h", f"wall_h_on_{cores}_cores"]
out, tot = [], 0.0
for lv in levels:
    rs = [r for r in rows if r["folder"] in folders(lv)]
    drop_s = sum(float(r["runtime_s"]) * int(float(r["threads"] or 1)) for r in rs)
    beds = sorted({r["bed_job_id"] for r in rs})
    bed_s = 0.0
    for b in beds:
        with h5py.File(os.path.join(data, "beds", b + ".h5"), "r") as f:
            rep = json.loads(f.attrs["report"])
        bed_s += rep.get("wall_time_s", 0) * rep.get("threads", 1)
    tot += drop_s + bed_s
    out.append([lv, len(rs), "%.2f" % (drop_s / 3600), ",".join(b[:8] for b in beds), "%.2f" % (bed_s / 3600),
                "%.2f" % ((drop_s + bed_s) / 3600), "%.2f" % ((drop_s + bed_s) / 3600 / cores)])
w = [max(len(str(r[i])) for r in [hdr] + out) for i in range(len(hdr))]
for r in [hdr] + out:
    print("  ".join(str(c).rjust(w[i]) for i, c in enumerate(r)))
print(f"whole sweep: {tot / 3600:.2f} core-hours, {tot / 3600 / cores:.2f} h on {cores} cores if none idled")
PY
    ;;
  run)
    out="${2:?$usage}"
    gs="${3:-$root/build/scheduler/gravsweep}"
    [ -x "$gs" ] || { echo "bench-sweep: no gravsweep at $gs (deploy/build.sh builds one)" >&2; exit 2; }
    mkdir -p "$out"
    where=()
    [ -n "${WHERE:-}" ] && where=(--where "$WHERE") && echo "bench-sweep: part of the sweep only: --where '$WHERE'"
    for spec in "$specs"/g*.json; do "$gs" submit "$spec" --db "$out/sweep.db" "${where[@]}"; done
    "$gs" resume --db "$out/sweep.db"
    # No --bed-cache: every bed is prepared, as on a machine without data/gravity_sweep/beds.
    rc=0
    "$gs" work --db "$out/sweep.db" --workers "${WORKERS:-$cores}" --threads "${THREADS:-1}" --lease 300 || rc=$?
    [ -n "${WHERE:-}" ] && echo "bench-sweep: part of the sweep only: --where '$WHERE'"
    report "$out"
    exit "$rc"  # work's own exit code (4: a job is dead)
    ;;
  report)
    report "${2:?$usage}"
    ;;
  *)
    echo "$usage" >&2
    exit 2
    ;;
esac
