#!/usr/bin/env bash
# Wall time of the first SECONDS of a drop, for BENCHMARKS.md: ROUNDS rounds (default 4)
# of `gravsweep run SPEC --bed BED --threads 2 --snapshot-interval 0` with SPEC's /stop/max_time_s
# cut to SECONDS (default 0.12), interleaved with a second binary when one is given; then the
# minimum and median wall seconds of each binary and its projectile's deepest point (the same
# depth to the last digit means the same arithmetic). SPEC is a scenario, or a sweep spec whose
# base is taken at Froude number FR (default 1: v = FR sqrt(g D)), as deploy/bench-gravity.sh
# does; AT_REST=loose sets /at_rest's fractions to 1 (a bed that still creeps is timed, not
# refused).
#
#   deploy/bench-drop.sh SPEC.json BED.h5 [OTHER_GRAVSWEEP] [ROUNDS] [SECONDS]
#   AT_REST=loose deploy/bench-drop.sh examples/gravity_sweep/g0.1.json data/gravity_sweep/beds/efa0c202f64195f5cfd0.h5 /tmp/gravsweep-main 3 0.3
#
# Run it on an otherwise idle machine; the load average is printed with the results.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
usage="usage: deploy/bench-drop.sh SPEC.json BED.h5 [OTHER_GRAVSWEEP] [ROUNDS] [SECONDS]"
spec="${1:?$usage}"
bed="${2:?$usage}"
other="${3:-}"
rounds="${4:-4}"
seconds="${5:-0.12}"
py=/usr/bin/python3
this="${GRAVSWEEP:-$root/build/scheduler/gravsweep}"
binaries=("$this")
[ -n "$other" ] && binaries+=("$other")
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$py" - "$spec" "$seconds" "$work/spec.json" "${FR:-1}" "${AT_REST:-}" <<'PY'
import json, math, sys
spec = json.load(open(sys.argv[1]))
if "base" in spec:  # a sweep spec: its base at Froude number FR
    spec = spec["base"]
    spec["projectile"]["impact_speed_m_s"] = float(sys.argv[4]) * math.sqrt(
        spec["gravity_m_s2"] * spec["projectile"]["diameter_m"])
spec.pop("$schema", None)
spec.setdefault("stop", {})["max_time_s"] = float(sys.argv[2])
if sys.argv[5] == "loose":
    spec["at_rest"] = {"surface_speed_fraction": 1, "rms_speed_fraction": 1}
json.dump(spec, open(sys.argv[3], "w"), indent=1)
PY
for r in $(seq 1 "$rounds"); do
  for i in "${!binaries[@]}"; do
    if ! "${binaries[$i]}" run "$work/spec.json" --out "$work/out$i" --bed "$bed" --threads 2 --snapshot-interval 0 \
      >/dev/null 2>"$work/err"; then
      cat "$work/err" >&2
      exit 1
    fi
    "$py" -c "import json,sys; m=json.load(open(sys.argv[1])); print(sys.argv[2], m['wall_time_s'], repr(m['max_depth_m']))" \
      "$work/out$i/metrics.json" "$i" >>"$work/times"
  done
done
echo "$rounds rounds, first $seconds s of $spec on $bed, 2 threads, load average $(cut -d' ' -f1-3 /proc/loadavg)"
"$py" - "$work/times" "${binaries[@]}" <<'PY'
import statistics, sys
rows = [line.split() for line in open(sys.argv[1])]
print(f"{'binary':50s} {'min_wall_s':>10s} {'median_wall_s':>13s} {'max_depth_m':>20s}")
for i, b in enumerate(sys.argv[2:]):
    mine = [r for r in rows if r[0] == str(i)]
    walls = [float(r[1]) for r in mine]
    print(f"{b:50s} {min(walls):10.2f} {statistics.median(walls):13.2f} {mine[-1][2]:>20s}")
PY
