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
# only on one host, interleaved or back to back. The tables are computed by deploy/bench_sweep.py.
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
  "$py" "$root/deploy/bench_sweep.py" report "$db" "$cores"
}

case "${1:-}" in
  estimate)
    "$py" "$root/deploy/bench_sweep.py" estimate "$root/data/gravity_sweep" "$cores"
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
