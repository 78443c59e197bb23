#!/usr/bin/env bash
# Campaign wall time with and without the thread pool ("no idle core"): runs SPEC from an
# empty database in each mode, ROUNDS times (default 1), alternating which mode goes first, and
# prints the wall times:
#   pooled:   gravsweep work --workers 2 --threads 1   (the supervisor passes --pool-threads 2: a bed
#             that runs alone, with nothing else claimable, takes both cores)
#   separate: two `gravsweep work --workers 1 --threads 1` processes side by side (each holds one
#             core: a lone bed runs on one while the other worker waits; the behaviour before the pool)
#
#   deploy/bench-campaign.sh examples/sweep_tiny.json [ROUNDS]
#   deploy/bench-campaign.sh examples/sweep_one_bed.json 3
#
# Run it on an otherwise idle machine (the load average is printed). A worker that fails stops the
# script with its exit code and the path of its log.
set -euo pipefail
export LC_ALL=C
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
spec="${1:?usage: deploy/bench-campaign.sh SPEC.json [ROUNDS]}"
rounds="${2:-1}"
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "ROUNDS: found '$rounds', expected a whole number >= 1" >&2; exit 2; }
gs="${GRAVSWEEP:-$root/build/scheduler/gravsweep}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
db="$work/c.db"
fail() { echo "$1: gravsweep work exited $2; its log: $3 (kept)" >&2; trap - EXIT; exit "$2"; }
run() {  # $1 = pooled | separate; sets wall_s and done_jobs
  rm -rf "$db" "$work/c.files" "$db-wal" "$db-shm"
  local planned
  planned=$("$gs" submit "$spec" --db "$db" | grep -o '[0-9]* new' | grep -o '[0-9]*')
  local t0 rc=0 rc_a=0
  t0=$(date +%s.%N)
  if [ "$1" = pooled ]; then
    "$gs" work --db "$db" --workers 2 --threads 1 --quiet >"$work/pooled.log" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] || fail pooled "$rc" "$work/pooled.log"
  else
    "$gs" work --db "$db" --workers 1 --threads 1 --quiet >"$work/separate-a.log" 2>&1 &
    local a=$!
    "$gs" work --db "$db" --workers 1 --threads 1 --quiet >"$work/separate-b.log" 2>&1 || rc=$?
    wait "$a" || rc_a=$?
    [ "$rc" -eq 0 ] || fail separate "$rc" "$work/separate-b.log"
    [ "$rc_a" -eq 0 ] || fail separate "$rc_a" "$work/separate-a.log"
  fi
  wall_s=$(/usr/bin/python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$t0" "$(date +%s.%N)")
  done_jobs=$("$gs" status --db "$db" --format json |
    /usr/bin/python3 -c 'import json,sys; print(sum(r["done"] for r in json.load(sys.stdin)["sweeps"]))')
  [ "$done_jobs" = "$planned" ] || { echo "$1: $done_jobs of $planned jobs done" >&2; exit 1; }
}
echo "spec $spec, $rounds round(s), load average at start $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-10s %12s %10s\n' mode wall_time_s jobs_done
for r in $(seq 1 "$rounds"); do
  modes=(separate pooled)
  [ $((r % 2)) -eq 0 ] && modes=(pooled separate)
  for mode in "${modes[@]}"; do
    run "$mode"
    printf '%-10s %12s %10s\n' "$mode" "$wall_s" "$done_jobs"
  done
done
