#!/usr/bin/env bash
# Drop speed at four gravity levels, for BENCHMARKS.md ("Long drops at four gravity levels"): this
# build (the drop at the adaptive step of /time_step) against another gravsweep (MAIN_GRAVSWEEP,
# the fixed step of /dt_s), interleaved, on the gravity sweep's own beds (data/gravity_sweep/beds,
# prepared by deploy/gravity-sweep.sh) at Froude number FR (default 1; v = FR sqrt(g D)).
#
#   deploy/bench-gravity.sh MAIN_GRAVSWEEP [ROUNDS] [LEVELS]
#   deploy/bench-gravity.sh /tmp/gravsweep-main 1 "9.81 0.1 0.01 0.001"
#
# Each round runs, per level: MAIN over the drop's first MAIN_WINDOW_S simulated seconds (default:
# the whole drop at 9.81 and 0.1 m/s2, 0.5 s below: the fixed step costs the same per step all
# through a drop, so its rate over a window is its rate), then this build over the whole drop to
# rest. Printed per level: simulated seconds per wall minute of each, their ratio, this build's
# whole drop (wall and simulated seconds) and MAIN's whole drop projected from its rate where only
# a window ran. 2 threads, no snapshots. Run it on an otherwise idle machine: the CPU model and
# the load average are printed with the results. AT_REST=loose sets /at_rest's fractions to 1 (a
# bed whose surface still creeps faster than 1 % of the impact speed is timed instead of refused;
# said in the header). SPEED_BOUND=normal_approach gives this build's adaptive step the bound of
# the pairs present (/time_step/speed_bound) instead of twice the fastest particle's speed.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
usage="usage: deploy/bench-gravity.sh MAIN_GRAVSWEEP [ROUNDS] [LEVELS]"
main_bin="${1:?$usage}"
rounds="${2:-1}"
levels="${3:-9.81 0.1 0.01 0.001}"
froude="${FR:-1}"
this="${GRAVSWEEP:-$root/build/scheduler/gravsweep}"
py=/usr/bin/python3
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# The sweep's bed of each level (job ids of deploy/gravity-sweep.sh's bed jobs).
declare -A bed_of=(
  [9.81]=dc58dbbe94582f715e03 [0.1]=efa0c202f64195f5cfd0
  [0.01]=645e11a65ceca9f4ea8a [0.001]=c52dc258847a1e220cd0)
# The adaptive step of the low-gravity sweep specs, used by this build at every level.
# SPEED_BOUND=normal_approach adds /time_step/speed_bound (said in the header).
adaptive='{"steps_per_contact": 20, "dt_max_s": 5e-05'"${SPEED_BOUND:+, \"speed_bound\": \"$SPEED_BOUND\"}"'}'

# spec LEVEL KIND OUT: the level's sweep base at FR; KIND main drops /time_step and cuts the drop.
make_spec() {
  "$py" - "$root/examples/gravity_sweep/g$1.json" "$2" "$froude" "$adaptive" "${MAIN_WINDOW_S:-}" "$3" \
    "${AT_REST:-}" <<'PY'
import json, math, sys
src, kind, froude, adaptive, window, out, at_rest = sys.argv[1:]
spec = json.load(open(src))["base"]
g = spec["gravity_m_s2"]
spec["projectile"]["impact_speed_m_s"] = float(froude) * math.sqrt(g * spec["projectile"]["diameter_m"])
if kind == "main":  # the fixed step; main's schema knows no /time_step
    spec.pop("time_step", None)
    spec["bed"].pop("time_step", None)
    cut = float(window) if window else (None if g >= 0.1 else 0.5)
    if cut:
        spec["stop"]["max_time_s"] = cut
else:
    spec["time_step"] = json.loads(adaptive)
if at_rest == "loose":
    spec["at_rest"] = {"surface_speed_fraction": 1, "rms_speed_fraction": 1}
json.dump(spec, open(out, "w"), indent=1)
PY
}

# main_bed BED OUT: BED for MAIN, whose bed key has no /bed/time_step (the grains are the same; the
# adaptive step of the bed's quench and relaxation is a fact of its preparation, not of the drop).
main_bed() {
  cp "$1" "$2"
  "$py" - "$2" <<'PY'
import h5py, json, sys
with h5py.File(sys.argv[1], "r+") as f:
    for attr in ("bed_key", "scenario"):
        doc = json.loads(f.attrs[attr])
        doc["bed"].pop("time_step", None)
        f.attrs[attr] = json.dumps(doc, separators=(",", ":"), sort_keys=True)
PY
  (cd "$(dirname "$2")" && sha256sum "$(basename "$2")" > "$(basename "$2").sha256")
}

echo "host: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "this: $("$this" --version)  main: $("$main_bin" --version)  Fr = $froude${AT_REST:+  /at_rest $AT_REST}  /time_step $adaptive"
for r in $(seq 1 "$rounds"); do
  for level in $levels; do
    bed="$root/data/gravity_sweep/beds/${bed_of[$level]}.h5"
    [ -f "$bed" ] || { echo "no bed for $level m/s2: $bed (run deploy/gravity-sweep.sh first)" >&2; exit 2; }
    [ -f "$work/main_bed_$level.h5" ] || main_bed "$bed" "$work/main_bed_$level.h5"
    for kind in main this; do
      bin="$this" kind_bed="$bed"
      [ "$kind" = main ] && bin="$main_bin" kind_bed="$work/main_bed_$level.h5"
      make_spec "$level" "$kind" "$work/$kind.json"
      if ! "$bin" run "$work/$kind.json" --out "$work/$kind" --bed "$kind_bed" --threads 2 \
        --snapshot-interval 0 --no-figures --quiet >/dev/null 2>"$work/err"; then
        echo "$kind at $level m/s2 failed:" >&2; cat "$work/err" >&2; exit 1
      fi
      "$py" -c 'import json,sys; m=json.load(open(sys.argv[1])); print(*sys.argv[2:], m["wall_time_s"], m["simulated_time_s"], m["steps"], m["stopped"])' \
        "$work/$kind/metrics.json" "$level" "$kind" >>"$work/times"
    done
  done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
"$py" - "$work/times" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
hdr = ("g_m_s2", "main_sim_s_per_wall_min", "this_sim_s_per_wall_min", "ratio_this_over_main",
       "this_whole_drop_wall_s", "this_simulated_s", "this_steps", "main_whole_drop_wall_s", "main_steps")
print(" ".join(f"{h:>24s}" for h in hdr))
levels = list(dict.fromkeys(r[0] for r in rows))
for lv in levels:
    def pick(kind):
        mine = [r for r in rows if r[0] == lv and r[1] == kind]
        return (statistics.median(float(r[2]) for r in mine), statistics.median(float(r[3]) for r in mine),
                statistics.median(int(r[4]) for r in mine), mine[-1][5].lower() == "true")
    mw, ms, mn, mstop = pick("main")
    tw, ts, tn, _ = pick("this")
    mrate, trate = 60 * ms / mw, 60 * ts / tw
    main_whole = f"{mw:.1f}" if mstop else f"~{ts / ms * mw:.0f} (projected)"
    cells = (lv, f"{mrate:.3f}", f"{trate:.3f}", f"{trate / mrate:.2f}", f"{tw:.1f}", f"{ts:.3f}",
             str(tn), main_whole, str(mn))
    print(" ".join(f"{c:>24s}" for c in cells))
PY
