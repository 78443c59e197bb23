#!/usr/bin/env bash
# The time-step check of the adaptive drop step (schemas: /time_step), in the style of Sunday et
# al. 2021 Fig. 4, at 9.81, 0.1, 0.01 and 0.001 m/s2: for each examples/dt_check/gLEVEL.json, the
# drop at the fixed 5 us step (the reference) and the same drop, on the same bed and start, with
# /time_step {steps_per_contact: N, dt_max_s: CAP}; prints zstop, tstop and apeak of both, their
# differences, the mean step, the wall times and their ratio. The bed of each level is prepared by
# the reference run (or taken from WORK/ref_gLEVEL/bed.h5 when it exists: rerun with other N).
# A second reference drop at another site (projectile seed + 1, same bed and step) gives the
# repeat scatter, and a third at the same site with the fixed step 10 % smaller (4.5 us) the
# chaos floor: a granular bed is chaotic, so any change of step, however harmless, changes the
# late trajectory and with it tstop by a few percent; a difference within these is no error.
#
#   deploy/dt-check.sh [WORK] [N] [CAP] [LEVELS...]
#   deploy/dt-check.sh runs/dt-check 20 5e-5                 # all four levels
#   deploy/dt-check.sh runs/dt-check 20 5e-5 0.1 0.01        # some of them
#
# Criterion (BENCHMARKS.md): zstop and tstop within 2 % of the reference, or within the repeat
# scatter where that is larger. The wall times are
# figures only when nothing else runs beside it (the load average is printed).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
work="${1:-$root/runs/dt-check}"
n="${2:-20}"
cap="${3:-5e-5}"
shift $(($# < 3 ? $# : 3))
levels=("$@")
[ ${#levels[@]} -gt 0 ] || levels=(9.81 0.1 0.01 0.001)
gs="${GRAVSWEEP:-$root/build/scheduler/gravsweep}"
py=/usr/bin/python3
[ -x "$gs" ] || { "$root/deploy/install-deps.sh" && "$root/deploy/build.sh"; }
mkdir -p "$work"
for g in "${levels[@]}"; do
  spec="$root/examples/dt_check/g$g.json"
  [ -f "$spec" ] || { echo "dt-check: no $spec" >&2; exit 2; }
  fast="$work/fast_g${g}_n${n}.json"
  repeat="$work/repeat_g${g}.json"
  smaller="$work/dt90_g${g}.json"
  "$py" - "$spec" "$fast" "$n" "$cap" "$repeat" "$smaller" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s.pop("$schema", None)
r = json.loads(json.dumps(s))
r["projectile"]["seed"] = r["projectile"].get("seed", 1) + 1
json.dump(r, open(sys.argv[5], "w"), indent=1)
c = json.loads(json.dumps(s))
c["dt_s"] = 0.9 * c["dt_s"]
json.dump(c, open(sys.argv[6], "w"), indent=1)
s["time_step"] = {"steps_per_contact": float(sys.argv[3]), "dt_max_s": float(sys.argv[4])}
json.dump(s, open(sys.argv[2], "w"), indent=1)
PY
  if [ ! -f "$work/ref_g$g/metrics.json" ]; then
    echo "g = $g m/s2: reference (fixed step) ..." >&2
    "$gs" run "$spec" --out "$work/ref_g$g" --threads 2 --snapshot-interval 0 >"$work/ref_g$g.log" 2>&1 ||
      { tail -3 "$work/ref_g$g.log" >&2; exit 1; }
  fi
  if [ ! -f "$work/repeat_g$g/metrics.json" ]; then
    echo "g = $g m/s2: reference at another site (the repeat scatter) ..." >&2
    "$gs" run "$repeat" --bed "$work/ref_g$g/bed.h5" --out "$work/repeat_g$g" --threads 2 --snapshot-interval 0 \
      >"$work/repeat_g$g.log" 2>&1 || { tail -3 "$work/repeat_g$g.log" >&2; exit 1; }
  fi
  if [ ! -f "$work/dt90_g$g/metrics.json" ]; then
    echo "g = $g m/s2: reference with the fixed step 10 % smaller (the chaos floor) ..." >&2
    "$gs" run "$smaller" --bed "$work/ref_g$g/bed.h5" --out "$work/dt90_g$g" --threads 2 --snapshot-interval 0 \
      >"$work/dt90_g$g.log" 2>&1 || { tail -3 "$work/dt90_g$g.log" >&2; exit 1; }
  fi
  echo "g = $g m/s2: adaptive step, N = $n, cap $cap s ..." >&2
  "$gs" run "$fast" --bed "$work/ref_g$g/bed.h5" --out "$work/fast_g${g}_n$n" --threads 2 --snapshot-interval 0 \
    >"$work/fast_g${g}_n$n.log" 2>&1 || { tail -3 "$work/fast_g${g}_n$n.log" >&2; exit 1; }
done
echo "dt check, N = $n steps per contact, cap $cap s; load average $(cut -d' ' -f1-3 /proc/loadavg); $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"$py" - "$work" "$n" "${levels[@]}" <<'PY'
import json, sys
work, n, levels = sys.argv[1], sys.argv[2], sys.argv[3:]
cols = ["g_m_s2", "vc_m_s", "zstop_ref_cm", "zstop_fast_cm", "dzstop_pct", "tstop_ref_s", "tstop_fast_s",
        "dtstop_pct", "dzstop_repeat_pct", "dtstop_repeat_pct", "dzstop_dt90_pct", "dtstop_dt90_pct", "apeak_ref_m_s2", "apeak_fast_m_s2", "mean_dt_fast_us", "wall_ref_s", "wall_fast_s", "speedup"]
rows = []
for g in levels:
    r = json.load(open(f"{work}/ref_g{g}/metrics.json"))
    f = json.load(open(f"{work}/fast_g{g}_n{n}/metrics.json"))
    q = json.load(open(f"{work}/repeat_g{g}/metrics.json"))
    c = json.load(open(f"{work}/dt90_g{g}/metrics.json"))
    pct = lambda a, b: 100 * (b - a) / a
    rows.append([g, f"{r['vc_m_s']:.4g}", f"{100 * r['zstop_m']:.3f}", f"{100 * f['zstop_m']:.3f}",
                 f"{pct(r['zstop_m'], f['zstop_m']):+.2f}", f"{r['tstop_s']:.4f}", f"{f['tstop_s']:.4f}",
                 f"{pct(r['tstop_s'], f['tstop_s']):+.2f}", f"{pct(r['zstop_m'], q['zstop_m']):+.2f}",
                 f"{pct(r['tstop_s'], q['tstop_s']):+.2f}", f"{pct(r['zstop_m'], c['zstop_m']):+.2f}",
                 f"{pct(r['tstop_s'], c['tstop_s']):+.2f}", f"{r['apeak_m_s2']:.4g}", f"{f['apeak_m_s2']:.4g}",
                 f"{1e6 * f['simulated_time_s'] / f['steps']:.2f}", f"{r['wall_time_s']:.1f}",
                 f"{f['wall_time_s']:.1f}", f"{r['wall_time_s'] / f['wall_time_s']:.2f}"])
w = [max(len(c), *(len(x[i]) for x in rows)) for i, c in enumerate(cols)]
print("  ".join(c.rjust(w[i]) for i, c in enumerate(cols)))
for x in rows:
    print("  ".join(v.rjust(w[i]) for i, v in enumerate(x)))
PY
