#!/usr/bin/env bash
# Campaign wall time with and without the thread pool (issue 12, "no idle core"): runs SPEC twice
# from an empty database each time, alternating ROUNDS times (default 1), and prints the wall times:
#   pooled:   gravsweep work --workers 2 --threads 1   (the supervisor passes --pool-threads 2: a bed
#             that runs alone, with nothing else claimable, takes both cores)
#   separate: two `gravsweep work --workers 1 --threads 1` processes side by side (each holds one
#             core: a lone bed runs on one while the other worker waits; the behaviour before the pool)
#
#   deploy/bench-campaign.sh examples/sweep_tiny.json [ROUNDS]
#   deploy/bench-campaign.sh examples/sweep_one_bed.json 1
#
# Run it on an otherwise idle machine (the load average is printed).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
spec="${1:?usage: deploy/bench-campaign.sh SPEC.json [ROUNDS]}"
rounds="${2:-1}"
gs="${GRAVSWEEP:-$root/build/scheduler/gravsweep}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
run() {  # $1 = pooled | separate; prints the wall time in s
  rm -rf "$work/c.db" "$work/c.files" "$work/c.db-wal" "$work/c.db-shm"
  "$gs" submit "$spec" --db "$work/c.db" >/dev/null
  local t0 t1
  t0=$(now)
  if [ "$1" = pooled ]; then
    "$gs" work --db "$work/c.db" --workers 2 --threads 1 --quiet >/dev/null 2>&1
  else
    "$gs" work --db "$work/c.db" --workers 1 --threads 1 --quiet >/dev/null 2>&1 &
    local a=$!
    "$gs" work --db "$work/c.db" --workers 1 --threads 1 --quiet >/dev/null 2>&1
    wait "$a"
  fi
  t1=$(now)
  local left
  left=$("$gs" status --db "$work/c.db" --format json 2>/dev/null | /usr/bin/python3 -c \
    'import json,sys; d=json.load(sys.stdin); print(sum(r.get("done",0) for r in d.get("sweeps",[])))' 2>/dev/null || echo "?")
  echo "$1 $(/usr/bin/python3 -c "print($t1 - $t0)") $left"
}
echo "spec $spec, $rounds round(s), load average at start $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-10s %12s %10s\n' mode wall_time_s jobs_done
for r in $(seq 1 "$rounds"); do
  for mode in separate pooled; do
    read -r m t d < <(run "$mode")
    printf '%-10s %12.1f %10s\n' "$m" "$t" "$d"
  done
done
