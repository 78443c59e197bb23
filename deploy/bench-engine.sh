#!/usr/bin/env bash
# Engine speed on a settled bed, for BENCHMARKS.md: ROUNDS rounds (default 3) of
# `gravsweep bench --bed BED --steps STEPS --threads 1,2`, interleaved with a second binary when
# one is given (e.g. a build of main, to compare before/after on the same machine state), then the
# median ns per particle-step and the bytes per particle of each binary and thread count.
#
#   deploy/bench-engine.sh BED.h5 [OTHER_GRAVSWEEP] [ROUNDS] [STEPS]
#   deploy/bench-engine.sh runs/1g/bed.h5 /tmp/gravsweep-main 3 2000
#
# Run it on an otherwise idle machine; the load average is printed with the results.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bed="${1:?usage: deploy/bench-engine.sh BED.h5 [OTHER_GRAVSWEEP] [ROUNDS] [STEPS]}"
other="${2:-}"
rounds="${3:-3}"
steps="${4:-2000}"
this="${GRAVSWEEP:-$root/build/scheduler/gravsweep}"
binaries=("$this")
[ -n "$other" ] && binaries+=("$other")
out="$(mktemp)"
trap 'rm -f "$out"' EXIT
for r in $(seq 1 "$rounds"); do
  for b in "${binaries[@]}"; do
    "$b" bench --bed "$bed" --steps "$steps" --threads 1,2 |
      awk -v b="$b" '$1 == "file" {print b, $3, $4, $6}' >>"$out"
  done
done
echo "median of $rounds rounds, $steps steps, load average $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-50s %8s %22s %20s\n' binary threads ns_per_particle_step bytes_per_particle
for b in "${binaries[@]}"; do
  for t in 1 2; do
    awk -v b="$b" -v t="$t" '$1 == b && $2 == t {print $3, $4}' "$out" | sort -g |
      awk -v b="$b" -v t="$t" '{ns[NR] = $1; by = $2}
        END {m = (NR % 2) ? ns[(NR + 1) / 2] : 0.5 * (ns[NR / 2] + ns[NR / 2 + 1]);
             printf "%-50s %8d %22.1f %20d\n", b, t, m, by}'
  done
done
