#!/usr/bin/env bash
# The time-step check of deploy/dt-check.sh over many sites: at one gravity level, the drop of
# examples/dt_check/gLEVEL.json at SITES projectile sites (projectile seeds 1..SITES, each its
# own lateral and vertical offset), each at the fixed step and with /time_step {N, CAP}, all on one
# bed. A single drop's tstop moves by several percent under any change of step (the bed is
# chaotic), so one site cannot tell a bias of the adaptive step from chaos; the mean over sites
# can. Prints each site, then the mean difference (adaptive - fixed) of zstop and tstop in % of
# the fixed step's mean, with the standard error of the paired differences and the scatter of the
# fixed-step runs over the sites. With CONTROL_DT, each site runs a third time at that fixed step
# (e.g. 4.5e-6, 10 % below the fixed one): a change of step known to be harmless, whose mean
# difference shows what chaos alone leaves in a mean over this many sites.
#
#   deploy/dt-check-sites.sh WORK LEVEL SITES [N] [CAP] [CONTROL_DT]
#   deploy/dt-check-sites.sh runs/dt-sites 0.01 8 20 5e-5 4.5e-6
#   SPEED_BOUND=normal_approach deploy/dt-check-sites.sh runs/dt-sites 0.01 16 20 5e-5
#
# SPEED_BOUND sets /time_step/speed_bound of the adaptive runs (absent: the scenario's default,
# twice the fastest particle's speed); their folders are named with it.
#
# The bed is prepared by the first run (or taken from WORK/bed_gLEVEL.h5 when it exists). Runs
# already finished (WORK/<run>/metrics.json) are kept: the script resumes where it stopped.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
work="${1:?usage: dt-check-sites.sh WORK LEVEL SITES [N] [CAP] [CONTROL_DT]}"
g="${2:?level (m/s2)}"
sites="${3:?number of sites}"
n="${4:-20}"
cap="${5:-5e-5}"
control="${6:-}"
bound="${SPEED_BOUND:-}"
tag="n${n}_cap${cap}${bound:+_$bound}"
gs="${GRAVSWEEP:-$root/build/scheduler/gravsweep}"
py=/usr/bin/python3
[ -x "$gs" ] || { "$root/deploy/install-deps.sh" && "$root/deploy/build.sh"; }
spec="$root/examples/dt_check/g$g.json"
[ -f "$spec" ] || { echo "dt-check-sites: no $spec" >&2; exit 2; }
mkdir -p "$work"
bed="$work/bed_g$g.h5"

run() {  # run NAME SPEC
  local name="$1" s="$2"
  [ -f "$work/$name/metrics.json" ] && return 0
  echo "g = $g m/s2: $name ..." >&2
  if [ -f "$bed" ]; then
    "$gs" run "$s" --bed "$bed" --out "$work/$name" --threads 2 --snapshot-interval 0 --quiet >"$work/$name.log" 2>&1 ||
      { tail -3 "$work/$name.log" >&2; exit 1; }
  else
    "$gs" run "$s" --out "$work/$name" --threads 2 --snapshot-interval 0 --quiet >"$work/$name.log" 2>&1 ||
      { tail -3 "$work/$name.log" >&2; exit 1; }
    cp "$work/$name/bed.h5" "$bed.tmp" && cp "$work/$name/bed.h5.sha256" "$bed.sha256" && mv "$bed.tmp" "$bed"
  fi
}

for site in $(seq 1 "$sites"); do
  fixed="$work/fixed_g${g}_s$site.json"
  fast="$work/fast_g${g}_${tag}_s$site.json"
  ctl="$work/control_g${g}_dt${control}_s$site.json"
  "$py" - "$spec" "$site" "$n" "$cap" "$fixed" "$fast" "$control" "$ctl" "$bound" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s.pop("$schema", None)
s["projectile"]["seed"] = int(sys.argv[2])
json.dump(s, open(sys.argv[5], "w"), indent=1)
if sys.argv[7]:
    c = json.loads(json.dumps(s))
    c["dt_s"] = float(sys.argv[7])
    json.dump(c, open(sys.argv[8], "w"), indent=1)
s["time_step"] = {"steps_per_contact": float(sys.argv[3]), "dt_max_s": float(sys.argv[4])}
if sys.argv[9]:
    s["time_step"]["speed_bound"] = sys.argv[9]
json.dump(s, open(sys.argv[6], "w"), indent=1)
PY
  run "fixed_g${g}_s$site" "$fixed"
  run "fast_g${g}_${tag}_s$site" "$fast"
  [ -z "$control" ] || run "control_g${g}_dt${control}_s$site" "$ctl"
done

echo "dt check over $sites sites at g = $g m/s2, N = $n, cap $cap s${bound:+, speed bound $bound}; load average $(cut -d' ' -f1-3 /proc/loadavg)"
"$py" - "$work" "$g" "$sites" "$tag" "$control" <<'PY'
import json, math, sys
work, g, sites, tag, control = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5]
rows, controls = [], []
for s in range(1, sites + 1):
    f = json.load(open(f"{work}/fixed_g{g}_s{s}/metrics.json"))
    a = json.load(open(f"{work}/fast_g{g}_{tag}_s{s}/metrics.json"))
    rows.append((s, f, a))
    if control:
        controls.append((s, f, json.load(open(f"{work}/control_g{g}_dt{control}_s{s}/metrics.json"))))
print(f"{'site':>4}  {'zstop_fixed_cm':>14}  {'zstop_fast_cm':>13}  {'tstop_fixed_s':>13}  {'tstop_fast_s':>12}  {'mean_dt_fast_us':>15}")
for s, f, a in rows:
    print(f"{s:>4}  {100 * f['zstop_m']:>14.3f}  {100 * a['zstop_m']:>13.3f}  {f['tstop_s']:>13.4f}  {a['tstop_s']:>12.4f}"
          f"  {1e6 * a['simulated_time_s'] / a['steps']:>15.2f}")

def stats(key, rows):
    fx = [f[key] for _, f, _ in rows]
    d = [a[key] - f[key] for _, f, a in rows]
    m = sum(fx) / len(fx)
    md = sum(d) / len(d)
    sd = math.sqrt(sum((x - md) ** 2 for x in d) / (len(d) - 1)) if len(d) > 1 else float("nan")
    sf = math.sqrt(sum((x - m) ** 2 for x in fx) / (len(fx) - 1)) if len(fx) > 1 else float("nan")
    return m, 100 * md / m, 100 * sd / math.sqrt(len(d)) / m, 100 * sf / m

for key, unit in (("zstop_m", "m"), ("tstop_s", "s")):
    m, md, se, sf = stats(key, rows)
    print(f"{key}: fixed-step mean {m:.5g} {unit}; adaptive - fixed {md:+.2f} % +- {se:.2f} % (standard error of "
          f"the {len(rows)} paired differences); site-to-site scatter of the fixed step {sf:.2f} %")
    if controls:
        _, cd, cse, _ = stats(key, controls)
        print(f"{key}: control (fixed {control} s) - fixed {cd:+.2f} % +- {cse:.2f} %")
PY
